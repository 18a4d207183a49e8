"""Every tuning constant of the kernels, each with the reason for its value.

A value is a derivation (stated), a measurement (the benchmark that makes it;
its figures are in that benchmark's report) or a standard choice (named). The
engine's are :mod:`pipelay_fast.engine.tuning`'s, the input layer's
:mod:`pipelay_fast.input.limits`'.
"""

from __future__ import annotations

from ..input.limits import ROUNDOFF

# --- round-off --------------------------------------------------------------------
# Double precision's machine epsilon, 2^-52 (not a choice).
EPS = 2.220446049250313e-16
# (A parameter in [0, 1] found by Newton has no tolerance and no step cap:
# :mod:`.roots` runs Newton, guarded by bisection, to round-off.)
# The package's round-off ROUNDOFF (:mod:`pipelay_fast.input.limits`, its
# derivation there: sums of up to ~1e5 terms): the relative difference [-]
# below which two of the solver's numbers are the same (kernels and engine,
# :mod:`pipelay_fast.engine.tuning` uses it too). Where
# (:func:`.contact.friction_commit`) a friction spring within this share of
# its mobilising displacement slides; (:func:`.grading.graded_tables`) two
# anchors closer than this many metres are one, and a stretch's element count
# phi is rounded up from phi - ROUNDOFF.

# --- the Newton iteration (:mod:`.newton`) --------------------------------------------
# A residual within ROUNDOFF_RATIO times its round-off floor is converged
# (:func:`.system._roundoff_ratio`): at the floor the ratio is of order 1,
# one Newton step before it two orders more.
ROUNDOFF_RATIO = 10.0
# A weighted residual above RUNAWAY times the larger of its start and one
# reference force has diverged: the line search takes rising merits while
# boundaries move (MERIT_RISE). The weighted residual is in units of the
# reference force fref (:func:`.system._weighted_max`), so one reference
# force is 1 there (the unit, not a choice): from a start nearer balance,
# the runaway is RUNAWAY reference forces.
RUNAWAY = 1e6

# --- step control (:mod:`.step`) ----------------------------------------------------
# Armijo's sufficient decrease of the merit (the textbook c1 = 1e-4,
# Nocedal and Wright, Numerical Optimization, 2006, Sec. 3.1), the step
# halved (BACKTRACK; the friction cut's forward search grows it by the
# inverse, :func:`.step._line_search`) up to LINE_SEARCH_TRIALS trials
# (down to 2^-11 of it; a trial of non-finite merit is halved like any other).
ARMIJO = 1e-4
BACKTRACK = 0.5
LINE_SEARCH_TRIALS = 12
# With the boundaries unknowns, the largest rise of the merit a step may
# bring (:func:`.step._accepts`): the weighted residual rises across good
# steps as the element lengths move with the boundaries (measured:
# bench_contact.py parts 1 and 6; Armijo alone cut steps to 1/8 to 1/32).
MERIT_RISE = 1e8
# No element of a boundary's zone shrinks below MIN_ELEMENT_SHARE of its
# length in one step (the elements stay positive, the mesh does not fold).
MIN_ELEMENT_SHARE = 0.1
# Touchdown may move at most SHORT_LAID_SHARE of the way to the modelled
# lower end in one step; more, and Newton stops (SHORT_LAID) for more laid
# pipe (:func:`pipelay_fast.engine.solver.more_laid`). The share is the
# bisection's: the laid pipe is then doubled (by 1 / BACKTRACK), so that a
# stopped step short of the old lower end moves touchdown by no more than
# that share of the new laid pipe.
SHORT_LAID_SHARE = BACKTRACK
# The span from re-contact to a bearing tip at most halves or grows by
# SPAN_GROWTH times in a step: its square is linear in the load past the
# change of regime, so the span itself follows a logarithmic step, whose
# factor is the bisection's (the inverse of BACKTRACK, as every growth and
# cut of the solver: the load steps and the laid pipe's doubling too).
SPAN_GROWTH = 1.0 / BACKTRACK

# --- contacts (:mod:`.contact`) --------------------------------------------------------
# A node within LATERAL_HYSTERESIS of its elements below the stinger's span
# is held laterally too: held and free would flip between iterations as a
# node crosses the tip.
LATERAL_HYSTERESIS = 0.05

# --- loads (:mod:`.loads`) ---------------------------------------------------------------
# The power law V0 (x/d)^p of a current has an infinite slope at the seabed;
# below POWER_FLOOR times the depth d it is continued by a quadratic
# (:func:`.loads.current_speed`). The floor is the round-off: a height within
# ROUNDOFF d of the seabed is the seabed to the solver (positions of order d),
# so the power law holds wherever a node can be told from the seabed. (Against
# the power law itself, bench_contact's 3D grid: the peak stress moves 2.7e-8
# at this floor, 3.4e-6 at 1e-6.)
POWER_FLOOR = ROUNDOFF

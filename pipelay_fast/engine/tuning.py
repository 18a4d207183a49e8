"""Every tuning constant of the engine, each with the reason for its value.

A value is a derivation (stated), a measurement (the benchmark script that
makes it; its figures are in that script's report, not here) or a standard
choice (named). The kernels' constants are :mod:`pipelay_fast.kernels.tuning`'s,
the input layer's limits :mod:`pipelay_fast.input.limits`'.
"""

from __future__ import annotations

from ..kernels.tuning import BACKTRACK, MIN_ELEMENT_SHARE, ROUNDOFF, SHORT_LAID_SHARE

# --- round-off -----------------------------------------------------------------
# Relative difference [-] below which two arc lengths, mesh lengths or element
# counts are the same: the kernels' round-off (its derivation there), one for
# the solver.
REL_ROUNDOFF = ROUNDOFF

# --- boundary layers -------------------------------------------------------------
# A boundary layer of length lam (the flexural length sqrt(EI/T)) decays as
# exp(-s / lam): three lengths leave exp(-3) = 5 %. The mesh each contact
# boundary carries with it (its zone, :func:`.boundaries.follow_nodes`), and the
# sticking zone kept behind the slipping one (:func:`.friction.slipping_length_bound`).
DECAY_LENGTHS = 3.0

# --- Newton's steps of the contact boundaries (:func:`.continuation.boundary_step`)
# The largest move of a boundary in one Newton step: MAX_BOUNDARY_STEP elements
# (href), or BOUNDARY_STEP_LAYER boundary layers in a tension-dominated lay, the
# larger. Measured: cold iterations on the grid and the random cases,
# benchmarks/bench_contact.py parts 1 and 6 (larger steps lose random cases;
# elements alone hold fine meshes to short steps).
MAX_BOUNDARY_STEP = 2.0
BOUNDARY_STEP_LAYER = 0.2

# --- load paths (:func:`.continuation.continuation`) ------------------------------
# One step rule for every load path (the homotopy from the first guess, the
# current's path). Each starts with LOAD_STEP, a quarter of the load, and no
# step is larger: friction is path dependent, and half steps follow another
# slip path on fine meshes (measured: S125 3D, benchmarks/bench_contact.py
# part 2). A converged step multiplies the next by LOAD_STEP_FACTOR, a failed
# one divides the step it took (bisection: a cut step is the half of the
# failed one that starts from the last converged state, and growth undoes one
# cut). A step cut below SMALLEST_LOAD_STEP fails the solve (LOAD_STEP halved
# 12 times: the homotopy's floor, measured on the random cases,
# bench_contact.py part 6), and so does a path that takes
# solver.max_load_steps steps.
LOAD_STEP = 0.25
LOAD_STEP_FACTOR = 1.0 / BACKTRACK  # (the kernels' halving: one bisection factor)
SMALLEST_LOAD_STEP = 1e-4
# A predicted start of a load step (a warm start's neighbour's increment, or
# the path's secant) may take at most this many times the iterations of the
# path's hardest converged call before the step is solved again from the last
# converged state (measured: the random 3D cases, bench_contact.py part 6).
PREDICTED_CAP = 2

# --- the regime at the stinger's ends (:mod:`.boundaries`) ------------------------
# Switches of regime in one Newton solve (between bearing on the tip and lifting
# off, or between conforming to the curve and held at its upper end): one each way.
MAX_TIP_SWITCHES = 2

# --- meshes ----------------------------------------------------------------------
# Geometric growth of neighbouring elements of a graded mesh (:mod:`.mesh`).
GROWTH = 1.2
# The default finest element (solver.min_element_length not given,
# :func:`.problem._mesh_sizes`): FINEST_IN_LAYER flexural lengths at
# touchdown (the boundary layer over which the curvature peaks), but no finer
# than h_max / FINEST_COARSENING. No measurement of either value of its own:
# the defaults as a whole are placed against finer and coarser meshes by
# benchmarks/speed_vs_error.py (S67 2D: on the error/time front).
FINEST_IN_LAYER = 0.02
FINEST_COARSENING = 8.0
# A mesh is graded at its foci when no node is further than ON_FOCUS h_min from
# the graded mesh's (the error of a node off its focus by d is O(d^2)).
ON_FOCUS = 0.02
# The shortest element [h_min] between lift-off and the tip's point, and the
# move of re-contact below which bear_on_tip leaves it (:mod:`.boundaries`):
# the kernels' shortest share of an element (MIN_ELEMENT_SHARE, the least a
# Newton step leaves of an element), so that a split the engine makes is one
# a step could make.
HOLD_SPLIT = MIN_ELEMENT_SHARE
# Newton's tolerance [-] on the first mesh, which only finds where the
# boundaries are (regrading moves them by its own discretisation): measured,
# cold iterations and answers on the quick grid, bench_contact.py parts 1 to 3.
LOOSE_TOLERANCE = 1e-3

# --- laid pipe (:func:`.solver.laid_short`, :func:`.solver.more_laid`) ----------------
# The laid pipe a mesh models behind touchdown: at least one flexural length
# sqrt(EI/T) (the boundary layer over which the pipe leaves the seabed),
# grown by LOAD_STEP_FACTOR (doubled) to at least that factor's flexural
# lengths when short; a solve adds laid pipe until the mesh would exceed
# solver.max_elements.
LAID_LENGTHS = 1.0
# The first mesh's default laid pipe (:func:`.problem._guess`): LOAD_STEP_FACTOR
# times LAID_LENGTHS flexural lengths (the grown amount) plus LAID_ELEMENTS elements (room for
# touchdown's first Newton steps, MAX_BOUNDARY_STEP elements each, when the
# flexural length is shorter than an element); no measurement.
LAID_ELEMENTS = 5.0
# On a laid pipe shorter than two flexural lengths (given by
# solver.laid_length or lay.pipe_length; the default is longer) the first
# mesh's touchdown focus, one flexural length before the catenary's, would
# lie nearer the lower end than this share of the laid pipe; it is put there
# instead (:func:`.problem.build_problem`). The share is the kernels'
# SHORT_LAID_SHARE: a touchdown nearer the lower end than that is one a
# Newton step would stop at for more laid pipe.
TOUCHDOWN_FOCUS_SHARE = SHORT_LAID_SHARE
# The largest share of the laid pipe's lateral force the held lower end may
# carry before the laid pipe is doubled: measured, the shares left with the
# sticking zone of DECAY_LENGTHS on the 3D grid, bench_contact.py part 1.
LOWER_END_SHARE = 0.01

# --- the first guess (:mod:`.guess`) ------------------------------------------------
# A guess that lifts off below the tip by less than this share of lam starts
# from the tip, lifting off (within the guess's first-order error in lam);
# measured: cold iterations on the grid, bench_contact.py part 1.
GUESS_LIFTOFF_ERROR = 0.05
# The first guess looks for the cable's lift-off on the stinger's curve
# continued below the tip down to the seabed or this many times the
# stinger's z range below the tip, the higher; a cable steeper than the curve
# there starts from the tip, lifting off, and Newton's step past the tip
# decides. Measured: continued to the seabed, the lay table's S300 at 633 kN
# (sweeps/lay_table.toml, tests/test_laytable.py) starts bearing on the tip
# with lift-off 306 m of arc below it, and its homotopy diverges; from the tip
# lifting off it converges in 15 iterations. The value 1 itself is not
# measured.
TIP_PAST_REACH = 1.0
# The bending-dominated J-lay's guess (:class:`.beam.ElasticaSpan`): the
# elastica's collocation (scipy's solve_bvp) runs to ELASTICA_TOL from a first
# mesh of ELASTICA_NODES nodes, within scipy's cap of 1000 nodes (the 31
# elasticas below take 51 to 283). Measured on the 29 bending-dominated
# J-lays of benchmarks/bench_random.py seed 1 and the 2 of bench_contact.py
# part 6: from 21 or 41 nodes all 29 are found, from 11 one is not (1:2d-332),
# from 5 two; at scipy's default 1e-3 all 29 solve (3 more iterations in all)
# but part 6's case 26 takes 389 Newton iterations instead of 44 (its current
# path with friction follows the start).
ELASTICA_TOL = 1e-4
ELASTICA_NODES = 41
# A roller stinger's guide (the quadratic through its rollers) on elements this
# many times the case's: its answer is only a start (measured:
# benchmarks/bench_rollers.py parts 1 and 3).
GUIDE_COARSENING = 2.0

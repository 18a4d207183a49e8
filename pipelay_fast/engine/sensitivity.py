"""The solved problem carried to a neighbouring case, its regime held: the
engine's half of the implicit function theorem.

With R(U, p) = 0 at the converged state U* of a case with parameter p (the
unknowns U include the contact boundaries' arc lengths, which the mesh
follows with its grading's rates), Newton from U* on the case at p + h,
with the contact set, the slip set and the regime at the stinger's tip
held, converges to U(p + h) on the branch of U*: the implicit function
theorem's U(p), whose central difference (U(p + h) - U(p - h)) / 2h is its
derivative to O(h^2). The case at p + h is built as a solve builds it
(:func:`.problem.remesh`): its mesh's sizes and length of pipe from its
own first guess (the flexural length, and with it the finest element,
changes with the tension and the depth; held, the derivative of a sagbend
peak misses a full solve's by 1.6e-4, S125 2D; the p - h side's may be
extrapolated from p's and p + h's, :func:`mirrored_sizes`), its
loads, supports and ends from its own data, so that a key entering
through derived quantities (the water depth's pressures and current
profile, the top tension's equation row, the current's drag) is
differentiated as the model has it.

Newton to the tolerance on each side, not one back-substitution on the
factored tangent: the tangent is exact in 2D (``benchmarks/check_tangent.py``),
so the first step from U* misses the converged side by O(h^2) only, but
where the stinger's boundaries move that error changes sign with h (the
kernel's step carries the nodes they move along the pipe), and the central
difference of first steps misses full solves in proportion to h (S67 2D,
d/da: 3.5e-4 at h = 1e-4 |a|, 1.1e-2 at 1e-3 |a|); of second steps, 7.5e-6
on S125 2D's sagbend peak where the tolerance is 1e-11 (solved to it:
1.3e-6); in 3D the friction springs' kinks keep the tangent inexact. Each
side takes two steps at least, and is solved to solver.tolerance: from
there the second step ends at the residual's round-off floor (2e-9 of the
reference force, S67 2D), and a side's stopping point enters the
difference as that floor / h.
The output layer differences the post-processed columns
(:mod:`pipelay_fast.output.sensitivity`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..input.case import Case
from ..kernels import layout as L
from .boundaries import liftoff_position, stinger_foci, touchdown_position
from .continuation import run_newton
from .friction import friction_path
from .problem import guess_sizes, remesh, sized_mesh
from .solver import _solution
from .state import Problem
from .supports import line_span

FRICTION_PATH = (
    "3D with seabed friction under a current: the answer follows the current's load path (its "
    "mesh graded under gravity, the friction springs anchored there, their slip set); "
    "Newton from the answer holds neither and misses finite differences of full solves by "
    "up to 2 % (S67 3D), and the slip set changes within +-1e-4 of a or of the current")


def regraded_problem(case: Case, pb: Problem, guessed: dict | None = None) -> Problem:
    """The problem of ``case`` (a neighbour of the case ``pb`` solved) on
    the mesh a solve of ``case`` grades at ``pb``'s boundaries: its sizes
    and length of pipe from ``guessed`` (None: ``case``'s first guess's,
    :func:`.problem.guess_sizes`; :func:`.problem.sized_mesh`), its map the
    grading's rates, ``pb``'s state interpolated onto it, its contact sets
    on the same boundaries (:func:`.problem.remesh`)."""
    stats = dict(pb.stats)
    sizes = sized_mesh(case, guessed or guess_sizes(case))
    total = sizes.pop("cold_total")
    if "cold_total" not in stats:  # laid pipe was added: the solve's length kept
        total = float(pb.s[-1])
    stats.update(sizes)
    graded = replace(pb, path=replace(pb.path, stats=stats))
    return remesh(case, graded, touchdown_position(pb), stinger_foci(case, pb), grading=True,
                  total=total)


def mirrored_sizes(base: dict, plus: dict) -> dict:
    """The first guess's sizes (:func:`.problem.guess_sizes`) at p - h from
    those at p (``base``) and p + h (``plus``), extrapolated linearly: they
    are smooth in p, and their O(h^2) error enters a derivative as O(h) of
    the mesh sizes' share of it (1.6e-4 of a sagbend peak's on S125 2D,
    the module docstring): a guess fewer a key."""
    return {name: 2.0 * value - plus[name] for name, value in base.items()}


def _regime(pb: Problem) -> tuple:
    """The regime a sensitivity holds: the mesh's node count, the boundaries
    present, the seabed's and the stinger's contact sets, each rigid
    point's branch and the friction springs' slip directions (but
    touchdown's, whose spring has no normal force: its state flips with no
    force)."""
    c = pb.contacts
    slips = np.sign(c.fric[:, [L.FR_DIR, L.FR_DIRZ]])
    if pb.td_node >= 0:  # touchdown's spring: no normal force there, either state
        slips[pb.td_node] = 0.0
    return (pb.nn, (pb.mesh.bnodes >= 0).tobytes(), c.bed_active.tobytes(),
            c.st_active.tobytes(), (c.points[:, L.PT_BEAR] != 0.0).tobytes(),
            slips[:, 0].tobytes(), slips[:, 1].tobytes())


_REGIME_PARTS = ("the mesh's element count (the discrete answer jumps)",
                 "the contact boundaries present", "the seabed's contact set",
                 "the stinger's contact set", "the rigid points' (stinger tip, rollers) bearing",
                 "the lateral slip set", "the axial slip set")


def neighbour_solutions(cases, pb: Problem, held: tuple | None = None, guessed=None):
    """The solutions of ``cases`` (neighbours of the case ``pb`` solved, or
    that case itself), each by Newton from ``pb``'s state to
    solver.tolerance, two steps at least, on the mesh a solve of that case grades at
    ``pb``'s boundaries (:func:`regraded_problem`, sized by ``guessed``,
    one per case, or each case's first guess), in one regime. None
    where a case follows the current's path with seabed friction
    (:data:`FRICTION_PATH`).

    Returns (the :class:`.state.Solution` of each, its Newton iterations in
    ``stats["iterations"]``; their regime; ""), or (None, None, the reason)
    when Newton does not converge (the tip's regime changes, a singular
    tangent, touchdown running off the laid pipe) or the answers' regimes
    differ from each other or from ``held`` (a regime these functions
    returned): the node count, a contact set, the slip set, the tip's or a
    roller's branch."""
    solutions, regimes = [], [] if held is None else [held]
    for case, sizes in zip(cases, guessed or [None] * len(cases), strict=True):
        if friction_path(case):
            return None, None, FRICTION_PATH
        new = regraded_problem(case, pb, sizes)
        new.settings.factors = pb.settings.factors.copy()
        new.settings.tolerance = None
        new.settings.in_balance = True  # U* is a refined solution: the boundaries move freely
        # two steps at least: the first misses the derivative by 2 % (the
        # module docstring), and may end below the tolerance where h is small
        status, react, info = run_newton(new, np.zeros_like(new.u), case.solver.tolerance, 1)
        steps = int(info[L.I_ITER])
        if status in (L.OK, L.MAX_ITERATIONS):
            new.settings.in_balance = True
            status, react, info = run_newton(new, np.zeros_like(new.u), case.solver.tolerance,
                                             case.solver.max_iterations)
        if status != L.OK:
            return None, None, f"Newton from the solution: {L.STATUS_TEXT.get(status, status)}"
        if new.lo_node >= 0 and new.has_curve:
            z_lo = float(new.u[new.lo_node * new.ndn + new.nd - 1])
            if z_lo < line_span(*new.curve_support)[0]:
                return None, None, "lift-off passes the stinger's tip (a regime switch)"
        regimes.append(_regime(new))
        stats = {"iterations": steps + int(info[L.I_ITER]), "meshes": 0, "seconds": 0.0,
                 "current_steps": 0, "current_step_max": 0}
        solutions.append(_solution(new, react, stats, touchdown_position(new),
                                   liftoff_position(case, new)))
    for k, part in enumerate(_REGIME_PARTS):
        if len({regime[k] for regime in regimes}) > 1:
            return None, None, f"{part} changes within the step (a regime switch)"
    return solutions, regimes[0], ""

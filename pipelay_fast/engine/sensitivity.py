"""The solved problem carried to neighbouring cases, its regime held: the
engine's half of the implicit function theorem.

With R(U, p) = 0 at the converged state U* of a case with parameter p (the
unknowns U include the contact boundaries' arc lengths, which the mesh
follows with its grading's rates, and the bottom tension), the solution of
the case at p + h on the branch of U*, with the contact set, the slip set
and the regime at the stinger's tip held, is U* + dU with K dU = -R(U*, p +
h) to O(h^2): K the tangent at U*, factored once for every neighbour
(:mod:`pipelay_fast.kernels.response`). The neighbours' states are this
linear map of their residuals, so central differences of them are the
derivative dU/dp = -K^-1 dR/dp to O(h^2) (no Newton step carries nodes
along the pipe).

The case at p + h is built as a solve builds it (:func:`.problem.remesh`):
its mesh's sizes and length of pipe from its own first guess (the flexural
length, and with it the finest element, changes with the tension and the
depth; held, the derivative of a sagbend peak misses a full solve's, S125
2D; the p - h side's may be extrapolated from p's and p + h's,
:func:`mirrored_sizes`), its loads, supports and ends from its own data,
so that a key entering through derived quantities (the water depth's
pressures and current profile, the top tension's equation row, the
current's drag) is differentiated as the model has it. The residual at p +
h is evaluated at U* interpolated onto that mesh.
The output layer differences the post-processed columns
(:mod:`pipelay_fast.output.sensitivity`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..input.case import Case
from ..kernels import layout as L
from ..kernels.response import (
    finish_2d,
    finish_3d,
    residual_2d,
    residual_3d,
    responses_2d,
    responses_3d,
)
from ..kernels.types import Mesh, Settings
from .boundaries import liftoff_position, stinger_foci, touchdown_position
from .continuation import boundary_step, run_newton
from .friction import friction_path
from .problem import guess_sizes, remesh, sized_mesh
from .solver import _solution
from .state import Problem
from .supports import line_span

FRICTION_PATH = (
    "3D with seabed friction under a current: the answer follows the current's load path (its "
    "mesh graded under gravity, the friction springs anchored there, their slip set); "
    "a response at the answer holds neither (Newton from it missed finite differences of "
    "full solves by up to 2 %, S67 3D), and the slip set changes within +-1e-4 of a or of "
    "the current")


def regraded_problem(case: Case, pb: Problem, guessed: dict | None = None,
                     keep_rates: bool = False) -> Problem:
    """The problem of ``case`` (a neighbour of the case ``pb`` solved) on
    the mesh a solve of ``case`` grades at ``pb``'s boundaries: its sizes
    and length of pipe from ``guessed`` (None: ``case``'s first guess's,
    :func:`.problem.guess_sizes`; :func:`.problem.sized_mesh`), its map the
    grading's rates (``keep_rates``: ``pb``'s, ``pb`` itself graded at its
    boundaries), ``pb``'s state interpolated onto it, its contact sets on
    the same boundaries (:func:`.problem.remesh`)."""
    stats = dict(pb.stats)
    sizes = sized_mesh(case, guessed or guess_sizes(case))
    total = sizes.pop("cold_total")
    if "cold_total" not in stats:  # laid pipe was added: the solve's length kept
        total = float(pb.s[-1])
    stats.update(sizes)
    graded = replace(pb, path=replace(pb.path, stats=stats))
    return remesh(case, graded, touchdown_position(pb), stinger_foci(case, pb), grading=True,
                  total=total, keep_rates=keep_rates)


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


def base_solution(case: Case, pb: Problem, sizes: dict):
    """The answer of ``case`` (solved to ``pb``) on the mesh a solve of it
    grades at ``pb``'s boundaries (:func:`regraded_problem`, sized by
    ``sizes``), by Newton from ``pb``'s state to solver.tolerance: the
    state the neighbours are linearised about.

    Returns (that :class:`.state.Problem`, its :class:`.state.Solution`, "")
    or (None, None, the reason): the answer follows the current's path with
    seabed friction (:data:`FRICTION_PATH`), or Newton does not converge."""
    if friction_path(case):
        return None, None, FRICTION_PATH
    new = regraded_problem(case, pb, sizes)
    new.settings.factors = pb.settings.factors.copy()
    new.settings.tolerance = None
    new.settings.in_balance = True  # U* is a refined solution: the boundaries move freely
    status, react, info = run_newton(new, np.zeros_like(new.u), case.solver.tolerance,
                                     case.solver.max_iterations)
    if status != L.OK:
        return None, None, f"Newton from the solution: {L.STATUS_TEXT.get(status, status)}"
    stats = {"iterations": int(info[L.I_ITER]), "meshes": 0, "seconds": 0.0,
             "current_steps": 0, "current_step_max": 0}
    return new, _solution(new, react, stats, touchdown_position(new),
                          liftoff_position(case, new)), ""


def _kernel_args(pb: Problem):
    """The Newton kernel's mesh and settings of ``pb`` (as
    :func:`.continuation.run_newton` passes them)."""
    mesh = Mesh(pb.s_el, pb.mesh.s_a, pb.mesh.s_b, pb.mesh.s_bd, pb.bnodes)
    settings = Settings(1.0, float(pb.settings.fref), float(pb.settings.href), 1, False,
                        boundary_step(pb))
    return mesh, settings


def _kernels(nd: int):
    """The linear response's kernels (residual, responses, finish) for ``nd``."""
    return (residual_2d, responses_2d, finish_2d) if nd == 2 else (residual_3d, responses_3d,
                                                                  finish_3d)


def _residuals(problems, out):
    """Each problem's residual at its state (:func:`.kernels.response.residual_2d`)
    into ``out`` = (g, delta, res_b, cmask, kind), a row each. Returns the
    bordered unknowns' counts."""
    residual = _kernels(problems[0].nd)[0]
    counts = []
    for k, pb in enumerate(problems):
        mesh, settings = _kernel_args(pb)
        counts.append(residual(pb.u, mesh, pb.model(), _copied(pb.kernel_supports()),
                               pb.kernel_ends(np.zeros_like(pb.u)), settings,
                               *(part[k] for part in out)))
    return counts


def neighbour_solutions(cases, base: Problem, guessed):
    """The solutions of ``cases`` (neighbours of the case ``base`` solved,
    :func:`base_solution`), each ``base``'s state interpolated onto the mesh
    a solve of that case grades at ``base``'s boundaries
    (:func:`regraded_problem`, sized by ``guessed``, one per case) and
    stepped by the linear response to its residual there (the module
    docstring; the tangent factored once for them all), in ``base``'s
    regime.

    Returns, for each case, (its :class:`.state.Solution`, "") or (None,
    the reason) where it leaves the regime: its mesh's element count, its
    constraint set or bordered unknowns differ, a rigid point changes
    branch, the slip set changes, lift-off passes the stinger's tip, or the
    tangent is singular."""
    sides = [regraded_problem(case, base, sizes, keep_rates=True)
             for case, sizes in zip(cases, guessed, strict=True)]
    answers = [(None, f"{_REGIME_PARTS[0]} changes within the step (a regime switch)")
               if side.nn != base.nn else None for side in sides]
    kept = [k for k, answer in enumerate(answers) if answer is None]
    m, n, nbr = len(kept), base.u.size, base.bnodes.size + 1
    out = (np.zeros((m + 1, n)), np.zeros((m + 1, n)), np.zeros((m + 1, nbr)),
           np.zeros((m + 1, n), dtype=np.bool_), np.zeros((m + 1, nbr), dtype=np.int64))
    counts = _residuals([*(sides[k] for k in kept), base], out)
    g, delta, res_b, cmask, kind = out
    same = [counts[i] == counts[-1] and (cmask[i] == cmask[-1]).all()
            and (kind[i] == kind[-1]).all() for i in range(m)]
    _residual, responses, finish = _kernels(base.nd)
    du, dz, react = np.zeros((m, n)), np.zeros((m, nbr)), np.zeros((m, n))
    mesh, settings = _kernel_args(base)
    singular = m > 0 and responses(
        base.u.copy(), mesh, base.model(), _copied(base.kernel_supports()),
        base.kernel_ends(np.zeros(n)), settings, g[:m], delta[:m], res_b[:m], du, dz,
        react) < 0
    held = _regime(base)
    for i, k in enumerate(kept):
        if singular:
            answers[k] = (None, "the tangent at the solution is singular")
        elif not same[i]:
            answers[k] = (None, "the constraint set changes within the step (a regime switch)")
        else:
            answers[k] = _stepped(cases[k], sides[k], du[i], dz[i], react[i],
                                  kind[-1][:counts[-1]], held, finish)
    return answers


def _stepped(case: Case, side: Problem, du, dz, react, kind, held, finish):
    """(The :class:`.state.Solution` of ``side`` stepped by ``du`` and the
    bordered steps ``dz`` (their unknowns' ``kind``) with the linearised
    reactions ``react``, ""), or (None, why it left the regime ``held``)."""
    for j, unknown in enumerate(kind):
        if unknown == 0:
            side.tb += dz[j]
        else:
            side.mesh.s_bd[unknown - 2] += dz[j]
    side.mesh.update_nodes()
    mesh, settings = _kernel_args(side)
    if finish(side.u, du, mesh, side.model(), side.kernel_supports(), settings, react) > 0:
        return None, f"{_REGIME_PARTS[4]} changes within the step (a regime switch)"
    if side.lo_node >= 0 and side.has_curve:
        z_lo = float(side.u[side.lo_node * side.ndn + side.nd - 1])
        if z_lo < line_span(*side.curve_support)[0]:
            return None, "lift-off passes the stinger's tip (a regime switch)"
    for part, before, after in zip(_REGIME_PARTS, held, _regime(side), strict=True):
        if before != after:
            return None, f"{part} changes within the step (a regime switch)"
    stats = {"iterations": 0, "meshes": 0, "seconds": 0.0, "current_steps": 0,
             "current_step_max": 0}
    return _solution(side, react, stats, touchdown_position(side),
                     liftoff_position(case, side)), ""


def _copied(sup):
    """A copy of the kernel's supports ``sup`` (an evaluation rewrites the
    nodal frames and the lateral hold, which a solution's output reads)."""
    return type(sup)(*(part.copy() for part in sup))

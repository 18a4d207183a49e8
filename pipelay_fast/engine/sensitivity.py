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
h is evaluated at U* interpolated onto that mesh. With seabed friction on
the current's path, the friction springs' anchors are part of the answer
(laid along the path): every neighbour takes the answer's anchors at its
nodes' material points and the answer's slip set, held (:func:`held_answer`).
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
from ..kernels.scene import in_scene
from ..kernels.types import Mesh, Settings
from .boundaries import liftoff_position, stinger_foci, touchdown_position
from .continuation import boundary_step, run_newton
from .friction import friction_path, slip_positions
from .problem import guess_sizes, remesh, sized_mesh
from .solver import _solution
from .state import Problem
from .supports import line_span
from .tuning import HELD_SLIP

ELASTIC_FRICTION = (
    "seabed friction on an elastic seabed under a current: the springs' normal force is "
    "the foundation's, which the Newton kernel updates between iterations "
    "(kernels.contact.friction_track) and its tangent does not carry")


def regraded_problem(case: Case, pb: Problem, guessed: dict | None = None,
                     keep_rates: bool = False, anchors: Problem | None = None) -> Problem:
    """The problem of ``case`` (a neighbour of the case ``pb`` solved) on
    the mesh a solve of ``case`` grades at ``pb``'s boundaries: its sizes
    and length of pipe from ``guessed`` (None: ``case``'s first guess's,
    :func:`.problem.guess_sizes`; :func:`.problem.sized_mesh`), its map the
    grading's rates (``keep_rates``: ``pb``'s, ``pb`` itself graded at its
    boundaries), ``pb``'s state interpolated onto it, its contact sets on
    the same boundaries (:func:`.problem.remesh`), with seabed friction on
    the current's path the friction springs of ``anchors`` (None: ``pb``;
    :func:`carry_anchors`) and ``pb``'s load factors."""
    stats = dict(pb.stats)
    sizes = sized_mesh(case, guessed or guess_sizes(case))
    total = sizes.pop("cold_total")
    if "cold_total" not in stats:  # laid pipe was added: the solve's length kept
        total = float(pb.s[-1])
    stats.update(sizes)
    graded = replace(pb, path=replace(pb.path, stats=stats))
    new = remesh(case, graded, touchdown_position(pb), stinger_foci(case, pb), grading=True,
                 total=total, keep_rates=keep_rates)
    new.settings.factors = pb.settings.factors.copy()  # (friction on, on its path)
    if friction_path(case):
        carry_anchors(pb if anchors is None else anchors, new)
    return new


def carry_anchors(pb: Problem, new: Problem):
    """The friction springs of ``pb`` onto ``new`` (``pb`` regraded): the
    anchors belong to material points (:func:`..kernels.contact.anchor_at`,
    piecewise linear in their arc lengths ``FR_S``), so each of ``new``'s
    nodes takes the anchors of its material point, ``pb``'s arc length plus
    the laid pipe prepended (``new``'s own position where that is new pipe:
    :func:`.problem.remesh` anchored it there); its slip directions and
    normal force are those of ``pb``'s node nearest to it, the force 0 off
    the seabed's contact (as the Newton kernel's tracking leaves it,
    :func:`..kernels.contact.friction_track`: a rigid seabed's contact
    reads its own)."""
    extra = float(new.s[-1] - pb.s[-1])
    old, fric = pb.contacts.fric, new.contacts.fric
    points = new.s - extra
    laid = points >= old[0, L.FR_S]
    for col in (L.FR_Y, L.FR_Z):
        fric[laid, col] = np.interp(points[laid], old[:, L.FR_S], old[:, col])
    right = np.clip(np.searchsorted(pb.s, points[laid]), 1, pb.nn - 1)
    nearest = right - (points[laid] - pb.s[right - 1] < pb.s[right] - points[laid])
    for col in (L.FR_W, L.FR_DIR, L.FR_DIRZ):
        fric[laid, col] = old[nearest, col]
    fric[new.contacts.bed_active == 0, L.FR_W] = 0.0


def hold_slips(pb: Problem):
    """Hold ``pb``'s slip set for its neighbours (:data:`.tuning.HELD_SLIP`):
    each sliding spring (``FR_DIR`` or ``FR_DIRZ`` not 0, as the answer's
    return mapping, :func:`..kernels.contact.friction_commit`, left it) has
    its anchor moved to HELD_SLIP d_slip behind the pipe, its force the
    same."""
    fric = pb.contacts.fric
    d_slip = pb.props[L.FRICTION_SLIP]
    lateral, along = slip_positions(pb.u, pb.nd, pb.props)
    for col, dcol, pos in ((L.FR_Y, L.FR_DIR, lateral), (L.FR_Z, L.FR_DIRZ, along)):
        sliding = fric[:, dcol] != 0.0
        if pos is not None and sliding.any():
            fric[sliding, col] = pos[sliding] + fric[sliding, dcol] * HELD_SLIP * d_slip
            fric[sliding, L.FR_S] = pb.s[sliding]


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


def held_answer(case: Case, pb: Problem) -> tuple[Problem | None, str]:
    """(The answer ``pb`` of ``case`` as its neighbours start from, ""), or
    (None, why it has no sensitivities). With seabed friction on the
    current's path its anchors are the laid pipe's, its slip set held
    (:func:`hold_slips`, on a copy of its springs): the sensitivities are
    those of the pipe laid as it lies, not of a lay redone from its gravity
    state; every neighbour takes these anchors (:func:`carry_anchors`), the
    anchor of a material point being piecewise linear between the answer's
    nodes."""
    if not friction_path(case):
        return pb, ""
    if not case.seabed.is_rigid:
        return None, ELASTIC_FRICTION
    held = replace(pb, contacts=replace(pb.contacts, fric=pb.contacts.fric.copy()))
    hold_slips(held)
    return held, ""


def base_solution(case: Case, pb: Problem, sizes: dict):
    """The answer of ``case`` (solved to ``pb``, :func:`held_answer`) on the
    mesh a solve of it grades at ``pb``'s boundaries (:func:`regraded_problem`,
    sized by ``sizes``), by Newton from ``pb``'s state to solver.tolerance:
    the state the neighbours are linearised about, its slip set held.

    Returns (that :class:`.state.Problem`, its :class:`.state.Solution`, "")
    or (None, None, the reason): Newton does not converge."""
    new = regraded_problem(case, pb, sizes)
    new.settings.tolerance = None
    new.settings.in_balance = True  # U* is a refined solution: the boundaries move freely
    status, react, info = run_newton(new, np.zeros_like(new.u), case.solver.tolerance,
                                     case.solver.max_iterations)
    if status != L.OK:
        return None, None, f"Newton from the solution: {L.STATUS_TEXT.get(status, status)}"
    if friction_path(case):
        hold_slips(new)
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


def _kernels(pb: Problem):
    """The linear response's kernels (residual, responses, finish) for
    ``pb``'s dimension and scene (:attr:`.state.Problem.scene`)."""
    kernels = (residual_2d, responses_2d, finish_2d) if pb.nd == 2 else (
        residual_3d, responses_3d, finish_3d)
    return tuple(in_scene(kernel, pb.scene) for kernel in kernels)


def _residuals(problems, out):
    """Each problem's residual at its state (:func:`.kernels.response.residual_2d`)
    into ``out`` = (g, delta, res_b, cmask, kind), a row each, and its
    lateral hold (3D: the nodes the stinger holds,
    :func:`.kernels.contact.lateral_hold`) as that evaluation marks it, as
    a solve's last evaluation leaves it for the profile (the lateral
    curvature there is the free side's). Returns the bordered unknowns'
    counts."""
    residual = _kernels(problems[-1])[0]
    counts = []
    for k, pb in enumerate(problems):
        mesh, settings = _kernel_args(pb)
        sup = _copied(pb.kernel_supports())
        counts.append(residual(pb.u, mesh, pb.model(), sup, pb.kernel_ends(np.zeros_like(pb.u)),
                               settings, *(part[k] for part in out)))
        pb.contacts.y_held[:] = sup.y_held
    return counts


def neighbour_solutions(cases, base: Problem, guessed, anchors: Problem | None = None):
    """The solutions of ``cases`` (neighbours of the case ``base`` solved,
    :func:`base_solution`), each ``base``'s state interpolated onto the mesh
    a solve of that case grades at ``base``'s boundaries
    (:func:`regraded_problem`, sized by ``guessed``, one per case) and
    stepped by the linear response to its residual there (the module
    docstring; the tangent factored once for them all), in ``base``'s
    regime, with seabed friction the springs of ``anchors`` (the held answer,
    :func:`held_answer`; None: ``base``'s).

    Returns, for each case, (its :class:`.state.Solution`, "") or (None,
    the reason) where it leaves the regime: its mesh's element count, its
    constraint set or bordered unknowns differ, a rigid point changes
    branch, the slip set changes, lift-off passes the stinger's tip, or the
    tangent is singular."""
    sides = [regraded_problem(case, base, sizes, keep_rates=True, anchors=anchors)
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
    _residual, responses, finish = _kernels(base)
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

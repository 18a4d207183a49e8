"""Solve one case: first guess, mesh, constraints, Newton with load-path fallback.

The orchestration lives here and in the modules it calls; every loop over
nodes or elements is a kernel in :mod:`pipelay_fast.kernels`. The path of a
solve:

1. natural-catenary guess (:mod:`.catenary`) plus the laid pipe, a mesh
   graded at touchdown and the top (:mod:`.mesh`), the constraints as flat
   arrays (:func:`.problem.build_problem`);
2. the mesh mapped onto the contact boundaries, which are unknowns of Newton
   (:mod:`.boundaries`);
3. Newton with line search (:func:`.kernels.newton.newton_2d`, ``newton_3d``), switching
   between lifting off and bearing on the stinger's tip when the kernel stops
   at the change of regime; if it fails, the out-of-balance force of the
   guess is removed in adaptive load steps, and the current is then applied
   in increments (friction is path dependent) (:mod:`.continuation`);
4. under gravity, until the mesh is graded at the boundaries the solve found
   (or when touchdown came too close to the lower end), the mesh is graded
   anew there and the solve repeated from the interpolated solution, so the
   answer does not depend on the path to it (:func:`_solve_mesh`);
5. the profile and summary (:mod:`.results`), refused if not finite or
   strained beyond the model.
"""

from __future__ import annotations

import time

import numpy as np

from ..input.case import Case
from ..input.errors import SolveError
from ..input.limits import IterationBudget
from ..input.surface import check_water
from ..kernels import layout as L
from ..kernels.contact import friction_track
from . import tuning as T
from .boundaries import (
    check_final_regime,
    graded_on_boundaries,
    last_roller_in_contact,
    lateral_hold_start,
    liftoff_position,
    roller_gaps,
    stinger_foci,
    touchdown_position,
    touchdown_spans,
)
from .continuation import ShortLaid, apply_current, newton_with_fallback
from .friction import anchor_friction, friction_path
from .guess import guide_case
from .problem import build_problem, remesh, roller_problem
from .state import Problem, Solution, restore, snapshot
from .warm import warm_problem


def solve_problem(case: Case, warm: Problem | None = None):
    """Solve with enough laid pipe: when the lower end, held laterally, carries
    more than tuning.LOWER_END_SHARE of the laid pipe's lateral force (friction has not
    taken it all up), the laid length is doubled (:func:`more_laid`) and the case
    solved again, until solver.max_elements refuses the mesh (a current the
    friction cannot hold: the error says so).
    ``warm``: the solved problem of a neighbouring case to start from. All
    the passes share one budget of solver.max_iterations_total iterations.

    Returns (the solved problem, for a neighbour's warm start; its
    :class:`.state.Solution`).

    Raises
    ------
    SolveError
        When no equilibrium is found within the budget, or the answer lifts
        off below the stinger's tip (:func:`.boundaries.check_final_regime`).
    ValueError
        When the laid pipe, doubled, would exceed solver.max_elements, or a
        mesh reaches where the seabed rises to the still water level
        (:func:`pipelay_fast.input.surface.check_water`, before its solve).
    """
    t0 = time.perf_counter()
    laid = None  # the case's
    budget = IterationBudget(case.solver.max_iterations_total)
    meshes = 0
    while True:  # ended by the budget, or by solver.max_elements as the laid pipe doubles
        pb, react, stats, s_t, s_l = _solve_mesh(case, warm, budget, laid)
        s_g = stats.pop("gravity_touchdown", s_t)
        warm = None
        meshes += stats["meshes"]
        if not _lower_end_holds(pb, react) or case.lay.pipe_length is not None:
            # the passes with the laid length doubled count too
            stats["iterations"], stats["meshes"] = budget.used, meshes
            stats["seconds"] = time.perf_counter() - t0
            check_final_regime(case, pb)
            return pb, _solution(pb, react, stats, s_t, s_l)
        # doubled from the laid pipe the mesh has: its touchdown under gravity,
        # or under the current when that lies further from the lower end (the
        # current moves touchdown along the pipe, by far more than the laid
        # pipe at times)
        laid = more_laid(pb, max(s_t, s_g))


def _lower_end_holds(pb: Problem, react) -> bool:
    """True when the lower end, held laterally, carries more than tuning.LOWER_END_SHARE
    of the lateral force on the laid pipe: the slipping (or elastically held)
    zone then reaches it, and more laid pipe is needed."""
    if pb.nd != 3 or pb.settings.factors[L.F_FRICTION] == 0.0:
        return False
    on_bed = np.flatnonzero(pb.contacts.fric[:, L.FR_W] > 0.0)
    total = np.abs(react[on_bed * pb.ndn + 1]).sum() + abs(react[1])
    return abs(react[1]) > T.LOWER_END_SHARE * total


def _solve_mesh(case: Case, warm: Problem | None, budget: IterationBudget,
                laid: float | None = None):
    """Solve under gravity, grading the mesh anew at the boundaries found until
    it is graded at them (:func:`graded_on_boundaries`) or would be graded
    again at boundaries it was graded at before (a cycle), then follow the
    current's path (the mesh follows the boundaries it moves). ``budget``:
    the solve's Newton iterations left; ``laid``: the first mesh's laid
    pipe [m] (None: the case's; a cold start only).

    Returns (problem, reactions, stats, touchdown and lift-off arc lengths [m]).
    """
    t0 = time.perf_counter()
    guided = warm is None and case.lay.has_rollers
    guide_iterations = 0
    if warm is not None:
        pb = warm_problem(case, warm)
    elif guided:
        pb, guide_iterations = _from_guide(case, budget, laid)
    else:
        pb = build_problem(case, laid)
    check_water(case, pb.u[pb.nd - 1::pb.ndn])  # the seabed below the water along the mesh
    # friction is path dependent: gravity first, then the current in steps
    path = friction_path(case)
    if path:
        pb.on_gravity_path()
    # graded, the first mesh only to tuning.LOOSE_TOLERANCE: it is to find where
    # the boundaries are, and is graded anew there unless it already is
    pb.settings.tolerance = (max(case.solver.tolerance, T.LOOSE_TOLERANCE)
                    if case.solver.grading and not guided else None)
    pb, react, stats = _solve_gravity(case, pb, budget)
    stats["iterations"] += guide_iterations
    passes = 1
    made = []  # the boundaries [m] each regrade of this pipe's length was graded at
    while True:
        s_t = touchdown_position(pb)
        foci = stinger_foci(case, pb)
        short = laid_short(case, pb, s_t)
        # the mesh follows the boundaries: graded anew at them until it is
        # graded where they are, and when laid pipe is short; ungraded, it
        # follows them with its one mesh, but for the lateral hold's start in
        # 3D, which no unknown follows: a node is put there (its elements
        # then uniform between the nodes), as often as grading would
        one_mesh = not case.solver.grading and lateral_hold_start(case, pb) is None
        # graded anew too where the mesh models another length of pipe than
        # the cold start (a warm start's first mesh, the neighbour's), unless
        # laid pipe had to be added
        total = pb.stats.get("cold_total")
        cold_length = total is None or abs(total - pb.s[-1]) <= T.REL_ROUNDOFF * total
        # ... and not when it would be graded at boundaries it was graded at
        # before (a cycle: the regrades do not settle)
        at = [s_t, *foci]
        again = not short and cold_length and any(
            len(before) == len(at)
            and max(abs(a - b) for a, b in zip(before, at, strict=True))
            <= T.ON_FOCUS * pb.stats["h_min"]
            for before in made)
        if (one_mesh or again
                or (graded_on_boundaries(case, pb) and not short and cold_length)):
            if pb.settings.tolerance is not None:  # on to the tolerance, this mesh
                pb.settings.tolerance = None
                pb.settings.in_balance = True  # the loose pass's solution, refined
                pb, react, more = _solve_gravity(case, pb, budget)
                stats = {key: stats[key] + more[key] for key in stats}
                s_t = touchdown_position(pb)
                foci = stinger_foci(case, pb)
            break
        # (laid pipe added, or regraded to the cold start's length: another pipe)
        made = [*made, at] if cold_length and not short else []
        pb = remesh(case, pb, s_t, foci, grading=True, total=total,
                    laid=more_laid(pb, s_t) if short else None)
        if total is not None and abs(pb.s[-1] - total) > T.REL_ROUNDOFF * total:
            pb.stats.pop("cold_total")  # laid pipe added (short), as the cold start would
        pb.settings.tolerance = None  # graded at the boundaries: to the tolerance
        if path:
            pb.on_gravity_path()
        # interpolated, the state is near balance, bearing on the tip too:
        # the first iteration need not hold the boundaries
        pb.settings.in_balance = True
        pb, react, more = _solve_gravity(case, pb, budget)
        stats = {key: stats[key] + more[key] for key in stats}
        passes += 1
    if path:
        pb, react, stats, s_t, passes = _current_path(case, pb, react, stats, budget, passes)
    stats.setdefault("current_steps", 0)  # no current's path: planar, or no friction
    stats.setdefault("current_step_max", 0)
    stats["meshes"] = passes + stats.pop("laid_added")
    stats["seconds"] = time.perf_counter() - t0
    return pb, react, stats, s_t, liftoff_position(case, pb)


def _current_path(case: Case, pb: Problem, react, stats: dict, budget: IterationBudget,
                  passes: int):
    """Follow the current's path from ``pb``'s gravity answer (reactions
    ``react``), adding laid pipe and solving gravity again when touchdown runs
    toward the lower end or a step leaves the lower end holding the laid pipe.
    Returns (problem, reactions, stats, touchdown's arc length [m], passes)."""
    while True:
        # along the current's path the boundaries move far: the mesh follows
        # them in zones, not with its whole grading, but for touchdown,
        # which the mesh follows over the spans beside it (:func:`touchdown_spans`)
        rates = pb.mesh.zone_b if pb.mesh.zone_b is not None else pb.mesh.s_b
        if rates is not None:
            pb.mesh.follow_rates(pb.bnodes, touchdown_spans(pb, rates))
        pb.path.before_current = snapshot(pb)
        stats["gravity_touchdown"] = touchdown_position(pb)
        # friction springs anchored where the pipe lies under gravity alone
        anchor_friction(pb.contacts.fric, pb.u, pb.nd, pb.s, pb.props)
        friction_track(pb.nd, pb.u, react, pb.props, pb.bed, pb.contacts.bed_active,
                       pb.contacts.fric, pb.s)
        pb.settings.factors[L.F_FRICTION] = 1.0
        try:
            react, more = apply_current(case, pb, budget, laid_holds=(
                None if case.lay.pipe_length is not None else _lower_end_holds))
            short = False
        except ShortLaid:  # touchdown ran toward the lower end under the current,
            # or a step left the lower end holding the laid pipe
            short = True
        if not short:
            # the mesh follows the boundaries the current moves
            stats["iterations"] += more["iterations"]
            stats["load_steps"] += more["load_steps"]
            stats["current_steps"] = more["load_steps"]
            stats["current_step_max"] = more["step_max"]
            s_t = touchdown_position(pb)
            break
        # more laid pipe, from the pipe under gravity alone, and the path again
        restore(pb, pb.path.before_current)
        pb = _with_more_laid(case, pb)
        pb.on_gravity_path()
        pb, react, more = _solve_gravity(case, pb, budget)
        stats = {key: stats[key] + more[key] for key in stats if key in more}
        passes += 1
    return pb, react, stats, s_t, passes


def _from_guide(case: Case, budget: IterationBudget, laid: float | None = None):
    """A roller stinger's start: its guide (the quadratic stinger through the
    rollers, :func:`.guess.guide_case`) solved under gravity on its first
    mesh to tuning.LOOSE_TOLERANCE, then the roller problem built from that answer
    (:func:`.problem.roller_problem`): from the first guess itself the
    rollers' contacts swing while the pipe finds its balance; the curve's
    single boundary does not (measured: benchmarks/bench_rollers.py).

    Returns (problem, the guide's Newton iterations)."""
    guide = guide_case(case)
    pb = build_problem(guide, laid)
    if friction_path(guide):
        pb.on_gravity_path()
    pb.settings.tolerance = max(case.solver.tolerance, T.LOOSE_TOLERANCE)
    try:
        pb, _react, stats = _solve_gravity(guide, pb, budget)
    except SolveError as err:
        raise SolveError(f"case {case.name!r}: the roller stinger's start, the quadratic "
                         f"stinger fitted through its rollers (a = {guide.lay.stinger.a:.6g} 1/m, "
                         f"tip at {list(guide.lay.stinger.lower)}), did not solve: {err}") from err
    return roller_problem(case, pb), stats["iterations"]


def _solve_gravity(case: Case, pb: Problem, budget: IterationBudget):
    """:func:`newton_with_fallback`, with laid pipe prepended each time Newton
    stops because touchdown runs toward the modelled lower end (SHORT_LAID).

    Returns (problem, reactions, iteration counts and the meshes laid pipe
    was prepended to, "laid_added").
    """
    used = budget.used
    added = 0
    while True:  # ended by the budget, or by solver.max_elements as the laid pipe doubles
        try:
            react, stats = newton_with_fallback(case, pb, budget)
        except ShortLaid:
            pb = _with_more_laid(case, pb)
            added += 1
            continue
        stats["iterations"] = budget.used - used  # the stopped calls' too
        stats["laid_added"] = added  # meshes with laid pipe prepended
        return pb, react, stats


def laid_short(case: Case, pb: Problem, s_t: float) -> bool:
    """Whether the mesh models too little laid pipe behind touchdown at
    ``s_t`` [m]: less than tuning.LAID_LENGTHS flexural lengths (never with a
    given pipe length, which has no more pipe). The one rule for laid pipe
    with :func:`more_laid`: the regrading passes, Newton stopping as
    touchdown runs toward the lower end (SHORT_LAID, :func:`_with_more_laid`)
    and the lower end carrying friction's force (:func:`solve_problem`)."""
    return case.lay.pipe_length is None and s_t < T.LAID_LENGTHS * pb.stats["flexural_length"]


def more_laid(pb: Problem, s_t: float) -> float:
    """The laid pipe [m] to model behind touchdown at ``s_t`` [m] when there
    is too little: tuning.LOAD_STEP_FACTOR (2) times what the mesh has, and
    at least that times tuning.LAID_LENGTHS flexural lengths."""
    return T.LOAD_STEP_FACTOR * max(s_t, T.LAID_LENGTHS * pb.stats["flexural_length"])


def _with_more_laid(case: Case, pb: Problem) -> Problem:
    """The mesh with :func:`more_laid` laid pipe: touchdown ran toward the
    lower end. A given pipe length has no more pipe: SolveError."""
    s_t = touchdown_position(pb)
    if case.lay.pipe_length is not None:
        raise SolveError(f"case {case.name!r}: touchdown runs into the lower end, held at "
                         f"lay.pipe_length = {case.lay.pipe_length!r} m (the pipe is too "
                         "short to reach the seabed and lie on it)")
    pb.stats.pop("cold_total", None)  # a warm start's too: laid pipe added, as the cold start would
    new = remesh(case, pb, s_t, stinger_foci(case, pb), laid=more_laid(pb, s_t))
    check_water(case, new.u[new.nd - 1::new.ndn])  # the laid pipe added below the water too
    return new


def _solution(pb: Problem, react, stats: dict, s_t: float, s_l: float | None) -> Solution:
    """The :class:`.state.Solution` of the solved problem ``pb`` with its
    reactions ``react``, counts ``stats`` and touchdown and lift-off arc
    lengths [m]."""
    c = pb.contacts
    tip = None
    if pb.has_curve and pb.tip[0] != 0.0:  # bearing: a node follows the tip
        tip = (int(pb.tip_node), float(pb.tip[1]))
    rollers = not pb.has_curve and len(c.points) > 0
    return Solution(
        nd=pb.nd, s=pb.s, u=pb.u,
        bottom_tension=float(pb.tb[0]) if pb.ends.slide_dof >= 0 else None,
        react=react, phi_r=c.phi_r, bed_active=c.bed_active, st_active=c.st_active,
        fric=c.fric, points=c.points, y_held=c.y_held,
        torque=float(pb.props[L.TORQUE]) if pb.nd == 3 else 0.0,
        lo_node=pb.lo_node, tip=tip, roller_nodes=pb.roller_nodes,
        roller_gaps=roller_gaps(pb) if rollers else np.zeros(0),
        last_roller=last_roller_in_contact(pb) if rollers else None,
        s_tdp=s_t, s_liftoff=s_l, stats=stats,
        top_jump=0.0 if pb.clear_of_stinger else pb.ends.pin_jump)


__all__ = ["Problem", "SolveError", "Solution", "solve_problem"]

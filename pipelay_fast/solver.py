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

import math
import time

import numpy as np

from .boundaries import (
    MAX_TIP_SWITCHES,
    graded_on_boundaries,
    lateral_hold_start,
    liftoff_position,
    stinger_foci,
    touchdown_position,
)
from .case import Case
from .continuation import ShortLaid, apply_current, newton_with_fallback
from .errors import SolveError
from .guess import guide_case
from .kernels import layout as L
from .kernels.contact import friction_track
from .kernels.layout import ST_ZL
from .limits import IterationBudget, strain_beyond_line
from .problem import (
    Problem,
    anchor_friction,
    build_problem,
    friction_path,
    remesh,
    restore,
    roller_problem,
    snapshot,
    warm_problem,
)
from .results import Result, build_profile, build_rollers, build_summary

MAX_MESH_PASSES = 4
# The first mesh's Newton tolerance [-]. That mesh is to find where the
# boundaries are; the mesh graded there moves them by its own discretisation
# (S67 2D at 4 m, bearing on the tip: re-contact 0.33 m), so they are not
# wanted closer. 1e-3 against 1e-4: quick grid 4667 -> 4357 iterations (260
# solves fewer, 6 more), planar 1785 -> 1645, warm 1482 -> 1453, the same
# answers (3.6e-9); 1e-2 lost a random case, 1e-1 S67 2D cases.
LOOSE_TOLERANCE = 1e-3


MAX_LAID_DOUBLINGS = 6


def solve_problem(case: Case, warm: Problem | None = None):
    """Solve with enough laid pipe: when the lower end, held laterally, carries
    more than LOWER_END_SHARE of the laid pipe's lateral force (friction has not
    taken it all up), the laid length is doubled and the case solved again.
    ``warm``: the solved problem of a neighbouring case to start from. All
    the passes share one budget of solver.max_iterations_total iterations.

    Returns (problem, reactions, stats, touchdown and lift-off arc lengths [m]).
    """
    t0 = time.perf_counter()
    current = case
    budget = IterationBudget(case.solver.max_iterations_total)
    meshes = 0
    for _ in range(MAX_LAID_DOUBLINGS + 1):
        pb, react, stats, s_t, s_l = _solve_mesh(current, warm, budget)
        warm = None
        meshes += stats["meshes"]
        if not _lower_end_holds(pb, react) or case.lay.pipe_length is not None:
            # the passes with the laid length doubled count too
            stats["iterations"], stats["meshes"] = budget.used, meshes
            stats["seconds"] = time.perf_counter() - t0
            return pb, react, stats, s_t, s_l
        laid = s_t + pb.stats["flexural_length"]  # what this mesh modelled behind touchdown
        current = current.with_changes({"solver.laid_length": 2.0 * laid})
    raise SolveError(
        f"case {case.name!r}: seabed friction does not hold the laid pipe before its "
        f"modelled lower end even with {current.solver.laid_length:.0f} m of it (the current "
        "on the laid pipe may exceed the friction); check seabed.lateral_friction and the "
        "current profile, or set solver.laid_length"
    )


LOWER_END_SHARE = 0.01  # largest share of the seabed's lateral force the held lower end may carry


def _lower_end_holds(pb: Problem, react) -> bool:
    """True when the lower end, held laterally, carries more than LOWER_END_SHARE
    of the lateral force on the laid pipe: the slipping (or elastically held)
    zone then reaches it, and more laid pipe is needed."""
    if pb.nd != 3 or pb.factors[L.F_FRICTION] == 0.0:
        return False
    on_bed = np.flatnonzero(pb.fric[:, L.FR_W] > 0.0)
    total = np.abs(react[on_bed * pb.ndn + 1]).sum() + abs(react[1])
    return abs(react[1]) > LOWER_END_SHARE * total


def _solve_mesh(case: Case, warm: Problem | None, budget: IterationBudget):
    """Solve under gravity, grading the mesh anew at the boundaries found until
    it is graded at them (:func:`graded_on_boundaries`), then follow the
    current's path (the mesh follows the boundaries it moves). ``budget``:
    the solve's Newton iterations left.

    Returns (problem, reactions, stats, touchdown and lift-off arc lengths [m]).
    """
    t0 = time.perf_counter()
    guided = warm is None and case.lay.has_rollers
    guide_iterations = 0
    if warm is not None:
        pb = warm_problem(case, warm)
    elif guided:
        pb, guide_iterations = _from_guide(case, budget)
    else:
        pb = build_problem(case)
    # friction is path dependent: gravity first, then the current in steps
    path = friction_path(case)
    if path:
        pb.on_gravity_path()
    # graded, the first mesh only to LOOSE_TOLERANCE: it is to find where
    # the boundaries are, and is graded anew there unless it already is
    pb.tolerance = (max(case.solver.tolerance, LOOSE_TOLERANCE)
                    if case.solver.grading and not guided else None)
    pb, react, stats = _solve_gravity(case, pb, budget)
    stats["iterations"] += guide_iterations
    passes = 1
    while True:
        s_t = touchdown_position(pb)
        foci = stinger_foci(case, pb)
        lam = pb.stats["flexural_length"]
        short_laid = case.lay.pipe_length is None and s_t < 0.5 * lam
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
        cold_length = total is None or abs(total - pb.s[-1]) <= 1e-9 * total
        if (one_mesh or passes >= MAX_MESH_PASSES
                or (graded_on_boundaries(case, pb) and not short_laid and cold_length)):
            if pb.tolerance is not None:  # on to the tolerance, this mesh
                pb.tolerance = None
                pb.in_balance = True  # the loose pass's solution, refined
                pb, react, more = _solve_gravity(case, pb, budget)
                stats = {key: stats[key] + more[key] for key in stats}
                s_t = touchdown_position(pb)
                foci = stinger_foci(case, pb)
            break
        pb = remesh(case, pb, s_t, foci, grading=True, total=total)
        if total is not None and abs(pb.s[-1] - total) > 1e-9 * total:
            pb.stats.pop("cold_total")  # laid pipe added (short), as the cold start would
        pb.tolerance = None  # graded at the boundaries: to the tolerance
        if path:
            pb.on_gravity_path()
        # interpolated, the state is near balance, bearing on the tip too
        # (held there, the first iteration cost 2 more a solve: full grid,
        # S67 2D 4742 -> 4480 iterations, S125 2D 5770 -> 5131, none more;
        # it once kept re-contact from a start one flexural length off)
        pb.in_balance = True
        pb, react, more = _solve_gravity(case, pb, budget)
        stats = {key: stats[key] + more[key] for key in stats}
        passes += 1
    while path:
        # along the current's path the boundaries move far: the mesh follows
        # them in zones, not with its whole grading (which would stretch the
        # laid pipe, and its friction springs, all the way to the lower end)
        if pb.zone_b is not None:
            pb.follow_rates(pb.bnodes, pb.zone_b)
        pb.before_current = snapshot(pb)
        # friction springs anchored where the pipe lies under gravity alone
        anchor_friction(pb.fric, pb.u, pb.nd, pb.s)
        friction_track(pb.nd, pb.u, react, pb.props, pb.bed_active, pb.fric, pb.s)
        pb.factors[L.F_FRICTION] = 1.0
        try:
            react, more = apply_current(case, pb, budget)
            short = False
        except ShortLaid:  # touchdown ran toward the lower end under the current
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
        restore(pb, pb.before_current)
        pb = _with_more_laid(case, pb)
        pb.on_gravity_path()
        pb, react, more = _solve_gravity(case, pb, budget)
        stats = {key: stats[key] + more[key] for key in stats}
        passes += 1
    stats.setdefault("current_steps", 0)  # no current's path: planar, or no friction
    stats.setdefault("current_step_max", 0)
    stats["meshes"] = passes + stats.pop("laid_added")
    stats["seconds"] = time.perf_counter() - t0
    return pb, react, stats, s_t, liftoff_position(case, pb)


def _from_guide(case: Case, budget: IterationBudget):
    """A roller stinger's start: its guide (the quadratic stinger through the
    rollers, :func:`.guess.guide_case`) solved under gravity on its first
    mesh to LOOSE_TOLERANCE, then the roller problem built from that answer
    (:func:`.problem.roller_problem`). From the first guess itself the
    rollers' contacts swung for 5 to 30 iterations while the pipe found its
    balance (S67 2D at 1 to 8 m elements, rollers on the paper's curve every
    1.5 to 12 m; 1.5 m diverged); the curve's single boundary does not, and
    from its answer the rollers take 3 to 6 more (the grid: 7 to 9 in all).

    Returns (problem, the guide's Newton iterations)."""
    guide = guide_case(case)
    pb = build_problem(guide)
    if friction_path(guide):
        pb.on_gravity_path()
    pb.tolerance = max(case.solver.tolerance, LOOSE_TOLERANCE)
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
    for added in range(MAX_LAID_DOUBLINGS + 1):
        try:
            react, stats = newton_with_fallback(case, pb, budget)
        except ShortLaid:
            pb = _with_more_laid(case, pb)
            continue
        stats["iterations"] = budget.used - used  # the stopped calls' too
        stats["laid_added"] = added  # meshes with laid pipe prepended
        return pb, react, stats
    raise SolveError(f"case {case.name!r}: touchdown still runs toward the lower end with "
                     f"{touchdown_position(pb):.4g} m of laid pipe modelled after "
                     f"{MAX_LAID_DOUBLINGS} doublings of it; the case may have no touchdown")


def _with_more_laid(case: Case, pb: Problem) -> Problem:
    """The mesh with its laid pipe doubled (at least two flexural lengths):
    touchdown ran toward the lower end. A given pipe length has no more pipe:
    SolveError."""
    s_t = touchdown_position(pb)
    if case.lay.pipe_length is not None:
        raise SolveError(f"case {case.name!r}: touchdown runs into the lower end, held at "
                         f"lay.pipe_length = {case.lay.pipe_length!r} m (the pipe is too "
                         "short to reach the seabed and lie on it)")
    lam = pb.stats["flexural_length"]
    pb.stats.pop("cold_total", None)  # a warm start's too: laid pipe added, as the cold start would
    return remesh(case, pb, s_t, stinger_foci(case, pb), laid=max(2.0 * lam, 2.0 * s_t))


def solve(case: Case, *, warm: Result | None = None) -> Result:
    """Solve one case.

    ``warm``: the result of a neighbouring case (same dimension and lay method,
    e.g. the previous `a` of a sweep); Newton starts from its solution on its
    mesh instead of from the catenary guess, and falls back to the catenary
    guess if that fails (or if its answer is refused).

    Returns
    -------
    Result
        ``.summary`` (dict, the columns of ``results.SUMMARY_UNITS``) and ``.profile`` (DataFrame,
        one row per node).

    Raises
    ------
    SolveError
        When Newton and the load-path fallback both fail, or
        solver.max_iterations_total Newton iterations are spent (each start,
        warm and cold, has its own budget); the message names the case, the
        load step, the residual and the reason. Also when the answer is
        refused: non-finite, strained beyond solver.max_strain, or lifting
        off below the stinger's tip (:func:`_check_regime`). An answer whose
        contact pulls is not refused: the contact boundaries' equations
        leave none (none in the grids and random cases of
        ``benchmarks/bench_contact.py``).
    ValueError
        When the mesh would exceed solver.max_elements (checked before it is
        built).
    """
    if warm is not None and not isinstance(getattr(warm, "state", None), Problem):
        raise ValueError("warm: expected a Result from pipelay_fast.solve, got "
                         f"{type(warm).__name__}")
    if warm is not None:
        try:
            return _checked_solve(case, warm.state)
        except SolveError:  # a neighbour too far away: start from the catenary
            pass
    return _checked_solve(case)


def _checked_solve(case: Case, warm: Problem | None = None) -> Result:
    """Solve, build the result and refuse it if it is not finite or is
    strained beyond solver.max_strain."""
    pb, react, stats, s_t, s_l = solve_problem(case, warm)
    _check_regime(case, pb)
    columns = build_profile(case, pb, react)
    rollers = build_rollers(case, pb, react)
    summary = build_summary(case, pb, columns, stats, s_t, s_l, rollers)
    bad = [key for key, val in summary.items() if isinstance(val, float) and math.isinf(val)]
    bad += [key for key, col in columns.items()
            if col.dtype.kind == "f" and not np.isfinite(col).all()]
    if bad:
        raise SolveError(f"case {case.name!r}: the solution has non-finite values in "
                         f"{', '.join(bad)}; it is not returned")
    beyond = strain_beyond_line(case, columns)
    if beyond is not None:
        raise SolveError(f"case {case.name!r}: {beyond}")
    return Result(case, summary, columns, state=pb, roller_columns=rollers)


def _check_regime(case: Case, pb: Problem):
    """Refuse a lift-off that the boundaries unknowns put below the stinger's
    tip, on the curve continued past it: there the pipe bears on the tip,
    but the solve ended lifting off (it switches between the two regimes at
    most MAX_TIP_SWITCHES times)."""
    if pb.lo_node < 0:
        return
    z_lo = float(pb.u[pb.lo_node * pb.ndn + pb.nd - 1])
    z_tip = float(pb.stinger[ST_ZL])
    if z_lo < z_tip:
        raise SolveError(
            f"case {case.name!r}: the pipe bears on the stinger's tip (its lift-off, "
            f"z = {z_lo:.3f} m, would lie below the tip, z = {z_tip:.3f} m), but the solve "
            f"ended lifting off (it switches between bearing on the tip and lifting off "
            f"at most {MAX_TIP_SWITCHES} times)")


__all__ = ["Problem", "SolveError", "solve"]

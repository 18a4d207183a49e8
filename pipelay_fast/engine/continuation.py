"""Newton on one mesh, and the load paths that lead there when it fails.

:func:`run_newton` calls the Newton kernel once; :func:`newton_in_regime`
repeats it across the switches of regime at the stinger's ends (lifting
off or bearing on its tip, conforming to it or held at its upper end
alone); :func:`continuation` is the one adaptive-step routine (step, cut,
grow) that every load path uses: the homotopy that removes the first
guess's out-of-balance force (:func:`newton_with_fallback`) and the current's
path, which seabed friction makes path dependent (:func:`apply_current`).
"""

from __future__ import annotations

import numpy as np

from ..input.case import Case
from ..input.errors import SolveError
from ..input.limits import IterationBudget
from ..kernels import layout as L
from ..kernels.layout import I_DELTA, I_ITER, I_PAST, I_RES, I_TOP_RES, I_TOP_TE, N_INFO
from ..kernels.newton import newton_2d, newton_3d
from ..kernels.scene import in_scene
from ..kernels.types import Mesh, Settings
from . import tuning as T
from .boundaries import (
    ONTO_STINGER,
    TO_UPPER_END,
    bear_on_tip,
    below_stinger,
    conform_from,
    lift_off_above_tip,
    tip_regime,
    touchdown_spans,
)
from .state import Problem, restore, snapshot

# the statuses at which a solve switches regime (:func:`.boundaries.tip_regime`)
_SWITCHES = (L.PAST_TIP, L.SPAN_CLOSED, TO_UPPER_END, ONTO_STINGER)


class ShortLaid(Exception):
    """The mesh needs more laid pipe: Newton stopped with SHORT_LAID (touchdown
    runs toward the modelled lower end, :func:`.solver._solve_gravity`), or a
    step of the current's path left the lower end holding the laid pipe
    (:func:`apply_current`)."""




def boundary_step(pb: Problem) -> float:
    """The largest move [m] of a contact boundary per Newton step (see
    tuning.MAX_BOUNDARY_STEP; a problem built with no boundary layer recorded, as
    the kernels' tests build them, has elements alone)."""
    return max(T.MAX_BOUNDARY_STEP * pb.settings.href,
               T.BOUNDARY_STEP_LAYER * pb.stats.get("boundary_layer", 0.0))


def run_newton(pb: Problem, g_off, tol, maxit):
    """One call of the Newton kernel on ``pb`` (updated in place: state,
    boundaries, node arc lengths), with residual offset ``g_off`` (ndof,),
    tolerance ``tol`` [-] and at most ``maxit`` iterations. The iterations may
    hold the contact boundaries while the pipe is out of balance, unless
    ``pb.settings.in_balance`` (which the call clears: it holds for its start only).
    Returns (status, reactions (ndof,) [N, N m], info (N_INFO,))."""
    react = np.zeros_like(pb.u)
    info = np.zeros(N_INFO)
    if pb.mesh.s_a is not None:
        s_a, s_b = pb.mesh.s_a, pb.mesh.s_b
    else:
        s_a, s_b = np.zeros(pb.nn), np.zeros((pb.bnodes.size, pb.nn))
    mesh = Mesh(pb.s_el, s_a, s_b, pb.mesh.s_bd, pb.bnodes)
    settings = Settings(float(tol), float(pb.settings.fref), float(pb.settings.href), int(maxit),
                        not pb.settings.in_balance, boundary_step(pb))
    pb.settings.in_balance = False
    kernel = in_scene(newton_2d if pb.nd == 2 else newton_3d, pb.scene)
    status = kernel(pb.u, mesh, pb.model(), pb.kernel_supports(), pb.kernel_ends(g_off),
                    settings, react, info)
    pb.mesh.update_nodes()
    return status, react, info


def _residual(pb: Problem):
    """The residual G (ndof,) [N, N m, m] at the current state, global frame,
    its constrained rows removed but the stinger curve's (the Newton kernel
    with no iteration, :func:`.newton._free_residual`): the homotopy's offset;
    and the top's effective tension there [N] (0 when the top tension is not
    given)."""
    _status, g, info = run_newton(pb, np.zeros_like(pb.u), 1.0, 0)
    return g, float(info[I_TOP_TE])


def _newton_state(info, status):
    """The reason and residuals of a Newton call that ended with ``status``."""
    reason = L.STATUS_TEXT.get(status, f"status {status}")
    return (f"{reason}; weighted residual {info[I_RES]:.3e}, constraint violation "
            f"{info[I_DELTA]:.3e}, top-tension residual {info[I_TOP_RES]:.3e} after "
            f"{int(info[I_ITER])} iterations")


def _fail(case, step, info, status, extra=""):
    raise SolveError(f"case {case.name!r} did not converge at {step}: "
                     f"{_newton_state(info, status)}{extra}")


def _budgeted_newton(case: Case, pb: Problem, g_off, budget: IterationBudget, where: str,
                     switch: bool = False, maxit: int | None = None, guessed: bool = False):
    """:func:`run_newton` within the solve's iteration budget; a SolveError
    naming solver.max_iterations_total when it is spent. ``switch``: a
    lift-off that reaches the stinger's tip (status PAST_TIP) is returned to
    the caller, which switches to bearing on the tip, instead of raised.
    ``maxit``: the call's iterations at most (None: solver.max_iterations).
    Touchdown running toward the lower end (SHORT_LAID) raises ShortLaid, for
    more laid pipe; ``guessed``: the call lifts off above a tip whose branch
    cycled (TIP_CYCLE), a regime guessed, not one Newton's iterate reached,
    from which touchdown's run measures no shortage of laid pipe: SHORT_LAID
    is then the call's failure, returned."""
    if budget.left < 1:
        raise SolveError(f"case {case.name!r} {budget.spent_message(where)}")
    status, react, info = run_newton(pb, g_off, pb.settings.tolerance or case.solver.tolerance,
                                      budget.cap(maxit or case.solver.max_iterations))
    budget.charge(info[I_ITER])
    if status == L.SHORT_LAID and not guessed:
        raise ShortLaid
    if status in (L.PAST_TIP, L.SPAN_CLOSED) and not switch:
        raise SolveError(f"case {case.name!r} at {where}: {_newton_state(info, status)}")
    if status != L.OK and budget.left < 1:
        raise SolveError(f"case {case.name!r} {budget.spent_message(where)} (last Newton "
                         f"call: {_newton_state(info, status)})")
    return status, react, info


def newton_in_regime(case: Case, pb: Problem, g_off, budget: IterationBudget, where: str,
                     predicted: bool = False, maxit: int | None = None):
    """:func:`_budgeted_newton`, switching between lifting off and bearing on
    the stinger's tip (at most tuning.MAX_TIP_SWITCHES times) when the kernel stops
    at the change of regime (PAST_TIP, SPAN_CLOSED), when, lifting off, the
    answer passes below the tip, and, with a node over the tip, when the
    answer leaves that node unloaded (:func:`.boundaries.tip_released`) or
    the tip's branch cycles with no progress (TIP_CYCLE): the pipe then lifts off
    above the tip; and at the curve's upper end, between conforming to the
    curve and being held at its end point alone (TO_UPPER_END, ONTO_STINGER,
    :func:`.boundaries.conform_from`; from the call's start when its iterate
    ran away, NOT_FINITE or SINGULAR). ``predicted``: the state was moved towards the answer
    (a predicted start, :func:`continuation`); it does not switch, but
    returns the status that asks for a switch, for the caller to solve the
    step from its own start. ``maxit``: each call's iterations at most
    (None: solver.max_iterations). A call lifting off above a tip whose
    branch cycled that stops with touchdown running toward the lower end
    fails (SHORT_LAID returned, no ShortLaid: :func:`_budgeted_newton`), so
    that the caller's fallback starts again from its own state (laid pipe
    added to the guessed regime's iterate would carry that regime on).

    Returns (status, reactions, info, iterations of every call).
    """
    spent = 0  # iterations of the calls that ended in a switch of regime
    cycled = False  # lifting off above a tip whose branch cycled (TIP_CYCLE)
    for switches in range(T.MAX_TIP_SWITCHES + 1):
        can_switch = ((pb.lo_node >= 0 or pb.clear_of_stinger)
                      and switches < T.MAX_TIP_SWITCHES)
        start = snapshot(pb)
        status, react, info = _budgeted_newton(case, pb, g_off, budget, where,
                                              switch=can_switch or predicted, maxit=maxit,
                                              guessed=cycled)
        stopped, status = status, tip_regime(pb, status, can_switch)
        if status not in _SWITCHES or predicted:
            break
        spent += int(info[I_ITER])
        if status == L.PAST_TIP:
            bear_on_tip(case, pb, float(info[I_PAST]))
        elif status == L.SPAN_CLOSED:
            cycled = cycled or stopped == L.TIP_CYCLE
            lift_off_above_tip(case, pb)
        elif status == ONTO_STINGER:
            conform_from(case, pb, below_stinger(pb))
        else:  # from the call's start if its iterate ran away
            if stopped in (L.NOT_FINITE, L.SINGULAR):
                restore(pb, start)
            conform_from(case, pb, -1)
    return status, react, info, int(info[I_ITER]) + spent


def continuation(case: Case, pb: Problem, budget: IterationBudget, load, *, name: str,
                 converged=None):
    """The one adaptive-step routine of every load path: raise a load level
    from 0 to 1, each step a Newton solve (:func:`newton_in_regime`) from the
    last converged state, with the step rule of tuning.LOAD_STEP,
    LOAD_STEP_FACTOR and SMALLEST_LOAD_STEP: a step that fails is undone and
    the step it took (shorter than the one asked where the path's end clips
    it) cut, one that converges grows for the next, up to LOAD_STEP.

    ``load(level, predict)`` puts the problem at that load level and returns
    Newton's residual offset (ndof,); with ``predict`` it may also move the
    state towards the step's answer (a warm start's neighbour's increment,
    or the path's own last increment, :meth:`.Problem.start_step`) and
    returns whether it did. A predicted start gets at most
    tuning.PREDICTED_CAP times the iterations of the path's hardest converged
    call so far (within solver.max_iterations). A step that fails from such a
    start, or that would switch regime at the tip from it, is solved again
    from the last converged state before it is halved, so that a warm start
    takes the cold start's steps (friction and the tip's contact are both
    path dependent: another sequence of steps may end on another answer).
    A step cut below tuning.SMALLEST_LOAD_STEP, or solver.max_load_steps
    steps taken, raises SolveError naming the load path ``name``, the level
    and why. Returns the last reactions and {"iterations", "load_steps",
    "step_max"}: the Newton iterations, the load steps (undone ones
    included) and the most iterations one of them took.
    """
    level, step = 0.0, T.LOAD_STEP
    max_steps = case.solver.max_load_steps
    stats = {"iterations": 0, "load_steps": 0, "step_max": 0}
    react = info = None
    status = L.OK
    hardest = 0  # the most iterations a converged call of this path took
    while level < 1.0:
        trial = min(1.0, level + step)
        where = f"{name} {trial:.4f} (load step {stats['load_steps'] + 1})"
        if stats["load_steps"] >= max_steps:
            _fail(case, where, info, status, f"; {max_steps} load steps taken, the limit "
                  "that solver.max_load_steps sets")
        saved = snapshot(pb)  # (with the boundaries' map: a switch of regime replaces it)
        g_off, predicted = load(trial, True)
        # a predicted start that takes PREDICTED_CAP times the iterations of
        # the path's hardest converged call so far is not nearer: the step is
        # solved from the last converged state instead
        cap = (min(T.PREDICTED_CAP * hardest, case.solver.max_iterations)
               if predicted and hardest > 0
               else None)
        try:
            status, react, info, used = newton_in_regime(case, pb, g_off, budget,
                                                                 where, predicted, cap)
        except ShortLaid:
            if not predicted:
                raise
            status, used = L.SHORT_LAID, 0  # (its iterations are in the budget)
        if status != L.OK and predicted and budget.left > 0:
            # from the last converged state, as the cold start
            restore(pb, saved)
            g_off, _ = load(trial, False)
            status, react, info, again = newton_in_regime(case, pb, g_off, budget,
                                                                  where)
            used += again
        if status == L.OK:
            hardest = max(hardest, int(info[I_ITER]))
        stats["iterations"] += used
        stats["load_steps"] += 1
        stats["step_max"] = max(stats["step_max"], used)
        if status == L.OK:
            level = trial
            step = min(T.LOAD_STEP_FACTOR * step, T.LOAD_STEP)
            if converged is not None:
                converged(level, react)
            continue
        restore(pb, saved)
        # the step taken, not the one asked: a step clipped at the path's end
        # and cut from the one asked would be tried again at the same level
        step = (trial - level) / T.LOAD_STEP_FACTOR
        if step < T.SMALLEST_LOAD_STEP:
            _fail(case, where, info, status, f"; load step cut below {T.SMALLEST_LOAD_STEP:g}")
    return react, stats


def homotopy(pb: Problem):
    """The homotopy's ``load(alpha, predict)`` for :func:`continuation` from
    the present state u0 of ``pb`` (:func:`_residual`): it returns the
    offset -(1 - alpha) G(u0) and, where the top tension T is given, sets
    the top's target to T0 + alpha (T - T0) (``pb.settings.top_target``; T
    at alpha = 1 exactly), T0 the top's effective tension at u0, so that u0
    solves the pipe's equations and the top's at alpha = 0. The contact
    boundaries' conditions keep no offset (with one, the lay table's sweep,
    sweeps/lay_table.toml, fails as often and takes more iterations). A u0
    whose top tension is not positive keeps T (the kernel solves for the
    bottom tension while its target is positive). The caller clears ``pb.settings.top_target`` when
    the path ends."""
    g0, te0 = _residual(pb)
    target = pb.ends.top_target
    eased = target > 0.0 and te0 > 0.0

    def load(alpha, _predict):
        if eased:
            pb.settings.top_target = target + (1.0 - alpha) * (te0 - target)
        return -(1.0 - alpha) * g0, False

    return load


def newton_with_fallback(case: Case, pb: Problem, budget: IterationBudget | None = None):
    """Newton from the current state; on failure, the load-path homotopy
    from that state u0, the one the mesh's solve started from (before any
    switch of regime at the stinger's tip: a switched state is Newton's
    stopped iterate, which may be far out of balance), with
    its load factor alpha from 0 to 1 (:func:`homotopy`, :func:`continuation`).
    ``budget``: the solve's Newton iterations left (None: a fresh one).

    Returns the reactions and a dict of iteration counts.
    """
    budget = budget or IterationBudget(case.solver.max_iterations_total)
    zero = np.zeros_like(pb.u)
    # (the boundaries start where the guess puts them; the kernel holds
    # them until the pipe is in equilibrium there)
    start = snapshot(pb)
    status, react, info, iters = newton_in_regime(
        case, pb, zero, budget, "the first Newton solve on a mesh")
    if status == L.OK:
        return react, {"iterations": iters, "load_steps": 1}
    if pb.path.warm:
        # a warm start is Newton from the neighbour's answer; where that does
        # not converge the neighbour is too far, and the cold start (with its
        # load path) is cheaper than a load path from the neighbour's state
        _fail(case, "the warm start's Newton solve", info, status)
    restore(pb, start)
    try:
        react, stats = continuation(case, pb, budget, homotopy(pb),
                                    name="the homotopy from the first guess, load factor",
                                    converged=lambda _level, _react: _free_touchdown(pb))
    finally:
        pb.settings.top_target = None
    return react, {"iterations": stats["iterations"] + iters, "load_steps": stats["load_steps"]}


def _free_touchdown(pb: Problem):
    """The mesh follows touchdown over the spans beside it
    (:func:`.boundaries.touchdown_spans`), its other boundaries as before;
    set after each converged step of the homotopy. Along it touchdown moves
    from the first guess's to the answer's, often more than its zone's
    DECAY_LENGTHS flexural lengths, and a zone's edge, a node that stays
    put, would stop it there, its elements squeezed against the edge. Not
    from the first guess, which is out of balance: freed there, touchdown
    can run to the lower end and the path end on another branch. A switch
    of regime at the tip maps the mesh in zones again until the step
    converges."""
    if pb.mesh.s_b is not None and pb.td_node > 0:
        pb.mesh.follow_rates(pb.bnodes, touchdown_spans(pb, pb.mesh.s_b))


def apply_current(case: Case, pb: Problem, budget: IterationBudget | None = None,
                  laid_holds=None):
    """Raise the current factor from 0 to 1 in load steps (friction follows
    this path; :func:`continuation`).
    ``budget``: the solve's Newton iterations left (None: a fresh one).
    ``laid_holds(pb, react)``: whether a converged step's reactions leave the
    lower end holding the laid pipe (:func:`.solver._lower_end_holds`); a
    step short of the full current that does raises ShortLaid, for more
    laid pipe and the path again (with the lower end held, the path follows
    another problem, whose equilibrium may end before the full current:
    a 2097 m J-lay under 1.9 m/s slid its whole laid pipe from factor 0.75
    and stalled at 0.875).

    The converged steps are recorded (``pb.path.current_path``, from the state
    before the current); a warm start begins each step from its neighbour's
    increment over it, and past the first step a step without one from this
    path's last increment (:meth:`.Problem.start_step`).
    """
    budget = budget or IterationBudget(case.solver.max_iterations_total)
    zero = np.zeros_like(pb.u)

    def load(factor, predict):
        pb.settings.factors[L.F_CURRENT] = factor
        # a predicted start: plus the neighbour's increment over the step,
        # or this path's last one (Problem.start_step)
        return zero, predict and pb.start_step(factor)

    pb.path.current_path = [pb.path_state(0.0)]

    def converged(level, react):
        pb.path.current_path.append(pb.path_state(level))
        if level < 1.0 and laid_holds is not None and laid_holds(pb, react):
            raise ShortLaid

    react, stats = continuation(case, pb, budget, load, name="current factor",
                                converged=converged)
    pb.settings.factors[L.F_CURRENT] = 1.0
    return react, stats

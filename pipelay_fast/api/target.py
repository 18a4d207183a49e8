"""Target solves: the value of one case key that makes a summary column meet a target.

``solve_for(case, target={"tip_clearance": 0.3}, vary="lay.top_tension",
bounds=(600e3, 1200e3))`` finds the top tension that gives 0.3 m of clearance
over the stinger's tip: a bracketed root find (:func:`scipy.optimize.brentq`)
on ``summary[column] - goal``, each trial solved warm from the trial nearest
to it so far (``pf.solve(case, warm=...)``), to 1e-4 of the goal; then the
root is polished on cold solves, so that the answer is the one ``pf.solve``
gives the returned case (graded, a warm start ends on the cold start's mesh
and gives its answer; ungraded, it keeps its neighbour's mesh, and its
column differs from the cold one by the discretisation error).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping

from scipy.optimize import brentq

from ..input.case import Case
from ..input.errors import SolveError
from ..input.validate import did_you_mean, get_path
from ..kernels.tuning import BACKTRACK
from ..output.results import SUMMARY_UNITS, Result
from .solve import solve

__all__ = ["TargetError", "TARGET_RTOL", "solve_for", "target_columns", "unit_text"]

TARGET_RTOL = 1e-6  # the target is met to this share of its value (or of the bound values)
STOP_SHARE = 0.01  # the root find stops at a trial within this share of rtol
COARSE_SHARE = 1e-4  # the warm trials' root find stops within this share of the goal


class TargetError(ValueError):
    """A target that the varied key cannot reach within its bounds."""


class _Met(Exception):
    """Ends the root find at a trial that meets the target (its value in args)."""


def target_columns() -> tuple[str, ...]:
    """The summary columns a target may name: the numeric ones with a unit,
    but the inputs the summary repeats (``a``, ``stinger_radius``,
    ``roller_shift``, ``water_depth``, ``current_speed``,
    ``current_heading_deg``) and ``solve_seconds``."""
    return tuple(name for name, unit in SUMMARY_UNITS.items()
                 if unit and name not in ("a", "stinger_radius", "roller_shift", "water_depth",
                                          "current_speed", "current_heading_deg",
                                          "solve_seconds"))


def solve_for(case: Case, target: Mapping[str, float], vary: str,
              bounds: tuple[float, float], *, rtol: float = TARGET_RTOL,
              warm: Result | None = None) -> Result:
    """The result of ``case`` with ``vary`` set so that the summary meets ``target``.

    Parameters
    ----------
    case : Case
    target : mapping
        One summary column and its goal, in the column's SI unit, e.g.
        ``{"tip_clearance": 0.3}`` [m] or ``{"sagbend_lcc_utilisation": 0.8}``.
    vary : str
        A numeric case key by its dotted path (``"lay.top_tension"``,
        ``"lay.stinger.a"``, ``"lay.pipe_length"``); the case must give it.
    bounds : (float, float)
        The bracket of ``vary`` [its unit], lo < hi; the column minus the goal
        must change sign between them.
    rtol : float
        The column meets the goal to ``rtol`` of the goal's size (of the
        column's size at the bounds for a goal of 0); default 1e-6.
    warm : Result, optional
        A neighbouring solution to start the first trial from (as
        :func:`pipelay_fast.solve`'s ``warm``); later trials start from the
        nearest trial.

    Returns
    -------
    Result
        The solved case at the root; ``result.target`` holds the column, the
        goal, the key, its value and the number of solves.

    Raises
    ------
    TargetError (a ValueError)
        When the goal is not between the column's values at the bounds (both
        are in the message), or the root does not meet it to ``rtol``.
    ValueError
        For a target column, key or bounds that cannot be used.
    SolveError
        When a trial does not solve (the message names the key's value).
    """
    column, goal = _target(target)
    lo, hi = _bounds(bounds, vary)
    tables = case.to_dict()
    current = get_path(tables, vary)
    if isinstance(current, bool) or not isinstance(current, numbers.Real):
        raise ValueError(f"vary = {vary!r} is not a numeric key the case gives "
                         f"(its value: {current!r}){did_you_mean(vary, _numeric_keys(tables))}")
    unit = unit_text(column)
    trials = _Trials(case, vary, column, goal)
    f_lo = trials.miss(lo, start=warm)
    f_hi = trials.miss(hi, start=None)
    if f_lo * f_hi > 0.0:
        raise TargetError(
            f"target {column} = {goal!r}{unit} is not reached for {vary} in [{lo!r}, {hi!r}]: "
            f"{column} = {f_lo + goal!r}{unit} at {vary} = {lo!r} and {f_hi + goal!r}{unit} "
            f"at {vary} = {hi!r}")
    scale = abs(goal) if goal != 0.0 else max(abs(f_lo), abs(f_hi))
    tol = STOP_SHARE * rtol * scale
    if abs(f_lo) <= tol or abs(f_hi) <= tol:
        root = lo if abs(f_lo) <= abs(f_hi) else hi
    else:
        near = _root(trials.miss, lo, hi, COARSE_SHARE * scale)
        root = _polish(trials, near, lo, hi, tol)
    trials.cold_miss(root)
    result = trials.cold[root]
    got = result.summary[column]
    if abs(got - goal) > rtol * scale:
        raise TargetError(f"target {column} = {goal!r}{unit}: the root {vary} = {root!r} "
                          f"gives {got!r}{unit}, not within rtol = {rtol:g} (the column "
                          "jumps there: a change of regime?)")
    result.target = {"column": column, "goal": goal, "vary": vary, "value": root,
                     "solves": trials.count}
    return result


class _Trials:
    """The column's miss ``summary[column] - goal`` at values of the key.

    ``miss`` solves warm from the nearest trial so far (or from ``start``,
    None: cold); ``cold_miss`` solves from the solver's own guess, the answer
    ``pf.solve`` gives that case, which the root is polished on: ungraded
    (``solver.grading = false``), a warm start keeps its neighbour's mesh,
    and the column with it differs from the cold answer by the
    discretisation error (graded, it is regraded with its own case's sizes
    and laid length and ends on the cold start's mesh).
    """

    def __init__(self, case: Case, vary: str, column: str, goal: float):
        self.case, self.vary, self.column, self.goal = case, vary, column, goal
        self.warm: dict[float, Result] = {}
        self.cold: dict[float, Result] = {}
        self.count = 0  # solves made

    def miss(self, value: float, start=False) -> float:
        """``summary[column] - goal`` at ``vary`` = ``value``, solved warm
        from ``start`` (a Result; None: cold; False, the default: the
        nearest trial so far), once per value."""
        value = float(value)
        if value not in self.warm:
            if start is False:
                known = {**self.warm, **self.cold}
                start = known[min(known, key=lambda v: abs(v - value))] if known else None
            self.warm[value] = self._solve(value, start)
        return self._off(self.warm[value], value)

    def cold_miss(self, value: float) -> float:
        """:meth:`miss` of the cold solve at ``value``."""
        value = float(value)
        if value not in self.cold:
            self._solve(value, None)
        return self._off(self.cold[value], value)

    def _solve(self, value: float, start) -> Result:
        try:
            result = solve(self.case.with_changes({self.vary: value}), warm=start)
            self.count += 1
        except SolveError as err:
            raise SolveError(f"solve_for: the trial {self.vary} = {value!r} did not solve: "
                             f"{err}") from err
        if start is None:
            self.cold[value] = result
        return result

    def _off(self, result: Result, value: float) -> float:
        got = result.summary[self.column]
        if not math.isfinite(got):
            raise TargetError(f"target {self.column}: the case at {self.vary} = {value!r} has "
                              f"{self.column} = {got!r} (no value to meet the target with)")
        return got - self.goal


def _root(miss, lo: float, hi: float, tol: float) -> float:
    """A root of ``miss`` in [lo, hi] (signs differ at the ends): brentq, ended
    at the first trial within ``tol``."""

    def miss_or_met(value: float) -> float:
        off = miss(value)
        if abs(off) <= tol:
            raise _Met(value)
        return off

    try:
        return brentq(miss_or_met, lo, hi)  # (scipy's tolerances: the miss ends it first)
    except _Met as met:
        return met.args[0]


def _polish(trials: _Trials, near: float, lo: float, hi: float, tol: float) -> float:
    """The root of the cold miss next to ``near``, the warm trials' root: a
    secant step from the warm trials' slope (a flat slope: straight to the
    upper bound), doubled until the cold miss changes sign, then brentq on
    the cold miss within ``tol``; a step that reaches a bound without a
    change of sign ends the search (TargetError)."""
    f0 = trials.cold_miss(near)
    if abs(f0) <= tol:
        return near
    (v1, r1), (v2, r2) = sorted(trials.warm.items(), key=lambda item: abs(item[0] - near))[:2]
    slope = (r1.summary[trials.column] - r2.summary[trials.column]) / (v1 - v2)
    step = -f0 / slope if slope != 0.0 else hi - lo
    while True:
        other = min(max(near + step, lo), hi)
        f1 = trials.cold_miss(other)
        if abs(f1) <= tol:
            return other
        if f0 * f1 < 0.0:
            return _root(trials.cold_miss, min(near, other), max(near, other), tol)
        if other in (lo, hi):
            break
        step /= BACKTRACK  # (doubled: the solver's bisection factor)
    raise TargetError(f"target {trials.column}: no root of the cold solves found next to "
                      f"{trials.vary} = {near!r} (the column jumps there: a change of regime?)")


def unit_text(column: str) -> str:
    """The unit of a summary column as a message suffix (" m"); "" if dimensionless."""
    unit = SUMMARY_UNITS[column]
    return "" if unit in ("", "-") else f" {unit}"


def _target(target) -> tuple[str, float]:
    """(column, goal) of a one-entry target mapping; ValueError otherwise."""
    if not isinstance(target, Mapping) or len(target) != 1:
        raise ValueError(f"target = {target!r} must name one summary column and its goal, "
                         "e.g. {'tip_clearance': 0.3}")
    ((column, goal),) = target.items()
    if column not in target_columns():
        raise ValueError(f"target column {column!r} is not a numeric summary column"
                         f"{did_you_mean(column, target_columns())}: "
                         f"one of {', '.join(target_columns())}")
    if isinstance(goal, bool) or not isinstance(goal, numbers.Real) or not math.isfinite(goal):
        raise ValueError(f"target {column} = {goal!r} must be a finite number")
    return column, float(goal)


def _bounds(bounds, vary) -> tuple[float, float]:
    """(lo, hi) as floats, finite and lo < hi; ValueError otherwise."""
    try:
        lo, hi = (float(b) for b in bounds)
    except (TypeError, ValueError):
        raise ValueError(f"bounds = {bounds!r} must be two numbers (lo, hi) of {vary}") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise ValueError(f"bounds = {bounds!r} must be finite with lo < hi")
    return lo, hi


def _numeric_keys(tree: Mapping, prefix: str = "") -> list[str]:
    """The dotted keys of the numeric values of the nested dict ``tree``."""
    keys = []
    for key, value in tree.items():
        if isinstance(value, Mapping):
            keys += _numeric_keys(value, f"{prefix}{key}.")
        elif isinstance(value, numbers.Real) and not isinstance(value, bool):
            keys.append(f"{prefix}{key}")
    return keys

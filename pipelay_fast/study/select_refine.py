"""The solves ``select`` refines its choices by: the design axis's value at
a given point solved warm (:class:`Evaluator`), and the root of an answer
between two grid points (:func:`grid_root`), the feasible range's ends among
them (:func:`refined_ends`).

Where the sweep has the answer's derivative with respect to the design
axis's key (the sweep file's ``sensitivities``,
:mod:`pipelay_fast.study.sensitivity`) at both grid points, the root is
the root of their cubic Hermite interpolant, confirmed and corrected by
Newton on solves there (:func:`pipelay_fast.study.sensitivity.hermite_newton`);
otherwise :func:`scipy.optimize.brentq` on solves between the grid points.
Both stop within XTOL_FRACTION of the grid step.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import pandas as pd
from scipy.optimize import brentq

from .limits import Range, limit_text
from .runner import CASE_ERRORS, solve_case
from .sensitivity import column_name, hermite_newton, hermite_root
from .sweep import AXES, DESIGN_AXES, Scene

__all__ = ["XTOL_FRACTION", "Evaluator", "Root", "grid_root", "refined_ends", "slopes"]

XTOL_FRACTION = 1e-4  # search tolerance as a share of the grid spacing of a


class Evaluator:
    """Summary of the group's case at a given value of its design axis
    ``variable`` (``a``), solved warm from the nearest value solved so far
    (the first from cold), for the scene's target when it has one; repeated
    values are cached. ``solves`` counts the solves."""

    def __init__(self, scene: Scene, values: dict, group: pd.DataFrame, variable: str):
        self.scene = scene
        self.variable = variable
        given = {name: values[column] for name, (_, column, _) in AXES.items()
                 if name in scene.axes and name not in DESIGN_AXES}
        self.values = given
        self.results: dict[float, object] = {}
        self.solves = 0
        self.last = math.nan

    def __call__(self, a: float) -> dict:
        a = self.last = float(a)
        if a in self.results:
            return self.results[a].summary
        case = self.scene.case_for({**self.values, self.variable: a})
        warm = None
        if self.results:
            warm = self.results[min(self.results, key=lambda b: abs(b - a))]
        result = solve_case(case, warm, self.scene.target)
        self.solves += 1
        self.results[a] = result
        return result.summary

    def failure(self, err: Exception) -> str:
        """A short note on the failed solve (the full message: solve that case)."""
        return f"{type(err).__name__} at {self.variable} = {self.last:.6g}"


def slopes(group: pd.DataFrame, variable: str, column: str) -> np.ndarray | None:
    """d ``column`` / d (the design axis ``variable``'s case key) at the
    group's grid points (the sweep's sensitivity column), None where the
    sweep has no such column."""
    name = column_name(column, AXES[variable][0])
    return group[name].to_numpy(dtype=float) if name in group else None


class Root(NamedTuple):
    """A root between two grid points (:func:`grid_root`): its value, how it
    was found (text for a note) and whether from the sensitivities (the
    Hermite interpolant of the grid points' derivatives) rather than from
    solves alone (brentq)."""

    value: float
    how: str
    by_sensitivities: bool


def grid_root(f, x, values, derivatives, j: int, evaluate: Evaluator | None) -> Root | None:
    """The root of ``f`` (a function of a summary) between the grid points
    ``x[j]``, ``x[j + 1]``, where its ``values`` differ in sign
    (:class:`Root`), or None where neither solves nor derivatives can refine it.

    With both grid points' ``derivatives`` finite (None: none): the
    Hermite interpolant's root, confirmed and corrected by solves
    (``evaluate``; without it, unconfirmed); else brentq on solves (the grid
    points' values taken as they are). Raises
    the solve's error (CASE_ERRORS)."""
    lo, hi = float(x[j]), float(x[j + 1])
    xtol = XTOL_FRACTION * (hi - lo)
    smooth = derivatives is not None and np.isfinite(derivatives[j:j + 2]).all()
    if smooth:
        bracket = {lo: (values[j], derivatives[j]), hi: (values[j + 1], derivatives[j + 1])}
        if evaluate is None:
            return Root(hermite_root(lo, hi, *values[j:j + 2], *derivatives[j:j + 2])[0],
                        "the sensitivities' Hermite interpolation, not confirmed by a solve",
                        True)
        before = evaluate.solves
        root = hermite_newton(lambda v: f(evaluate(v)), bracket, xtol)[0]
        return Root(root, f"Newton on the sensitivities, {evaluate.solves - before} solve(s)",
                    True)
    if evaluate is None:
        return None
    before = evaluate.solves
    grid = {lo: values[j], hi: values[j + 1]}  # (not solved again)
    root = brentq(lambda v: grid[v] if v in grid else f(evaluate(v)), lo, hi, xtol=xtol)
    evaluate(root)
    return Root(root, f"brentq on solves, {evaluate.solves - before} solve(s)", False)


def refined_ends(r: Range, a, margins: dict, derivatives: dict, evaluate: Evaluator | None,
                 notes: list[str]) -> tuple[Range, dict]:
    """(the range ``r`` with each end a limit binds moved to the root of that
    limit's margin between the grid points around it (:func:`grid_root`,
    ``derivatives`` {limit: the margin's derivatives at the grid points, or
    None}); {end: its summary} of the ends solved). An end stays
    interpolated, with a note in ``notes``, when a solve fails or another
    limit does not hold at the root; an end on a grid point, and every end
    without ``evaluate`` or derivatives, stays as it is."""
    solved: dict = {}
    for side, x, limit in (("low", r.low, r.low_binds), ("high", r.high, r.high_binds)):
        i = int(np.searchsorted(a, x))
        if limit is None or i == 0 or i >= a.size or x == a[i]:
            continue
        try:
            found = grid_root(lambda s, m=limit: float(m.margin(s[m.column])), a,
                              margins[limit], derivatives.get(limit), i - 1, evaluate)
        except CASE_ERRORS as err:
            notes.append(f"feasible {side} end not refined: {evaluate.failure(err)}")
            continue
        if found is None:
            continue
        root, how, by_sensitivities = found
        if evaluate is not None:
            summary = evaluate(root)
            broken = [limit_text(m) for m in margins
                      if m is not limit and m.margin(summary[m.column]) < 0.0]
            if broken:
                notes.append(f"feasible {side} end not refined: {', '.join(broken)} fails at "
                             f"{root:.6g}")
                continue
            solved[root] = summary
        if by_sensitivities:
            notes.append(f"feasible {side} end by {how}")
        r = r._replace(**{side: root})
    return r, solved

"""Choosing the stinger from a sweep's results: its curvature ``a``, or a
roller stinger's radius (``stinger_radius``) or the shift of its rollers'
heights (``roller_shift``), whichever of these design axes the scene varies
(the selection's ``variable``; ``a`` below stands for it, and each choice is
written in the columns of its name: ``a_min_stress``,
``stinger_radius_min_stress``, ...).

For every S-lay scene and every combination of the other inputs (current speed
and heading, tension) two choices are made from the grid of ``a`` values:

* ``a_min_stress``: the ``a`` that minimises the maximum von Mises stress. The
  grid minimum is refined between its two neighbours with a bounded scalar
  search (:func:`scipy.optimize.minimize_scalar`, ``method="bounded"``), each
  evaluation a solve warm-started from the nearest case solved so far.
* ``a_equal_peaks``: the ``a`` at which the overbend and sagbend peaks are
  equal, the root of ``overbend_max_von_mises - sagbend_max_von_mises`` found
  by :func:`scipy.optimize.brentq` between the two grid points that bracket
  it (the bracket of lowest stress when there are several), warm-started too.

At the equal-peaks ``a`` the selection also gives the lay's answers there:
``equal_peaks_max_utilisation`` (the DNVGL-ST-F101 checks, NaN without a
``[checks]`` table) and ``equal_peaks_tip_clearance`` [m].

Refinement needs the scenes' base cases, which the sweep stores in
``sweep.json``; ``refine=False`` reports the grid values only.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.optimize import brentq, minimize_scalar

from ..output.io import write_table
from .dataset import read_summary
from .runner import CASE_ERRORS, solve_case
from .sweep import AXES, DESIGN_AXES, Scene, Sweep

__all__ = ["SELECTION_UNITS", "select"]

SELECTION_UNITS = {
    "scene": "", "method": "", "dimension": "", "water_depth": "m",
    "current_speed": "m/s", "current_heading_deg": "deg",
    "given_top_tension": "N", "given_bottom_tension": "N", "given_pipe_length": "m",
    "n_grid": "", "a_grid_min": "1/m", "a_grid_max": "1/m",
    "a_min_stress": "1/m", "min_max_von_mises": "Pa",
    "a_equal_peaks": "1/m", "equal_peaks_von_mises": "Pa",
    "equal_peaks_max_utilisation": "-", "equal_peaks_tip_clearance": "m",
    "reference_a": "1/m", "n_solves": "", "note": "", "variable": "",
    # a roller stinger's design axes, as a's four columns
    **{f"{axis}_{what}": AXES[axis][2] for axis in DESIGN_AXES[1:]
       for what in ("grid_min", "grid_max", "min_stress", "equal_peaks")},
}
# the inputs that, with the scene, make one selection group
GROUP_COLUMNS = ("current_speed", "current_heading_deg", "given_top_tension",
                 "given_bottom_tension", "given_pipe_length")
# summary column -> selection column, reported at the equal-peaks a
EQUAL_PEAKS_ANSWERS = {"max_utilisation": "equal_peaks_max_utilisation",
                       "tip_clearance": "equal_peaks_tip_clearance"}
XTOL_FRACTION = 1e-4  # search tolerance as a share of the grid spacing of a
FLAT_SHARE = 0.005  # grid points this close to the minimum stress make it "flat"


def select(root: str | os.PathLike, *, refine: bool = True, write: bool = True) -> pd.DataFrame:
    """The selection table of the results directory ``root`` (one row per
    S-lay group: scene and the other inputs; the columns of
    ``SELECTION_UNITS``, SI).

    ``refine``: refine the grid's choices with further solves (needs
    ``root/sweep.json``); False: grid values only. Written to
    ``root/selection.parquet`` (units in the schema) when ``write``.
    Raises ValueError when ``root`` has no summary table.
    """
    root = Path(root)
    summary = read_summary(root)
    if summary.empty:
        raise ValueError(f"{root}: no summary table (run a sweep into it first)")
    sweep = Sweep.from_spec(json.loads((root / "sweep.json").read_text())) if refine else None
    rows = []
    ok = summary[(summary["status"] == "ok") & (summary["method"] == "S")]
    keys = ["scene", *GROUP_COLUMNS]
    for key, group in ok.groupby(keys, dropna=False, sort=True):
        values = dict(zip(keys, key, strict=True))
        scene = sweep.scene(values["scene"]) if sweep is not None else None
        variable = design_variable(scene, group)
        rows.append(_select_group(group.sort_values(variable), values, scene, variable))
    table = pd.DataFrame(rows, columns=list(SELECTION_UNITS))
    for column, unit in SELECTION_UNITS.items():
        table[column] = table[column].astype(str if unit == "" else np.float64) \
            if column not in ("n_grid", "n_solves") else table[column].astype(np.int64)
    if write:
        write_table(table, root / "selection.parquet", SELECTION_UNITS)
    return table


def design_variable(scene: Scene | None, group: pd.DataFrame) -> str:
    """The design axis a group is chosen over: the one its scene varies (from
    the results when the scene is not at hand: the one whose column varies,
    else the one the cases give)."""
    if scene is not None:
        varied = [axis for axis in DESIGN_AXES if axis in scene.axes]
        if varied:
            return varied[0]
    columns = [axis for axis in DESIGN_AXES if axis in group]  # (each its summary column)
    for column in columns:
        if group[column].nunique() > 1:
            return column
    given = [c for c in columns if group[c].notna().any()]
    return given[0] if given else "a"


def _select_group(group: pd.DataFrame, values: dict, scene: Scene | None,
                  variable: str) -> dict:
    """The selection row of one group's solved cases (sorted by ``variable``)."""
    a = group[variable].to_numpy()
    vm = group["max_von_mises"].to_numpy()
    gap = (group["overbend_max_von_mises"] - group["sagbend_max_von_mises"]).to_numpy()
    first = group.iloc[0]
    row = {**values, "method": first["method"], "dimension": first["dimension"],
           "water_depth": first["water_depth"], "n_grid": len(a), "variable": variable,
           f"{variable}_grid_min": float(a.min()), f"{variable}_grid_max": float(a.max()),
           "reference_a": scene.reference_a if scene is not None else math.nan}
    notes = []
    evaluate = (_Evaluator(scene, values, group, variable)
                if scene is not None and len(a) > 1 else None)

    i = int(np.argmin(vm))
    row[f"{variable}_min_stress"], row["min_max_von_mises"] = float(a[i]), float(vm[i])
    flat = a[vm <= (1.0 + FLAT_SHARE) * vm[i]]
    if len(flat) > 1:
        notes.append(f"flat minimum: max stress within {100 * FLAT_SHARE:g} % of it for "
                     f"{variable} in [{flat.min():.6g}, {flat.max():.6g}]")
    if len(a) < 3 or i in (0, len(a) - 1):
        notes.append("stress minimum at the end of the grid" if len(a) > 1 else "one grid point")
    elif evaluate is not None:
        step = min(a[i] - a[i - 1], a[i + 1] - a[i])
        try:
            best = minimize_scalar(lambda x: evaluate(x)["max_von_mises"], method="bounded",
                                   bounds=(a[i - 1], a[i + 1]),
                                   options={"xatol": XTOL_FRACTION * step})
            if best.fun <= vm[i]:
                row[f"{variable}_min_stress"] = float(best.x)
                row["min_max_von_mises"] = float(best.fun)
        except CASE_ERRORS as err:
            notes.append(f"minimum not refined: {evaluate.failure(err)}")

    row[f"{variable}_equal_peaks"] = row["equal_peaks_von_mises"] = math.nan
    row.update(dict.fromkeys(EQUAL_PEAKS_ANSWERS.values(), math.nan))
    finite = np.isfinite(gap)
    brackets = [j for j in range(len(a) - 1) if finite[j] and finite[j + 1]
                and np.sign(gap[j]) != np.sign(gap[j + 1])]
    if not brackets:
        notes.append("overbend and sagbend peaks do not cross on the grid")
    else:
        j = min(brackets, key=lambda j: max(vm[j], vm[j + 1]))
        k = j if abs(gap[j]) <= abs(gap[j + 1]) else j + 1  # grid estimate
        row[f"{variable}_equal_peaks"], row["equal_peaks_von_mises"] = float(a[k]), float(vm[k])
        row.update(_answers(group.iloc[k]))
        if gap[j] == 0.0 or gap[j + 1] == 0.0:
            pass
        elif evaluate is not None:
            try:
                root = brentq(lambda x: _gap(evaluate(x)), a[j], a[j + 1],
                              xtol=XTOL_FRACTION * (a[j + 1] - a[j]))
                row[f"{variable}_equal_peaks"] = float(root)
                row["equal_peaks_von_mises"] = evaluate(root)["max_von_mises"]
                row.update(_answers(evaluate(root)))
            except CASE_ERRORS as err:
                notes.append(f"equal peaks not refined: {evaluate.failure(err)}")
        else:
            notes.append("equal peaks: nearest grid point")
    row["n_solves"] = evaluate.solves if evaluate is not None else 0
    row["note"] = "; ".join(notes)
    return row


def _answers(summary) -> dict:
    """The lay's answers of a summary row (dict or Series) under the selection's names."""
    return {name: float(summary[column]) for column, name in EQUAL_PEAKS_ANSWERS.items()}


def _gap(summary: dict) -> float:
    """Overbend less sagbend peak von Mises stress [Pa] of a summary row."""
    return summary["overbend_max_von_mises"] - summary["sagbend_max_von_mises"]


class _Evaluator:
    """Summary of the group's case at a given value of its design axis
    ``variable`` (``a``), solved warm from the nearest value solved so far
    (the first from cold), for the scene's target when it has one; repeated
    values are cached."""

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


def format_selection(table: pd.DataFrame) -> str:
    """The selection as a plain-text table: the variable's choices (a in 1/m,
    a radius or a shift in m), stresses in MPa; the scene column as wide as
    its longest name."""
    width = max([5, *(len(str(name)) for name in table["scene"])])
    lines = [f"{'scene':<{width}} {'dim':<3} {'current':>10} {'variable':>14} "
             f"{'min_stress':>13} {'max VM':>8} {'equal_peaks':>13} {'peak VM':>8} "
             f"{'max util':>8} {'tip m':>6} {'reference_a':>11}  note"]
    for _, r in table.iterrows():
        current = f"{r['current_speed']:.2g}@{r['current_heading_deg']:.0f}°"
        v = r["variable"]
        lines.append(
            f"{r['scene']:<{width}} {r['dimension']:<3} {current:>10} {v:>14} "
            f"{_a(r[f'{v}_min_stress']):>13} "
            f"{_mpa(r['min_max_von_mises']):>8} {_a(r[f'{v}_equal_peaks']):>13} "
            f"{_mpa(r['equal_peaks_von_mises']):>8} {_num(r['equal_peaks_max_utilisation']):>8} "
            f"{_num(r['equal_peaks_tip_clearance']):>6} {_a(r['reference_a']):>11}  {r['note']}")
    return "\n".join(lines)


def _a(value: float) -> str:
    return "n/a" if not math.isfinite(value) else f"{value:.6f}"


def _num(value: float) -> str:
    return "n/a" if not math.isfinite(value) else f"{value:.3f}"


def _mpa(value: float) -> str:
    return "n/a" if not math.isfinite(value) else f"{value / 1e6:.1f}"

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
  between the two grid points that bracket it (the bracket of lowest stress
  when there are several), warm-started too: by :func:`scipy.optimize.brentq`
  on solves, or, where the sweep has both peaks' derivatives by the design
  axis's key at both points (the sweep file's ``sensitivities``), by the
  root of their cubic Hermite interpolant, confirmed and corrected by Newton
  on solves (:mod:`.select_refine`; without ``refine``, that root
  unconfirmed, the stress there interpolated linearly and the answers the
  nearest grid point's). ``n_solves_equal_peaks`` counts its solves,
  ``n_solves`` all the group's.

At the equal-peaks ``a`` the selection also gives the lay's answers there:
``equal_peaks_max_utilisation`` (the DNVGL-ST-F101 checks, NaN without a
``[checks]`` table) and ``equal_peaks_tip_clearance`` [m].

Refinement needs the scenes' base cases, which the sweep stores in
``sweep.json``; ``refine=False`` reports the grid values only (and the
roots the sensitivities give, unconfirmed).

Limits (:mod:`.limits`: the sweep file's ``[select]`` table, or the
``limits`` argument, which overrides it key by key) bound summary columns:
tip clearance, utilisation (at most 1 by default where the cases have a
``[checks]`` table), overbend and sagbend strain, the top tension's window
and the roller reaction. From the grid, interpolated linearly between grid
points, the selection gives the feasible range of ``a``
(``a_feasible_min``, ``a_feasible_max``; the widest, when there are
several; with ``refine``, an end a limit binds is the root of that
limit's margin between the grid points around it, found as the equal
peaks are, from the limit column's derivatives where the sweep has them;
without ``refine``, their Hermite root or the linear interpolation), the
limit binding at each end (``feasible_min_binds``, ``feasible_max_binds``:
"grid end" where none does), whether the equal-peaks ``a`` is inside a
feasible range (``equal_peaks_feasible``)
and, inside the range, ``a_best``: the ``a`` of the lowest
``max_utilisation`` (``max_von_mises`` without ``[checks]``;
``best_objective`` names it). Without a feasible point ``feasible`` is
False and ``ruled_out_by`` says which limit rules the scene out and by how
much.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.optimize import minimize_scalar

from ..output.io import write_table
from .dataset import read_summary
from .limits import (
    check_limits,
    feasible_ranges,
    group_limits,
    limit_text,
    shortfall_text,
)
from .runner import CASE_ERRORS
from .select_refine import XTOL_FRACTION, Evaluator, grid_root, refined_ends, slopes
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
    "equal_peaks_max_von_mises_over_smys": "-", "equal_peaks_yielded": "",
    "equal_peaks_bears_on_tip": "", "n_yielded": "",
    "limits": "", "feasible": "", "a_feasible_min": "1/m", "a_feasible_max": "1/m",
    "feasible_min_binds": "", "feasible_max_binds": "", "ruled_out_by": "",
    "equal_peaks_feasible": "", "a_best": "1/m", "best_objective": "",
    "best_max_utilisation": "-", "best_max_von_mises": "Pa",
    "reference_a": "1/m", "n_solves": "", "n_solves_equal_peaks": "", "note": "",
    "variable": "",
    # a roller stinger's design axes, as a's columns
    **{f"{axis}_{what}": AXES[axis][2] for axis in DESIGN_AXES[1:]
       for what in ("grid_min", "grid_max", "min_stress", "equal_peaks", "feasible_min",
                    "feasible_max", "best")},
}
# flags: a nullable boolean (missing where there is no equal-peaks a)
FLAG_COLUMNS = ("equal_peaks_yielded", "equal_peaks_bears_on_tip", "feasible",
                "equal_peaks_feasible")
COUNT_COLUMNS = ("n_grid", "n_solves", "n_solves_equal_peaks", "n_yielded")
# the inputs that, with the scene, make one selection group
GROUP_COLUMNS = ("water_depth", "current_speed", "current_heading_deg", "given_top_tension",
                 "given_bottom_tension", "given_pipe_length")
# summary column -> selection column, reported at the equal-peaks a
EQUAL_PEAKS_ANSWERS = {"max_utilisation": "equal_peaks_max_utilisation",
                       "tip_clearance": "equal_peaks_tip_clearance",
                       "max_von_mises_over_smys": "equal_peaks_max_von_mises_over_smys",
                       "yielded": "equal_peaks_yielded",
                       "bears_on_tip": "equal_peaks_bears_on_tip"}
FLAT_SHARE = 0.005  # grid points this close to the minimum stress make it "flat"


def select(root: str | os.PathLike, *, refine: bool = True, write: bool = True,
           limits: Mapping | None = None, sensitivities: bool = True) -> pd.DataFrame:
    """The selection table of the results directory ``root`` (one row per
    S-lay group: scene and the other inputs; the columns of
    ``SELECTION_UNITS``, SI).

    ``refine``: refine the grid's choices with further solves (needs
    ``root/sweep.json``); False: grid values only. ``limits``: the
    ``[select]`` keys of :mod:`.limits` (SI), each replacing the sweep
    file's. ``sensitivities``: use the sweep's derivatives by the design
    axis where it has them (False: refine by solves alone). Written to
    ``root/selection.parquet`` (units in the schema)
    when ``write``. Raises ValueError when ``root`` has no summary table (or,
    with ``refine``, no ``sweep.json``), or a limit is not valid (naming it).
    """
    root = Path(root)
    given = check_limits("limits", dict(limits or {}))
    summary = read_summary(root)
    if summary.empty:
        raise ValueError(f"{root}: no summary table (run a sweep into it first)")
    spec_path = root / "sweep.json"
    if refine and not spec_path.is_file():
        raise ValueError(f"{root}: no sweep.json, whose scenes refinement solves (refine=False "
                         "uses the grid alone)")
    spec = json.loads(spec_path.read_text()) if spec_path.is_file() else {}
    limits = {**check_limits("select", spec.get("select", {})), **given}
    sweep = Sweep.from_spec(spec) if refine else None
    references = {s["name"]: s.get("reference_a") for s in spec.get("scenes", [])}
    rows = []
    ok = summary[(summary["status"] == "ok") & (summary["method"] == "S")]
    keys = ["scene", *GROUP_COLUMNS]
    for key, group in ok.groupby(keys, dropna=False, sort=True):
        values = dict(zip(keys, key, strict=True))
        scene = sweep.scene(values["scene"]) if sweep is not None else None
        variable = design_variable(scene, group)
        group = group.sort_values(variable)
        if not sensitivities:
            group = group[[c for c in group if not c.startswith("d_")]]
        rows.append(_select_group(group, values, scene, variable, limits,
                                  references.get(values["scene"])))
    table = pd.DataFrame(rows, columns=list(SELECTION_UNITS))
    for column, unit in SELECTION_UNITS.items():
        kind = ("boolean" if column in FLAG_COLUMNS else np.int64 if column in COUNT_COLUMNS
                else str if unit == "" else np.float64)
        table[column] = table[column].astype(kind)
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


def _select_group(group: pd.DataFrame, values: dict, scene: Scene | None, variable: str,
                  limits: Mapping, reference: float | None) -> dict:
    """The selection row of one group's solved cases (sorted by ``variable``)
    within ``limits`` (:func:`.limits.check_limits`'); ``reference``: the
    scene's ``reference_a`` (None: not given)."""
    a = group[variable].to_numpy()
    vm = group["max_von_mises"].to_numpy()
    first = group.iloc[0]
    row = {**values, "method": first["method"], "dimension": first["dimension"],
           "water_depth": first["water_depth"], "n_grid": len(a), "variable": variable,
           "n_yielded": int(group["yielded"].fillna(False).sum()) if "yielded" in group else 0,
           f"{variable}_grid_min": float(a.min()), f"{variable}_grid_max": float(a.max()),
           "reference_a": math.nan if reference is None else float(reference)}
    notes = []
    evaluate = (Evaluator(scene, values, group, variable)
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

    before = evaluate.solves if evaluate is not None else 0
    row.update(_equal_peaks(group, variable, evaluate, notes))
    row["n_solves_equal_peaks"] = (evaluate.solves if evaluate is not None else 0) - before
    row["note"] = "; ".join(notes)
    row.update(_limit_columns(group, variable, limits, row, evaluate))
    row["n_solves"] = evaluate.solves if evaluate is not None else 0
    return row


def _equal_peaks(group: pd.DataFrame, variable: str, evaluate: Evaluator | None,
                 notes: list[str]) -> dict:
    """The equal-peaks columns of one group's selection row: the root of
    the overbend less the sagbend peak between the grid points that bracket
    it (the bracket of lowest stress when there are several), found by
    :func:`.select_refine.grid_root` (the nearest grid point where it
    cannot refine), the lay's answers there; how it was found, or why not,
    added to ``notes``."""
    a = group[variable].to_numpy()
    vm = group["max_von_mises"].to_numpy()
    gap = (group["overbend_max_von_mises"] - group["sagbend_max_von_mises"]).to_numpy()
    over, sag = (slopes(group, variable, f"{bend}_max_von_mises")
                 for bend in ("overbend", "sagbend"))
    row = {f"{variable}_equal_peaks": math.nan, "equal_peaks_von_mises": math.nan,
           **dict.fromkeys(EQUAL_PEAKS_ANSWERS.values(), None)}
    finite = np.isfinite(gap)
    brackets = [j for j in range(len(a) - 1) if finite[j] and finite[j + 1]
                and np.sign(gap[j]) != np.sign(gap[j + 1])]
    if not brackets:
        notes.append("overbend and sagbend peaks do not cross on the grid")
        return row
    j = min(brackets, key=lambda j: max(vm[j], vm[j + 1]))
    k = j if abs(gap[j]) <= abs(gap[j + 1]) else j + 1  # grid estimate
    row[f"{variable}_equal_peaks"], row["equal_peaks_von_mises"] = float(a[k]), float(vm[k])
    row.update(_answers(group.iloc[k]))
    if gap[j] == 0.0 or gap[j + 1] == 0.0:
        return row
    try:
        found = grid_root(_gap, a, gap, None if over is None else over - sag, j, evaluate)
    except CASE_ERRORS as err:
        notes.append(f"equal peaks not refined: {evaluate.failure(err)}")
        return row
    if found is None:
        notes.append("equal peaks: nearest grid point")
        return row
    root, how, by_sensitivities = found
    row[f"{variable}_equal_peaks"] = float(root)
    if by_sensitivities:
        notes.append(f"equal peaks by {how}")
    if evaluate is not None:
        row["equal_peaks_von_mises"] = evaluate(root)["max_von_mises"]
        row.update(_answers(evaluate(root)))
    else:  # the grid's answers, interpolated linearly
        t = (root - a[j]) / (a[j + 1] - a[j])
        row["equal_peaks_von_mises"] = float((1 - t) * vm[j] + t * vm[j + 1])
    return row


def _answers(summary) -> dict:
    """The lay's answers of a summary row (dict or Series) under the selection's names."""
    answers = {}
    for column, name in EQUAL_PEAKS_ANSWERS.items():
        value = summary.get(column)  # (None: a results directory written without it)
        answers[name] = (value if value is None or isinstance(value, bool | np.bool_)
                         or value is pd.NA else float(value))
    return answers


def _limit_columns(group: pd.DataFrame, variable: str, limits: Mapping, row: dict,
                   evaluate: Evaluator | None) -> dict:
    """The limits' columns of one group's selection row (``row``: its
    choices so far, the equal-peaks ``a`` and the refined stress minimum
    among them), the range's ends refined by ``evaluate`` when given
    (:func:`_refined_ends`); notes on limits that cannot apply, or ends not
    refined, are added to its note."""
    a = group[variable].to_numpy(dtype=float)
    applied, notes = group_limits(limits, group)
    margins = {limit: limit.margin(group[limit.column]) for limit in applied}
    out = {"limits": "; ".join(limit_text(limit) for limit in applied) or "none",
           "ruled_out_by": "", "best_objective": "", "feasible_min_binds": "",
           "feasible_max_binds": "", "equal_peaks_feasible": False}
    ranges = feasible_ranges(a, margins)
    out["feasible"] = bool(ranges)
    if not ranges:
        out["ruled_out_by"] = shortfall_text(a, margins, variable)
        out["equal_peaks_feasible"] = None
        return _with_notes(out, row, notes)
    widest = max(ranges, key=lambda r: r.high - r.low)
    notes += [f"feasible also for {variable} in [{r.low:.6g}, {r.high:.6g}]"
              for r in ranges if r is not widest]
    derivatives = {limit: _margin_slopes(group, variable, limit) for limit in applied}
    widest, solved = refined_ends(widest, a, margins, derivatives, evaluate, notes)
    out.update({f"{variable}_feasible_min": widest.low, f"{variable}_feasible_max": widest.high,
                "feasible_min_binds": limit_text(widest.low_binds),
                "feasible_max_binds": limit_text(widest.high_binds)})
    equal = row[f"{variable}_equal_peaks"]
    out["equal_peaks_feasible"] = (bool(any(r.low <= equal <= r.high for r in ranges))
                                   if math.isfinite(equal) else None)
    objective = ("max_utilisation" if np.isfinite(group["max_utilisation"]).any()
                 else "max_von_mises")
    refined = row[f"{variable}_min_stress"]
    if objective == "max_von_mises" and widest.low <= refined <= widest.high:
        solved[refined] = {"max_von_mises": row["min_max_von_mises"], "max_utilisation": math.nan}

    def at(x: float, column: str) -> float:  # a solved value, else the grid's, interpolated
        return float(solved[x][column]) if x in solved else float(np.interp(x, a, group[column]))

    inside = (a >= widest.low) & (a <= widest.high)
    candidates = [*a[inside], widest.low, widest.high, *([refined] if refined in solved else [])]
    best = float(candidates[int(np.nanargmin([at(x, objective) for x in candidates]))])
    out.update({f"{variable}_best": best, "best_objective": objective,
                "best_max_utilisation": at(best, "max_utilisation"),
                "best_max_von_mises": at(best, "max_von_mises")})
    return _with_notes(out, row, notes)


def _margin_slopes(group: pd.DataFrame, variable: str, limit) -> np.ndarray | None:
    """The derivative of ``limit``'s margin by the design axis at the grid
    points (None: the sweep has no sensitivities)."""
    d = slopes(group, variable, limit.column)
    return None if d is None else d if limit.sense == "min" else -d


def _with_notes(out: dict, row: dict, notes: list[str]) -> dict:
    """``out`` with ``notes`` appended to the note of ``row``."""
    if notes:
        out["note"] = "; ".join([n for n in (row.get("note", ""), *notes) if n])
    return out


def _gap(summary: dict) -> float:
    """Overbend less sagbend peak von Mises stress [Pa] of a summary row."""
    return summary["overbend_max_von_mises"] - summary["sagbend_max_von_mises"]

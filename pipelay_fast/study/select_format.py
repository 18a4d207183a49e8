"""The selection (:func:`pipelay_fast.study.select.select`) as plain text:
the choices, then the limits, then a legend that spells out every
column's name and gives its unit."""

from __future__ import annotations

import math
import textwrap

import pandas as pd

from .sweep import AXES

__all__ = ["LEGEND", "design_value", "format_selection"]

LEGEND_WIDTH = 100  # characters a legend line is wrapped at

LEGEND = (
    "legend:",
    "  variable: the stinger's design axis the scene varies, with its unit (a: the "
    "curvature, 1/m; stinger_radius, roller_shift: m); min_stress, equal_peaks, "
    "feasible_min, feasible_max, best and reference_a are in that unit",
    "  current: surface current speed [m/s] @ heading [deg]; dim: 2d or 3d solve",
    "  min_stress: where the largest von Mises stress along the pipe is least; max_vm: "
    "that stress [MPa]",
    "  equal_peaks: where the overbend and sagbend peak von Mises stresses are equal; "
    "peak_vm: that peak [MPa]; util: the largest code-check utilisation there [-] "
    "(n/a without [checks]); tip: the tip clearance there [m]; vm/smys: the largest von "
    "Mises stress there over SMYS [-]",
    "  flags (at equal_peaks): yielded = von Mises above SMYS somewhere along the pipe; "
    "on_tip = the pipe bears on the stinger's tip; - = neither",
    "  yielded_grid: grid cases with von Mises above SMYS / grid cases",
    "  feasible_min, feasible_max: the widest range inside every limit (each limit's "
    "column linear between grid points); binds: the limit reached at that end (grid end: "
    "none, the range reaches the grid's end)",
    "  best: inside that range, where the largest utilisation is least (max_util [-]; the "
    "largest von Mises stress without [checks], max_vm [MPa]); equal_peaks_in: equal_peaks "
    "lies in a feasible range",
)


def format_selection(table: pd.DataFrame) -> str:
    """The selection as plain text: a table of the choices (the variable's
    values in its unit, stresses in MPa), a table of the limits' answers
    (feasible range, binding limits, best value; or why none is feasible),
    each headed by the columns' names and a line of their units, and the
    :data:`LEGEND` (wrapped at LEGEND_WIDTH)."""
    table = table.assign(scene=_scene_labels(table))
    width = max([5, *(len(str(name)) for name in table["scene"])])
    choices = [_row(width, "scene", "dim", "current", "variable", "min_stress", "max_vm",
                    "equal_peaks", "peak_vm", "util", "tip", "vm/smys", "flags",
                    "reference_a", "note"),
               _row(width, "", "", "m/s@deg", "[unit]", "variable's", "MPa", "variable's",
                    "MPa", "-", "m", "-", "", "variable's", "")]
    limits = [_limits_row(width, "scene", "dim", "current", "variable", "feasible_min",
                          "feasible_max", "best", "max_util", "max_vm", "equal_peaks_in",
                          "yielded_grid", "binds (at feasible_min | at feasible_max)"),
              _limits_row(width, "", "", "m/s@deg", "[unit]", "variable's", "variable's",
                          "variable's", "-", "MPa", "", "", "")]
    for _, r in table.iterrows():
        v = r["variable"]
        key = (r["scene"], r["dimension"], _current(r), f"{v}[{AXES[v][2]}]")
        choices.append(_row(
            width, *key, design_value(r[f"{v}_min_stress"]), _mpa(r["min_max_von_mises"]),
            design_value(r[f"{v}_equal_peaks"]), _mpa(r["equal_peaks_von_mises"]),
            _num(r["equal_peaks_max_utilisation"]), _num(r["equal_peaks_tip_clearance"]),
            _num(r["equal_peaks_max_von_mises_over_smys"]), _flags(r),
            design_value(r["reference_a"]), r["note"]))
        yielded = f"{r['n_yielded']}/{r['n_grid']}"
        if not r["feasible"]:
            limits.append(_limits_row(width, *key, "infeasible", "", "", "", "", "", yielded,
                                      r["ruled_out_by"]))
            continue
        limits.append(_limits_row(
            width, *key, design_value(r[f"{v}_feasible_min"]),
            design_value(r[f"{v}_feasible_max"]), design_value(r[f"{v}_best"]),
            _num(r["best_max_utilisation"]), _mpa(r["best_max_von_mises"]),
            _yes(r["equal_peaks_feasible"]), yielded,
            f"{r['feasible_min_binds']} | {r['feasible_max_binds']}"))
    applied = sorted(set(table["limits"]))
    header = "limits: " + " / ".join(applied) if applied else "limits: none"
    legend = [textwrap.fill(line, LEGEND_WIDTH, subsequent_indent="    ") for line in LEGEND]
    return "\n".join([*choices, "", header, *limits, "", *legend])


def _row(width, scene, dim, current, variable, min_stress, max_vm, equal, peak, util, tip,
         over, flags, reference, note) -> str:
    return (f"{scene:<{width}} {dim:<3} {current:>9} {variable:>19} {min_stress:>12} "
            f"{max_vm:>7} {equal:>12} {peak:>7} {util:>6} {tip:>7} {over:>7} {flags:>14} "
            f"{reference:>12}  {note}").rstrip()


def _limits_row(width, scene, dim, current, variable, low, high, best, util, vm, inside,
                yielded, binds) -> str:
    return (f"{scene:<{width}} {dim:<3} {current:>9} {variable:>19} {low:>12} {high:>12} "
            f"{best:>12} {util:>8} {vm:>7} {inside:>14} {yielded:>12}  {binds}").rstrip()


def _scene_labels(table: pd.DataFrame) -> pd.Series:
    """Each row's scene, with its water depth where the scene has several
    (a depth axis): "S@60m"."""
    depths = table.groupby("scene")["water_depth"].transform("nunique")
    return table["scene"].where(depths <= 1, table["scene"] + "@" + table["water_depth"].map(
        lambda d: f"{d:g}m"))


def _current(r) -> str:
    return f"{r['current_speed']:.2g}@{r['current_heading_deg']:.0f}"


def _flags(r) -> str:
    flags = [name for name, column in (("yielded", "equal_peaks_yielded"),
                                       ("on_tip", "equal_peaks_bears_on_tip"))
             if _true(r[column])]
    if not flags and (pd.isna(r["equal_peaks_yielded"]) or pd.isna(r["equal_peaks_bears_on_tip"])):
        return "n/a"
    return ",".join(flags) or "-"


def _true(value) -> bool:
    return not pd.isna(value) and bool(value)


def _yes(value) -> str:
    return "n/a" if pd.isna(value) else ("yes" if value else "no")


def design_value(value: float) -> str:
    """A value of a design axis as ``select`` prints it (and the sweep
    figure labels it): six decimals, "n/a" when not finite."""
    return "n/a" if not math.isfinite(value) else f"{value:.6f}"


def _num(value: float) -> str:
    return "n/a" if not math.isfinite(value) else f"{value:.3f}"


def _mpa(value: float) -> str:
    return "n/a" if not math.isfinite(value) else f"{value / 1e6:.1f}"

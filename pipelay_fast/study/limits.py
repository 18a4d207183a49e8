"""The lay's limits in ``select``: the ``[select]`` table of a sweep file (or
the command line's options) and the feasible range of a design axis on a grid.

A limit bounds one summary column, from below or from above::

    [select]
    min_tip_clearance = 0.2          # m, tip_clearance >= 0.2
    max_utilisation = 1.0            # -, max_utilisation <= 1 (the default where [checks] is given)
    max_overbend_strain = 0.0025     # -, overbend_max_strain <= 0.0025
    max_sagbend_strain = 0.0015      # -, sagbend_max_strain <= 0.0015
    top_tension = [400e3, 900e3]     # N, 400 kN <= top_tension <= 900 kN (the tensioner's range)
    max_roller_reaction = 250e3      # N, max_roller_reaction <= 250 kN (roller stingers)

Each limit's margin is the distance of its column inside the limit, in the
column's unit (``column - value`` for a minimum, ``value - column`` for a
maximum): the grid point is feasible where every margin is >= 0. Between two
grid points each margin is interpolated linearly, so a range's end lies
where the first margin crosses zero (:func:`feasible_ranges`); its error is
the interpolation's, h^2 max|m''| / (8 |m'|) in the axis for a grid step h.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from typing import NamedTuple

import numpy as np

from ..input.validate import fail, reject_unknown
from ..output.results import SUMMARY_UNITS

__all__ = ["LIMIT_KEYS", "Limit", "Range", "check_limits", "feasible_ranges", "group_limits",
           "limit_text", "shortfall_text"]

# key -> (summary column, its bound: "min", "max" or "window", a [min, max] pair);
# each in its column's unit (SUMMARY_UNITS)
LIMIT_KEYS = {"min_tip_clearance": ("tip_clearance", "min"),
              "max_utilisation": ("max_utilisation", "max"),
              "max_overbend_strain": ("overbend_max_strain", "max"),
              "max_sagbend_strain": ("sagbend_max_strain", "max"),
              "top_tension": ("top_tension", "window"),
              "max_roller_reaction": ("max_roller_reaction", "max")}
DEFAULT_MAX_UTILISATION = 1.0  # where the cases have a [checks] table
# display unit of an SI unit in the printed limits
_DISPLAY = {"N": ("kN", 1e-3)}


class Limit(NamedTuple):
    """One bound on a summary column: ``column`` >= ``value`` (sense "min")
    or <= ``value`` (sense "max"), in the column's SI ``unit``."""

    column: str
    sense: str
    value: float
    unit: str

    def margin(self, values) -> np.ndarray:
        """How far ``values`` (the column's) lie inside the limit [unit]; < 0 outside."""
        v = np.asarray(values, dtype=float)
        return v - self.value if self.sense == "min" else self.value - v


def check_limits(path: str, table) -> dict:
    """The limits of a ``[select]`` table (or the command line's) as
    {key: value} (``top_tension``: a (min, max) tuple), SI; a value of the
    wrong type or out of range raises ValueError naming ``path.key`` and the
    value."""
    if not isinstance(table, Mapping):
        fail(path, table, "must be a table of limits, e.g. {min_tip_clearance = 0.2}")
    reject_unknown(table, list(LIMIT_KEYS), f"{path}.")
    limits = {}
    for key, value in table.items():
        where = f"{path}.{key}"
        if key == "top_tension":
            if not isinstance(value, list | tuple) or len(value) != 2:
                fail(where, value, "must be a list [min, max] of tensions (N)")
            lo, hi = (_number(f"{where}[{i}]", v) for i, v in enumerate(value))
            if lo < 0.0 or lo >= hi:
                fail(where, value, "must have 0 <= min < max (N)")
            limits[key] = (lo, hi)
            continue
        number = _number(where, value)
        if key == "min_tip_clearance" and number < 0.0:
            fail(where, value, "must be >= 0 (m)")
        if key != "min_tip_clearance" and number <= 0.0:
            fail(where, value, f"must be > 0 ({SUMMARY_UNITS[LIMIT_KEYS[key][0]]})")
        limits[key] = number
    return limits


def _number(path, value) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value):
        fail(path, value, "must be a finite number")
    return float(value)


def group_limits(limits: Mapping, group) -> tuple[list[Limit], list[str]]:
    """(the limits that apply to a group of summary rows, notes on those that
    cannot): ``limits`` as :func:`check_limits` gives them, with
    ``max_utilisation`` DEFAULT_MAX_UTILISATION where the rows have
    utilisations ([checks]) and none is given. A limit whose column is NaN
    in every row (no ``[checks]``, no rollers) is left out with a note."""
    given = dict(limits)
    if "max_utilisation" not in given and np.isfinite(group["max_utilisation"]).any():
        given["max_utilisation"] = DEFAULT_MAX_UTILISATION
    applied, notes = [], []
    for key, value in given.items():
        column, sense = LIMIT_KEYS[key]
        unit = SUMMARY_UNITS[column]
        if not np.isfinite(group[column].to_numpy(dtype=float)).any():
            notes.append(f"{key} not applied: {column} is not evaluated for these cases")
            continue
        if sense == "window":
            applied += [Limit(column, "min", value[0], unit), Limit(column, "max", value[1], unit)]
        else:
            applied.append(Limit(column, sense, float(value), unit))
    return applied, notes


class Range(NamedTuple):
    """A feasible range of the axis: its ends and the limit binding at each
    (None: the grid's end, where no limit binds)."""

    low: float
    high: float
    low_binds: Limit | None
    high_binds: Limit | None


def feasible_ranges(x, margins) -> list[Range]:
    """The ranges of ``x`` (the grid, increasing) where every margin is >= 0,
    each margin interpolated linearly between grid points. ``margins``:
    {Limit: its margins at the grid points}. A NaN margin makes its grid
    point infeasible and the segments beside it too (a range ending there
    is then said to end at the "grid end"). Touching pieces are merged;
    the ranges are ordered from the lowest x."""
    x = np.asarray(x, dtype=float)
    limits = list(margins)
    m = np.array([np.asarray(margins[k], dtype=float) for k in limits]).reshape(len(limits),
                                                                                 x.size)
    ok = np.all(m >= 0.0, axis=0)  # (NaN compares False)
    pieces = [(x[i], x[i], None, None) for i in range(x.size) if ok[i]]
    for i in range(x.size - 1):
        piece = _segment(x[i], x[i + 1], m[:, i], m[:, i + 1], limits)
        if piece is not None:
            pieces.append(piece)
    pieces.sort(key=lambda p: (p[0], p[1]))
    ranges: list[Range] = []
    for lo, hi, lo_bind, hi_bind in pieces:
        if ranges and lo <= ranges[-1].high:  # (a piece at a grid point binds nothing)
            last = ranges[-1]
            if lo == last.low and last.low_binds is None:
                last = last._replace(low_binds=lo_bind)
            if hi > last.high or (hi == last.high and last.high_binds is None):
                last = last._replace(high=hi, high_binds=hi_bind)
            ranges[-1] = last
            continue
        ranges.append(Range(lo, hi, lo_bind, hi_bind))
    return ranges


def _segment(x0, x1, m0, m1, limits):
    """The feasible piece (low, high, its binding limits) of the segment [x0,
    x1] with end margins ``m0``, ``m1`` (one per limit), or None."""
    if not (np.isfinite(m0).all() and np.isfinite(m1).all()):
        return None
    lo, hi, lo_bind, hi_bind = 0.0, 1.0, None, None
    for a, b, limit in zip(m0, m1, limits, strict=True):
        if a < 0.0 and b < 0.0:
            return None
        if a >= 0.0 and b >= 0.0:
            continue
        t = a / (a - b)  # where the margin crosses zero
        if a < 0.0 and t > lo:
            lo, lo_bind = t, limit
        elif b < 0.0 and t < hi:
            hi, hi_bind = t, limit
    if lo > hi:
        return None
    return x0 + lo * (x1 - x0), x0 + hi * (x1 - x0), lo_bind, hi_bind


def limit_text(limit: Limit | None) -> str:
    """The limit as text in display units (``tip_clearance >= 0.2 m``); "grid end" for None."""
    if limit is None:
        return "grid end"
    sign = ">=" if limit.sense == "min" else "<="
    return f"{limit.column} {sign} {_quantity(limit.value, limit.unit)}"


def _quantity(value: float, unit: str) -> str:
    shown, factor = _DISPLAY.get(unit, (unit, 1.0))
    return f"{value * factor:.4g}" + ("" if shown in ("", "-") else f" {shown}")


def shortfall_text(x, margins, variable: str) -> str:
    """Why no point of the grid ``x`` meets every limit (``margins`` as for
    :func:`feasible_ranges`): each limit that no grid point meets, with how
    far its best point falls short; if each is met somewhere, the limits that
    conflict, at the grid point whose worst shortfall (relative to the
    limit's value) is least, and where each limit holds."""
    alone = []
    for limit, m in margins.items():
        m = np.asarray(m, dtype=float)
        if not np.isfinite(m).any():
            alone.append(f"{limit_text(limit)}: not evaluated")
        elif np.nanmax(m) < 0.0:
            i = int(np.nanargmax(m))
            alone.append(f"{limit_text(limit)}: short by {_quantity(-m[i], limit.unit)} at best "
                         f"({variable} = {x[i]:.6g})")
    if alone:
        return "ruled out by " + "; ".join(alone)
    each = []
    for limit, m in margins.items():
        spans = ", ".join(f"[{r.low:.6g}, {r.high:.6g}]"
                          for r in feasible_ranges(x, {limit: m}))
        each.append(f"{limit_text(limit)} holds for {variable} in {spans}")
    # each shortfall relative to its limit's value (a limit of 0, as a
    # clearance of 0 m: in its own unit)
    scaled = np.array([np.asarray(m, dtype=float) / (abs(limit.value) or 1.0)
                       for limit, m in margins.items()])
    i = int(np.nanargmax(np.nanmin(scaled, axis=0)))
    short = [f"{limit_text(limit)} short by {_quantity(-m[i], limit.unit)}"
             for limit, m in margins.items() if m[i] < 0.0]
    return (f"the limits conflict: {'; '.join(each)}; at best ({variable} = {x[i]:.6g}) "
            + ", ".join(short))

"""Sensitivities in a sweep: the sweep file's ``sensitivities = [...]``,
their summary columns, and the roots ``select`` finds from them.

Each case of a sweep with ``sensitivities = ["lay.stinger.a", ...]`` is
solved with ``pf.solve(case, sensitivities=keys)``
(:func:`pipelay_fast.output.sensitivity.sensitivity_table`): its summary row
gets ``d_<row>__d_<key>``, the derivative of each sensitivity row (the
numeric summary columns and the peaks' arc lengths ``s_<peak>``) with
respect to each key, in the unit ``<row unit>/<key unit>`` (``-`` written
1, a compound key unit in brackets: ``Pa/(1/m)``), NaN where it is not
differentiable or the scene's case does not give the key, the reasons in
``sensitivity_reasons``.

:func:`hermite_newton` finds the root of an answer between two grid points
from its values and derivatives there: the root of their cubic Hermite
interpolant, then Newton on solves at the root found, with the
interpolant's slope there, kept inside the bracket.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Mapping, Sequence

import numpy as np

from ..input.keys import number_units
from ..input.limits import ROUNDOFF
from ..input.validate import fail, number_at
from ..output.sensitivity import summary_rows

__all__ = ["REASONS", "check_sensitivities", "column_name", "given_keys", "hermite_newton",
           "hermite_root", "sensitivity_columns", "sensitivity_values"]

REASONS = "sensitivity_reasons"  # the text column of the reasons for NaN


def check_sensitivities(path: str, value, cases: Sequence) -> tuple[str, ...]:
    """The keys of a sweep file's ``sensitivities`` (a list of dotted numeric
    case keys, each given as a number by at least one of ``cases``, the
    scenes' base cases). ValueError naming ``path`` otherwise."""
    if not isinstance(value, list) or not all(isinstance(k, str) for k in value):
        fail(path, value, "must be a list of dotted case keys, e.g. [\"lay.stinger.a\"]")
    units = number_units()
    for i, key in enumerate(value):
        if key in value[:i]:
            fail(path, value, f"repeats the key {key!r}")
        if key not in units:
            fail(f"{path}[{i}]", key, "is not a numeric case key (see docs/keys.md)")
        if not any(given_keys(case, [key]) for case in cases):
            fail(f"{path}[{i}]", key, "is not given as a number by any scene's case")
    return tuple(value)


def given_keys(case, keys: Sequence[str]) -> tuple[str, ...]:
    """The keys of ``keys`` that ``case`` gives as a number."""
    tables = case.to_dict()
    return tuple(key for key in keys if number_at(tables, key) is not None)


def column_name(row: str, key: str) -> str:
    """The summary column of d ``row`` / d ``key``."""
    return f"d_{row}__d_{key}"


def _unit(row_unit: str, key_unit: str) -> str:
    top = "1" if row_unit in ("", "-") else row_unit
    if key_unit in ("", "-"):
        return top
    return f"{top}/({key_unit})" if any(c in key_unit for c in "/ ") else f"{top}/{key_unit}"


def sensitivity_columns(keys: Sequence[str]) -> dict[str, str]:
    """{column: unit} of the summary's sensitivity columns for ``keys`` (and
    the reasons' text column); {} without keys."""
    if not keys:
        return {}
    units = number_units()
    columns = {column_name(row, key): _unit(unit, units[key])
               for key in keys for row, unit in summary_rows().items()}
    columns[REASONS] = ""
    return columns


def sensitivity_values(table, keys: Sequence[str], asked: Sequence[str] = ()) -> dict:
    """The sensitivity columns of one summary row from ``table`` (a
    ``Result.sensitivities`` with a column for each of ``keys``; None
    without keys), and in ``sensitivity_reasons`` the reasons for NaN: each
    distinct reason once, with the rows it concerns ("key: reason [rows]"),
    and each of the sweep's keys ``asked`` not in ``keys`` as not given."""
    values, rows_of = {}, {}
    if table is not None:
        values = {column_name(row, key): float(table.at[row, key])
                  for key in keys for row in table.index}
        for row, text in table["reason"].items():
            if text:
                rows_of.setdefault(text, []).append(row)
    every = 0 if table is None else len(table.index)
    reasons = [f"{text} [{'every row' if len(rows) == every else ', '.join(rows)}]"
               for text, rows in rows_of.items()]
    reasons += [f"{key}: not a number in the scene's case" for key in asked if key not in keys]
    values[REASONS] = "; ".join(reasons)
    return values


def hermite_root(x0: float, x1: float, f0: float, f1: float, d0: float, d1: float
                 ) -> tuple[float, float]:
    """(the root in [x0, x1] of the cubic Hermite interpolant of values
    ``f0``, ``f1`` (of opposite signs) and slopes ``d0``, ``d1`` at ``x0``,
    ``x1``; the interpolant's slope there). Of several roots, the one nearest
    the linear interpolant's."""
    h = x1 - x0
    p0, p1, m0, m1 = f0, f1, d0 * h, d1 * h  # in t = (x - x0) / h
    coefficients = [2 * p0 + m0 - 2 * p1 + m1, -3 * p0 - 2 * m0 + 3 * p1 - m1, m0, p0]
    roots = [t.real for t in np.roots(coefficients)
             if abs(t.imag) <= ROUNDOFF and -ROUNDOFF <= t.real <= 1.0 + ROUNDOFF]
    linear = f0 / (f0 - f1)
    t = min(roots, key=lambda r: abs(r - linear)) if roots else linear
    t = min(max(t, 0.0), 1.0)
    slope = (3 * coefficients[0] * t**2 + 2 * coefficients[1] * t + coefficients[2]) / h
    return x0 + t * h, slope


def hermite_newton(f: Callable[[float], float], bracket: Mapping, xtol: float
                   ) -> tuple[float, int]:
    """(a root of ``f``, the evaluations of ``f`` made), ``f`` solved in
    the bracket ``bracket`` = {x: (f(x), f'(x))} of two points where ``f``
    has opposite signs.

    The first trial is :func:`hermite_root`; each trial is solved, and is the
    root when the Newton step f(x) / s from it is at most ``xtol``, s the
    Hermite interpolant's slope at the first trial, the secant through the
    last two trials at the next; else the next trial is x - f(x) / s inside
    the bracket narrowed by the trial's sign, or the bracket's middle where
    it falls outside or the step is not half the one before it at most
    (Newton no faster than bisection: rtsafe's rule), until the bracket is
    narrower than ``xtol`` (the end of least |f| is then the root)."""
    (x0, (f0, d0)), (x1, (f1, d1)) = sorted(bracket.items())
    x, slope = hermite_root(x0, x1, f0, f1, d0, d1)
    lo, hi, f_lo = x0, x1, f0
    best = min(((abs(f0), x0), (abs(f1), x1)))
    last, before = None, math.inf
    for n in itertools.count(1):  # (ends: the bracket halves every two trials at least)
        fx = f(x)
        best = min(best, (abs(fx), x))
        if fx == 0.0:
            return x, n
        if last is not None and last[0] != x and last[1] != fx:
            slope = (fx - last[1]) / (x - last[0])
        last = (x, fx)
        step = fx / slope if slope != 0.0 and math.isfinite(slope) else math.inf
        if abs(step) <= xtol:
            return x, n
        if (fx < 0.0) == (f_lo < 0.0):
            lo, f_lo = x, fx
        else:
            hi = x
        if hi - lo <= xtol:
            return best[1], n
        if lo < x - step < hi and abs(step) <= 0.5 * abs(before):
            x, before = x - step, step
        else:
            x, before = 0.5 * (lo + hi), 0.5 * (hi - lo)

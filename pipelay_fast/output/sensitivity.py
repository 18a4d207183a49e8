"""Exact sensitivities of a solved case's summary: the derivative of every
numeric summary column, and of the nodes its peaks sit on, with respect to
named numeric case keys (``pipelay_fast.solve(case, sensitivities=[...])``).

Each key p is moved by +-h through the case's own build
(:meth:`pipelay_fast.input.case.Case.with_number`: the tables on the key's
path re-validated); the engine carries the solved state to each side, on
the mesh a solve of that side grades at the solution's boundaries, with its
regime held, by the linear response of the tangent at the solution, factored
once for every key (:func:`pipelay_fast.engine.sensitivity.neighbour_solutions`,
the implicit function theorem); each side is post-processed as a solve is
(:func:`.results.build_profile`, :func:`.results.build_summary`) and a
column's derivative is the central difference (f(p + h) - f(p - h)) / 2h,
exact to O(h^2) with no re-solve from the first guess. NaN, with the
reason, where the column is not differentiable at p: a side's regime
differs (the mesh's node count, a contact or slip set, the tip's regime),
a peak sits on another node on either side, the two one-sided differences
disagree by more than :data:`KINK`, the column depends on the functional
load case's second solve, or the answer followed the current's path with
seabed friction (3D).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ..engine.model import dimension_of
from ..engine.problem import guess_sizes
from ..engine.sensitivity import base_solution, mirrored_sizes, neighbour_solutions
from ..input.validate import get_path, number_at
from .design import bend_regions
from .results import SUMMARY_UNITS, build_profile, build_rollers, build_summary

# the key's relative step h / |p| (an absolute step of STEP in the key's SI
# unit where p = 0), from the step-size study of benchmarks/bench_sensitivity.py
# (S67 2D, four keys, against full solves): the largest relative difference
# 5.9e-4 at 1e-2, 1e-5 at 1e-3 (the O(h^2) error), 3.9e-6 at 1e-4, 4.3e-5 at
# 1e-5 and 6.5e-4 at 1e-6 (the sides' noise, 1e-12 of a value, over h)
STEP = 1e-4
# the one-sided differences (f(p + h) - f(p)) / h and (f(p) - f(p - h)) / h
# of a smooth column differ by h f'' and by the linear sides' second-order
# term (the nodes that follow a boundary keep their values; a relative 1e-4
# at STEP, but 0.11 on S67 2D's tip clearance by a, which is then NaN though
# its central difference is within 2e-6 of full solves'); by more than
# this share of the larger, the column has a kink or a jump within +-h
KINK = 0.1

# the columns that read the functional load case (a second solve, not differentiated)
FUNCTIONAL_COLUMNS = ("sagbend_lcc_utilisation", "sagbend_lcc_axial_ratio", "max_utilisation")
# the summary columns whose value is the profile's largest at one node:
# (profile column, region), the peak's arc length a row "s_<column>"
PEAKS = {
    "max_von_mises": ("von_mises", None), "overbend_max_von_mises": ("von_mises", "hog"),
    "sagbend_max_von_mises": ("von_mises", "sag"), "overbend_max_moment": ("moment", "hog"),
    "sagbend_max_moment": ("moment", "sag"), "max_lateral_deflection": ("y", None),
}
SKIPPED = ("solve_seconds",)


def summary_rows() -> dict:
    """The rows of a sensitivity table and their units: the numeric summary
    columns with a unit, then ``s_<peak>`` [m] for each of :data:`PEAKS`."""
    rows = {name: unit for name, unit in SUMMARY_UNITS.items() if unit and name not in SKIPPED}
    rows.update({f"s_{name}": "m" for name in PEAKS})
    return rows


def _side(case, sol, functional):
    """(summary with the peaks' arc lengths, peak nodes) of one side."""
    cols = build_profile(case, sol)
    summary = build_summary(case, sol, cols, build_rollers(case, sol), functional,
                            identify=False)
    hog, sag = bend_regions(cols, sol.s_tdp, sol.s_liftoff, case.lay.stinger is not None)
    if hog is None:  # J-lay: the sagbend is the span above touchdown
        hog, sag = np.zeros(sol.s.size, dtype=bool), sol.s >= sol.s_tdp
    nodes = {}
    for name, (column, region) in PEAKS.items():
        mask = {None: np.ones(sol.s.size, dtype=bool), "hog": hog, "sag": sag}[region]
        values = np.abs(cols[column])
        k = int(np.flatnonzero(mask)[np.argmax(values[mask])]) if mask.any() else -1
        nodes[name] = k
        summary[f"s_{name}"] = float(sol.s[k]) if k >= 0 else math.nan
    return summary, nodes


def _key_value(tables: dict, key: str) -> float:
    """The value of ``key`` in a case's ``tables`` (its ``to_dict()``)."""
    value = number_at(tables, key)
    if value is None:
        raise ValueError(f"sensitivities: {key!r} is not a numeric key the case gives "
                         f"(its value: {get_path(tables, key)!r})")
    return value


def sensitivity_table(case, state, keys, functional=None) -> pd.DataFrame:
    """The derivatives of the summary of ``case`` solved to ``state`` (its
    :class:`pipelay_fast.engine.state.Problem`) with respect
    to each of ``keys`` (dotted case keys with numeric values).

    Returns a DataFrame, one row per :func:`summary_rows` row, one float
    column per key (d row / d key, in the row's SI unit per the key's:
    ``unit`` and ``attrs["key_units"]``), and ``reason``: why a NaN is NaN
    ("key: reason"; "" where every key's derivative is a number).
    ``attrs["steps"]``: each key's step h.

    Every row is NaN, with the reason, where the solution itself does not
    refine on its mesh (:func:`pipelay_fast.engine.sensitivity.base_solution`:
    3D with friction under a current). Raises ValueError for a key that is
    not numeric in the case.
    """
    rows = summary_rows()
    sizes = guess_sizes(case)
    base, _solution, error = base_solution(case, state, sizes)
    table = {key: np.full(len(rows), math.nan) for key in keys}
    reasons = {name: [] for name in rows}
    steps, moved, why = _moved_cases(case, keys, error)
    pairs = [key for key in keys if not why[key]]
    # the case itself first: its state by the same linear map as its
    # neighbours' (the solution's residual at the tolerance answered as
    # theirs is), so that the one-sided differences compare like with like
    cases, guessed = [case], [sizes]
    for key in pairs:
        plus = guess_sizes(moved[key][0])
        cases += moved[key]
        guessed += [plus, mirrored_sizes(sizes, plus)]
    answers = iter(neighbour_solutions(cases, base, guessed) if base is not None else ())
    solution, why_0 = next(answers, (None, error))
    if solution is not None:
        f0, nodes0 = _side(case, solution, functional)
    elif why_0 != error:
        for key in pairs:
            why[key] = f"the solution itself: {why_0}"
        pairs = []
    for key in pairs:
        (sol_p, why_p), (sol_m, why_m) = next(answers), next(answers)
        why[key] = why_p or why_m
        if why[key]:
            continue
        (fp, nodes_p), (fm, nodes_m) = (_side(c, sol, functional)
                                        for c, sol in zip(moved[key], (sol_p, sol_m),
                                                          strict=True))
        for i, name in enumerate(rows):
            text = _not_differentiable(name, f0, fp, fm, nodes0, nodes_p, nodes_m,
                                       steps[key], functional, case.solver.tolerance)
            if text:
                reasons[name].append(f"{key}: {text}")
            else:
                table[key][i] = (fp[name] - fm[name]) / (2.0 * steps[key])
    for key in keys:
        if why[key]:
            for name in rows:
                reasons[name].append(f"{key}: {why[key]}")
    frame = pd.DataFrame(table, index=list(rows))
    frame["unit"] = list(rows.values())
    frame["reason"] = ["; ".join(reasons[name]) for name in rows]
    # the registry is imported here, not with the package, so that its
    # generator runs as ``python -m pipelay_fast.input.keys`` without a
    # second copy of the module
    from ..input.keys import number_units
    frame.attrs["key_units"] = {key: number_units().get(key, "") for key in keys}
    frame.attrs["steps"] = steps
    return frame


def _moved_cases(case, keys, error: str):
    """Each key's step h, its cases at p + h and p - h, and why it has no
    sensitivities ("" where it has: ``error``, the solution's, else the
    step leaves the key's range or changes the model's dimension)."""
    tables = case.to_dict()
    steps, moved, why = {}, {}, {}
    for key in keys:
        p = _key_value(tables, key)
        h = STEP * abs(p) if p != 0.0 else STEP
        steps[key], moved[key], why[key] = h, [], error
        for sign in (1.0, -1.0) if not error else ():
            try:
                moved[key].append(case.with_number(key, p + sign * h))
            except ValueError as err:
                why[key] = f"p {'+-'[sign < 0]} h outside the key's range ({err})"
                break
            if dimension_of(moved[key][-1]) != dimension_of(case):
                why[key] = "the step changes the model's dimension"
                break
    return steps, moved, why


def _not_differentiable(name, f0, fp, fm, nodes0, nodes_p, nodes_m, h, functional,
                        tolerance) -> str:
    """Why row ``name`` has no derivative from the sides ``fp``, ``fm``
    around ``f0`` (their peak nodes ``nodes_*``); "" where it has one. A
    side's change of a column below ``tolerance`` (solver.tolerance, to
    which the solution the sides are linearised about is solved) of its
    value is not resolved by the solve, nor one below STEP^2 of it by the
    linear sides (their second-order term, even in h, is of that order):
    no kink is sought in it."""
    if functional is not None and name in FUNCTIONAL_COLUMNS:
        return "reads the functional load case (a second solve, not differentiated)"
    values = (f0[name], fp[name], fm[name])
    if any(v is None or not math.isfinite(float(v)) for v in values):
        return "the column is not a finite number here"
    peak = name[2:] if name.startswith("s_") else name
    if peak in PEAKS and not nodes0[peak] == nodes_p[peak] == nodes_m[peak]:
        return (f"the peak jumps between nodes {nodes_m[peak]}, {nodes0[peak]} and "
                f"{nodes_p[peak]} within +-h")
    up, down = (values[1] - values[0]) / h, (values[0] - values[2]) / h
    steepest = max(abs(up), abs(down))
    resolved = max(tolerance, STEP**2) * abs(values[0])
    if abs(up - down) > KINK * steepest and steepest * h > resolved:
        return f"one-sided differences {down:.6g} and {up:.6g} disagree (a kink within +-h)"
    return ""

"""Sensitivities in a sweep and ``select`` refining with them (issue 43,
part 3 and target 3).

A small sweep of the paper's S67 (2D, 1 m/s along the lay) over a = -0.0018,
-0.0017 (around the 0.2 m tip clearance) and -0.0013, -0.0012 (around the
equal peaks) with ``sensitivities = ["lay.stinger.a"]``: the summary's
derivative columns against central differences of full solves, and the
equal-peaks ``a`` and the tip clearance's boundary found from them against
roots of direct cold solves (brentq to 1e-10 in ``a``, independent of
``select``), in fewer solves than ``select``'s refinement by solves alone.
The Hermite root and its Newton correction are checked on closed forms.
"""

from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

import pipelay_fast as pf
from pipelay_fast.output import sensitivity as S
from pipelay_fast.output.io import read_units
from pipelay_fast.study.dataset import read_summary
from pipelay_fast.study.runner import run_sweep
from pipelay_fast.study.select import select
from pipelay_fast.study.sensitivity import hermite_newton, hermite_root
from pipelay_fast.study.sweep_file import load_sweep
from tests.reference import solves

ROOT = Path(__file__).resolve().parents[1]
GRID = [-0.0018, -0.0017, -0.0013, -0.0012]  # 1/m
KEY = "lay.stinger.a"
LIMITS = {"min_tip_clearance": 0.2}  # m


def paper_s67(grid, **more) -> dict:
    """sweeps/paper.toml's S67 scene, 2D, over ``grid``, with ``more`` keys."""
    spec = tomllib.loads((ROOT / "sweeps" / "paper.toml").read_text())
    spec["scenes"] = [s for s in spec["scenes"] if s["name"] == "S67"]
    spec["vary"] = {"a": grid, "current_speed": [1.0], "current_heading": [0.0]}
    return {**spec, **more}


@pytest.fixture(scope="module")
def swept(tmp_path_factory):
    """(the results directory of the small sweep, its scene's base case)."""
    out = tmp_path_factory.mktemp("sens")
    sweep = load_sweep(paper_s67(GRID, sensitivities=[KEY]), base_dir=ROOT / "sweeps")
    run_sweep(sweep, out, workers=1, progress=False)
    return out, sweep.scenes[0].case


def direct_root(case, f, lo, hi) -> float:
    """The root of ``f`` (of a summary) in a between ``lo`` and ``hi`` by cold
    solves (:func:`tests.reference.solves.direct_root`)."""
    return solves.direct_root(case, KEY, f, lo, hi, 1e-10)[0]


def gap(summary) -> float:
    return summary["overbend_max_von_mises"] - summary["sagbend_max_von_mises"]


def test_the_sweep_writes_the_derivatives_with_units(swept):
    """d_<column>__d_lay.stinger.a in <unit>/(1/m), agreeing with a central
    difference of full solves (h = 1e-7 in a, a relative 1e-4) at a grid
    point to 1e-4 (the difference's own error: h^2 f''' / 6 and the solves'
    round-off / h)."""
    out, case = swept
    grid = read_summary(out).sort_values("a")
    units = read_units(next((out / "summary").glob("scene=S67/*.parquet")))
    assert units[f"d_overbend_max_von_mises__d_{KEY}"] == "Pa/(1/m)"
    assert units[f"d_tip_clearance__d_{KEY}"] == "m/(1/m)"
    assert units[f"d_max_von_mises_over_smys__d_{KEY}"] == "1/(1/m)"
    assert units["sensitivity_reasons"] == ""
    row = grid[grid["a"] == -0.0013].iloc[0]
    h = 1e-7
    up, down = (pf.solve(case.with_changes({KEY: -0.0013 + s * h})).summary for s in (1, -1))
    for column in ("overbend_max_von_mises", "sagbend_max_von_mises", "bottom_tension"):
        central = (up[column] - down[column]) / (2 * h)
        assert row[f"d_{column}__d_{KEY}"] == pytest.approx(central, rel=1e-4), column
    # the top tension is the case's (580 kN): its derivative is 0 but for
    # the central difference's O(h^2) error, h = S.STEP |a|: each side's top
    # tension is held by the linearised equation alone, so the sides miss it
    # by the tension's curvature times the step squared, a relative
    # STEP^2 of the tension per relative change of a (10 of them allowed)
    a = -0.0013
    assert abs(row[f"d_top_tension__d_{KEY}"]) < 10 * S.STEP**2 * 580e3 / abs(a)
    # the quadratic stinger has no radius: NaN, with the reason
    assert math.isnan(row[f"d_stinger_radius__d_{KEY}"])
    assert "stinger_radius" in row["sensitivity_reasons"]


def test_select_finds_the_equal_peaks_and_the_boundary_by_newton(swept):
    """The equal-peaks a and the tip clearance's end of the feasible range
    within 1e-7 of the direct roots, in fewer solves than brentq on solves
    (which agrees with them too); without refinement, the Hermite root of
    the grid's values and slopes, within 1e-7 too (the gap is nearly linear
    here: its second difference over the bracket is some 1e-3 of its change,
    and the solves' answers jump by a few kPa between meshes)."""
    out, case = swept
    equal = direct_root(case, gap, -0.0013, -0.0012)
    clearance = direct_root(case, lambda s: s["tip_clearance"] - 0.2, -0.0018, -0.0017)
    (newton,) = select(out, write=False, limits=LIMITS).itertuples()
    (solves,) = select(out, write=False, limits=LIMITS, sensitivities=False).itertuples()
    assert abs(newton.a_equal_peaks - equal) <= 1e-7
    assert abs(solves.a_equal_peaks - equal) <= 1e-7
    assert newton.feasible_max_binds == "tip_clearance >= 0.2 m"
    assert abs(newton.a_feasible_max - clearance) <= 1e-7
    assert abs(solves.a_feasible_max - clearance) <= 1e-7
    assert 1 <= newton.n_solves_equal_peaks < solves.n_solves_equal_peaks
    assert newton.n_solves < solves.n_solves
    assert "equal peaks by Newton on the sensitivities" in newton.note
    assert "feasible high end by Newton on the sensitivities" in newton.note

    (rough,) = select(out, refine=False, write=False, limits=LIMITS).itertuples()
    assert rough.n_solves == 0
    assert abs(rough.a_equal_peaks - equal) <= 1e-7
    assert "Hermite interpolation, not confirmed by a solve" in rough.note


def test_a_results_directory_keeps_its_sensitivities(swept):
    """A sweep without the directory's sensitivities (or with others) is
    refused before anything is solved: rows with and without them never mix."""
    out, _ = swept
    before = json.loads((out / "sweep.json").read_text())
    plain = load_sweep(paper_s67(GRID), base_dir=ROOT / "sweeps")
    with pytest.raises(ValueError, match="holds results with sensitivities"):
        run_sweep(plain, out, workers=1, progress=False)
    assert json.loads((out / "sweep.json").read_text()) == before
    assert before["sensitivities"] == [KEY]
    assert before["scenes"][0]["sensitivities"] == [KEY]


@pytest.mark.parametrize("value, message", [
    ("lay.stinger.a", "must be a list of dotted case keys"),
    (["lay.stinger.b"], r"sensitivities\[0\].*not a numeric case key"),
    (["lay.stinger.radius"], r"sensitivities\[0\].*not given as a number by any scene"),
    ([KEY, KEY], "repeats the key"),
])
def test_a_sensitivities_list_is_checked_naming_the_key(value, message):
    with pytest.raises(ValueError, match=message):
        load_sweep(paper_s67([-0.0012], sensitivities=value), base_dir=ROOT / "sweeps")


def test_sensitivities_and_a_target_are_refused_together():
    target = {"tip_clearance": 0.3, "vary": "lay.top_tension", "bounds": [400e3, 900e3]}
    with pytest.raises(ValueError, match="target.*cannot be combined with sensitivities"):
        load_sweep(paper_s67([-0.0012], sensitivities=[KEY], target=target),
                   base_dir=ROOT / "sweeps")


def test_hermite_root_is_exact_for_a_cubic():
    """A cubic is its own Hermite interpolant: (x - 0.3)(x^2 + 1) on [0, 1]."""
    f = np.polynomial.Polynomial.fromroots([0.3]) * np.polynomial.Polynomial([1.0, 0.0, 1.0])
    d = f.deriv()
    root, slope = hermite_root(0.0, 1.0, f(0.0), f(1.0), d(0.0), d(1.0))
    assert root == pytest.approx(0.3, abs=1e-14)
    assert slope == pytest.approx(d(0.3), rel=1e-12)


def test_hermite_newton_confirms_and_corrects():
    """exp(x) - 2 between 0.6 and 0.8 (root ln 2): the Hermite root misses
    by 4e-6, the Newton step from the solved trial brings the next within
    1e-10, whose step then stops the search: two evaluations, against
    brentq's seven to the same tolerance (with the two ends given)."""
    calls = []

    def f(x):
        calls.append(x)
        return math.exp(x) - 2.0

    bracket = {x: (math.exp(x) - 2.0, math.exp(x)) for x in (0.6, 0.8)}
    root, n = hermite_newton(f, bracket, 1e-10)
    assert abs(root - math.log(2.0)) <= 1e-10
    assert n == len(calls) == 2
    assert 1e-6 < abs(calls[0] - math.log(2.0)) < 1e-5  # (the first trial alone misses)
    _, brent = brentq(lambda x: math.exp(x) - 2.0, 0.6, 0.8, xtol=1e-10, full_output=True)
    assert brent.function_calls - 2 > n


def test_the_reasons_name_each_reason_once_with_its_rows():
    """A reason holding "; " stays whole; a key the scene's case lacks is said."""
    import pandas as pd

    from pipelay_fast.study.sensitivity import sensitivity_values

    why = f"{KEY}: 3D with friction; the slip set changes"
    table = pd.DataFrame({KEY: [math.nan, math.nan, 2.0], "unit": ["Pa", "m", "m"],
                          "reason": [why, why, ""]}, index=["p", "q", "r"])
    values = sensitivity_values(table, [KEY], [KEY, "lay.top_tension"])
    assert values[f"d_r__d_{KEY}"] == 2.0
    assert values["sensitivity_reasons"] == (
        f"{why} [p, q]; lay.top_tension: not a number in the scene's case")
    assert sensitivity_values(None, (), [KEY]) == {
        "sensitivity_reasons": f"{KEY}: not a number in the scene's case"}

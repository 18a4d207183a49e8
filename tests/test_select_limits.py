"""Limits in ``select`` and the summary's flags.

The feasible range is checked on a results directory built here by hand,
whose columns are linear in ``a`` (the range's ends and the limit binding
at each are then known in closed form and the interpolation is exact), and
on the paper's S67 scene against a root of ``tip_clearance - 0.2`` found by
direct solves. The flags are checked on cases built just either side of
each threshold.
"""

from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy.optimize import brentq

import pipelay_fast as pf
from pipelay_fast.cli import main
from pipelay_fast.output.io import read_units
from pipelay_fast.study.dataset import read_summary
from pipelay_fast.study.limits import Limit, check_limits, feasible_ranges
from pipelay_fast.study.runner import run_sweep
from pipelay_fast.study.select import select
from pipelay_fast.study.sweep_file import load_sweep
from tests.helpers import EXAMPLES

ROOT = Path(__file__).resolve().parents[1]
GRID = np.round(np.arange(-0.0021, -0.00085, 1e-4), 10)  # 1/m, 13 values


def linear_rows(a: np.ndarray) -> pd.DataFrame:
    """Summary rows of one S-lay scene whose answers are linear in c = -a:
    tip clearance 1000 c - 1 [m], utilisation 0.2 + 300 c, overbend strain
    0.5 c, top tension 5e5 + 1e8 c [N], overbend peak 100 + 5e4 c [MPa] and
    sagbend peak 190 - 2e4 c [MPa] (equal at c = 90/7e4), yielded above
    192 MPa (c > 0.00184: the three grid points of largest c)."""
    c = -a
    over, sag = 100e6 + 5e10 * c, 190e6 - 2e10 * c
    return pd.DataFrame({
        "case_id": [f"c{i}" for i in range(a.size)], "method": "S", "dimension": "2d",
        "a": a, "stinger_radius": math.nan, "roller_shift": math.nan, "water_depth": 67.0,
        "current_speed": 1.0, "current_heading_deg": 0.0, "status": "ok", "message": "",
        "given_top_tension": math.nan, "given_bottom_tension": math.nan,
        "given_pipe_length": math.nan, "chain": "k", "chain_position": np.arange(a.size),
        "tip_clearance": 1000.0 * c - 1.0, "max_utilisation": 0.2 + 300.0 * c,
        "overbend_max_strain": 0.5 * c, "sagbend_max_strain": 0.0004 + 0.0 * c,
        "top_tension": 5e5 + 1e8 * c, "max_roller_reaction": math.nan,
        "overbend_max_von_mises": over, "sagbend_max_von_mises": sag,
        "max_von_mises": np.maximum(over, sag), "max_von_mises_over_smys": np.maximum(over, sag)
        / 192e6, "yielded": np.maximum(over, sag) > 192e6, "bears_on_tip": 1000.0 * c - 1.0 <= 0.0,
    })


def results_dir(root: Path, select_table: dict | None = None) -> Path:
    """A results directory holding the linear rows (scene S) and a sweep.json."""
    folder = root / "summary" / "scene=S"
    folder.mkdir(parents=True)
    linear_rows(GRID).to_parquet(folder / "chunk-0.parquet")
    spec = {"name": "linear", "scenes": [], **({"select": select_table} if select_table else {})}
    (root / "sweep.json").write_text(json.dumps(spec))
    return root


def test_the_feasible_range_of_linear_answers_is_exact(tmp_path):
    """tip_clearance >= 0.25 m holds for c >= 0.00125, utilisation <= 0.8 for
    c <= 0.002: a in [-0.002, -0.00125], each end bound by its limit; the
    least utilisation inside is at the clearance end, 0.2 + 300 * 0.00125."""
    root = results_dir(tmp_path, {"min_tip_clearance": 0.25, "max_utilisation": 0.8})
    (row,) = select(root, refine=False).itertuples()
    assert row.feasible and row.limits == "tip_clearance >= 0.25 m; max_utilisation <= 0.8"
    assert row.a_feasible_min == pytest.approx(-0.002, abs=1e-15)
    assert row.a_feasible_max == pytest.approx(-0.00125, abs=1e-15)
    assert (row.feasible_min_binds, row.feasible_max_binds) == (
        "max_utilisation <= 0.8", "tip_clearance >= 0.25 m")
    assert row.best_objective == "max_utilisation"
    assert row.a_best == pytest.approx(-0.00125, abs=1e-15)
    assert row.best_max_utilisation == pytest.approx(0.2 + 300.0 * 0.00125, rel=1e-12)
    # the peaks cross at c = 90/7e4 = 0.0012857; refine=False keeps the nearest grid point
    assert row.a_equal_peaks == pytest.approx(-0.0013) and row.equal_peaks_feasible
    assert row.n_yielded == 3 and not row.equal_peaks_yielded
    assert row.equal_peaks_max_von_mises_over_smys == pytest.approx(165e6 / 192e6, rel=1e-12)
    units = read_units(root / "selection.parquet")
    assert (units["a_feasible_min"], units["best_max_von_mises"]) == ("1/m", "Pa")


def test_a_further_limit_moves_the_end_it_binds(tmp_path):
    """overbend strain 0.5 c <= 0.00095: c <= 0.0019 binds before the
    utilisation's 0.002; a top tension window [6e5, 7.1e5] N (c in [0.001,
    0.0021]) binds at neither end."""
    root = results_dir(tmp_path)
    (row,) = select(root, refine=False, write=False, limits={
        "min_tip_clearance": 0.25, "max_utilisation": 0.8, "max_overbend_strain": 0.00095,
        "top_tension": [6e5, 7.1e5]}).itertuples()
    assert row.a_feasible_min == pytest.approx(-0.0019, abs=1e-15)
    assert row.feasible_min_binds == "overbend_max_strain <= 0.00095"
    assert row.a_feasible_max == pytest.approx(-0.00125, abs=1e-15)
    # without the clearance, the tension window's least value binds at c = 0.001
    (row,) = select(root, refine=False, write=False, limits={
        "top_tension": [6e5, 7.1e5], "max_utilisation": 0.8}).itertuples()
    assert row.a_feasible_max == pytest.approx(-0.001, abs=1e-15)
    assert row.feasible_max_binds == "top_tension >= 600 kN"
    assert row.feasible_min_binds == "max_utilisation <= 0.8"


def test_an_infeasible_scene_says_which_limit_and_by_how_much(tmp_path):
    """The clearance reaches 1000 * 0.0021 - 1 = 1.1 m at most: a 2 m limit
    is 0.9 m short. Clearance >= 0.25 (c >= 0.00125) and utilisation <= 0.5
    (c <= 0.001) each hold somewhere but never together."""
    root = results_dir(tmp_path)
    (row,) = select(root, refine=False, write=False,
                    limits={"min_tip_clearance": 2.0}).itertuples()
    assert not row.feasible and math.isnan(row.a_feasible_min)
    assert row.ruled_out_by == ("ruled out by tip_clearance >= 2 m: short by 0.9 m at best "
                                "(a = -0.0021)")
    (row,) = select(root, refine=False, write=False,
                    limits={"min_tip_clearance": 0.25, "max_utilisation": 0.5}).itertuples()
    assert row.ruled_out_by == (
        "the limits conflict: tip_clearance >= 0.25 m holds for a in [-0.0021, -0.00125]; "
        "max_utilisation <= 0.5 holds for a in [-0.001, -0.0009]; at best (a = -0.0013) "
        "max_utilisation <= 0.5 short by 0.09")


def test_the_default_utilisation_limit_applies_where_there_are_checks(tmp_path):
    """Without limits, utilisation <= 1 (c <= 0.0008/0.3... beyond the grid,
    so the whole grid); with utilisation NaN (no [checks]) no limit applies
    and the least von Mises stress is the objective."""
    root = results_dir(tmp_path)
    (row,) = select(root, refine=False, write=False).itertuples()
    assert row.limits == "max_utilisation <= 1"
    assert (row.a_feasible_min, row.a_feasible_max) == (GRID[0], GRID[-1])
    assert row.feasible_min_binds == row.feasible_max_binds == "grid end"
    frame = pd.read_parquet(root / "summary" / "scene=S" / "chunk-0.parquet")
    frame["max_utilisation"] = math.nan
    frame.to_parquet(root / "summary" / "scene=S" / "chunk-0.parquet")
    (row,) = select(root, refine=False, write=False).itertuples()
    assert row.limits == "none" and row.best_objective == "max_von_mises"
    # max(over, sag) is least where they cross, c = 90/7e4, between grid points:
    # the grid's best is the nearer grid point, c = 0.0013
    assert row.a_best == pytest.approx(-0.0013)


def test_feasible_ranges_of_a_dip_are_two():
    """A margin 1 - |x| / 2 ... negative around 0 between +-0.5: two ranges, each
    bound at its inner end."""
    x = np.linspace(-2.0, 2.0, 9)
    limit = Limit("c", "min", 0.5, "-")
    ranges = feasible_ranges(x, {limit: limit.margin(np.abs(x))})
    assert [(r.low, r.high) for r in ranges] == [(-2.0, -0.5), (0.5, 2.0)]
    assert (ranges[0].high_binds, ranges[1].low_binds) == (limit, limit)
    assert ranges[0].low_binds is None


def test_select_limits_from_the_command_line_replace_the_files(tmp_path, capsys):
    root = results_dir(tmp_path, {"min_tip_clearance": 0.5, "max_utilisation": 0.8})
    assert main(["select", str(root), "--no-refine", "--min-tip-clearance", "0.25"]) == 0
    printed = capsys.readouterr().out
    assert "limits: tip_clearance >= 0.25 m; max_utilisation <= 0.8" in printed
    line = next(ln for ln in printed.splitlines() if ln.startswith("S ") and "-0.001250" in ln)
    assert "-0.002000" in line and "max_utilisation <= 0.8 | tip_clearance >= 0.25 m" in line
    assert "legend:" in printed and "[MPa]" in printed
    assert main(["select", str(root), "--no-refine", "--top-tension", "7e5", "6e5"]) == 2
    assert "limits.top_tension = [700000.0, 600000.0] must have 0 <= min < max" in \
        capsys.readouterr().err


@pytest.mark.parametrize("table, message", [
    ({"min_tip_clearence": 0.2}, "unknown key select.min_tip_clearence (did you mean "
                                 "select.min_tip_clearance?)"),
    ({"max_utilisation": "1"}, "select.max_utilisation = '1' must be a finite number"),
    ({"max_sagbend_strain": 0.0}, "select.max_sagbend_strain = 0.0 must be > 0 (-)"),
    ({"min_tip_clearance": -0.1}, "select.min_tip_clearance = -0.1 must be >= 0 (m)"),
    ({"top_tension": 5e5}, "select.top_tension = 500000.0 must be a list [min, max]"),
])
def test_a_select_table_is_checked_naming_the_key(table, message):
    with pytest.raises(ValueError, match=None) as caught:
        load_sweep({"case": "s67", "select": table})
    assert message in str(caught.value)
    assert check_limits("select", {"top_tension": [1.0, 2.0]}) == {"top_tension": (1.0, 2.0)}


# --------------------------------------------------------------------------- the paper's S67


def test_the_tip_clearance_end_on_the_paper_s67_matches_direct_solves(tmp_path):
    """S67 of sweeps/paper.toml (2D) on three of its grid points, a = -0.0019,
    -0.0018, -0.0017: with tip_clearance >= 0.2 m the range's upper end is
    where the clearance, linear between -0.0018 and -0.0017, crosses 0.2.
    The root of tip_clearance - 0.2 by direct solves (brentq to 1e-9 in a)
    lies within the interpolation's error of it, h^2 |f''| / (8 |f'|) with
    f'' the grid's second difference and f' the secant, doubled (f'' is not
    constant); refined by solves, within the root search's tolerance."""
    spec = tomllib.loads((ROOT / "sweeps" / "paper.toml").read_text())
    spec["scenes"] = [s for s in spec["scenes"] if s["name"] == "S67"]
    spec["vary"] = {"a": [-0.0019, -0.0018, -0.0017], "current_speed": [1.0],
                    "current_heading": [0.0]}
    sweep = load_sweep(spec, base_dir=ROOT / "sweeps")
    run_sweep(sweep, tmp_path, workers=1, progress=False)
    (row,) = select(tmp_path, refine=False, write=False,
                    limits={"min_tip_clearance": 0.2}).itertuples()
    assert row.feasible_max_binds == "tip_clearance >= 0.2 m"
    assert (row.a_feasible_min, row.feasible_min_binds) == (-0.0019, "grid end")

    grid = read_summary(tmp_path).sort_values("a")
    a, f = grid["a"].to_numpy(), grid["tip_clearance"].to_numpy()
    h = 1e-4
    curvature = abs(f[0] - 2.0 * f[1] + f[2]) / h**2
    slope = abs(f[2] - f[1]) / h
    error = 2.0 * h**2 * curvature / (8.0 * slope)
    base = sweep.scenes[0].case

    def clearance(x):
        return pf.solve(base.with_changes({"lay.stinger.a": x})).summary["tip_clearance"] - 0.2

    root = brentq(clearance, a[1], a[2], xtol=1e-9)
    assert abs(row.a_feasible_max - root) <= error
    assert 1e-7 < error < 1e-5  # (the error stated: a few 1e-6 in a on a 1e-4 grid)
    # refined by solves (brentq to 1e-4 of the grid step, 1e-8 in a, warm-started)
    (row,) = select(tmp_path, write=False, limits={"min_tip_clearance": 0.2}).itertuples()
    assert abs(row.a_feasible_max - root) <= 2e-8
    assert row.a_best == row.a_feasible_max  # utilisation rises with |a|: least at the end
    assert row.best_max_utilisation == pytest.approx(
        pf.solve(base.with_changes({"lay.stinger.a": row.a_best})).summary["max_utilisation"],
        rel=1e-6)


# --------------------------------------------------------------------------- flags


@pytest.fixture(scope="module")
def s67():
    return pf.load_case(EXAMPLES / "s67.toml").with_changes({"solver.element_length": 8.0})


def test_yielded_just_either_side_of_smys(s67):
    """SMYS a hair (1e-6 relative) below the profile's own largest von Mises
    stress: yielded; a hair above: not. SMYS does not change the answer."""
    peak = float(pf.solve(s67).profile["von_mises"].max())
    for factor, yielded in ((1.0 - 1e-6, True), (1.0 + 1e-6, False)):
        summary = pf.solve(s67.with_changes({"pipe.smys": peak * factor})).summary
        assert summary["yielded"] is yielded
        assert summary["max_von_mises_over_smys"] == pytest.approx(1.0 / factor, rel=1e-12)


def test_bears_on_tip_just_either_side_of_the_switch(s67):
    """The pipe leaves the stinger at its tip for a = -0.0011 and above it for
    -0.0012; bisected to 1e-9 in a, the two sides differ: bearing, a node of
    the profile sits on the tip point (to round-off) with the tip's
    reaction > 0; clear, no node is within a micrometre of it and the tip
    carries nothing."""
    x_tip, z_tip = s67.lay.stinger.lower

    def solve(a):
        return pf.solve(s67.with_changes({"lay.stinger.a": a}))

    lo, hi = -0.0012, -0.0011
    assert not solve(lo).summary["bears_on_tip"] and solve(hi).summary["bears_on_tip"]
    while hi - lo > 1e-9:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if not solve(mid).summary["bears_on_tip"] else (lo, mid)
    for a, bears in ((lo, False), (hi, True)):
        result = solve(a)
        p = result.profile
        nearest = float(np.hypot(p["x"] - x_tip, p["z"] - z_tip).min())
        assert result.summary["bears_on_tip"] is bears
        if bears:
            assert nearest < 1e-9 and result.summary["tip_reaction"] > 0.0
        else:
            assert nearest > 1e-6 and result.summary["tip_reaction"] == 0.0


def test_solve_prints_the_flags(tmp_path, capsys):
    case = tmp_path / "case.toml"
    text = (EXAMPLES / "s67.toml").read_text().replace("a = -0.0012", "a = -0.0011")
    case.write_text(text)
    assert main(["solve", str(case)]) == 0
    printed = capsys.readouterr().out
    assert "\nflags: BEARS ON THE STINGER TIP (tip reaction" in printed
    assert re_value(printed, "bears_on_tip") == "True"


def re_value(printed: str, name: str) -> str:
    line = next(ln for ln in printed.splitlines() if ln.split()[:1] == [name])
    return line.split()[1]


def test_a_failed_rows_flags_are_missing_in_the_dataset(tmp_path):
    """A sweep's summary keeps the flags as nullable booleans: true and false
    as solved, missing (not false) on a failed row, through Parquet too."""
    import pyarrow.parquet as pq

    from pipelay_fast.study.dataset import summary_frame, summary_table

    rows = [{"status": "ok", "yielded": True, "bears_on_tip": False},
            {"status": "failed", "yielded": None}]
    frame = summary_frame(rows)
    assert str(frame["yielded"].dtype) == "boolean"
    assert frame["yielded"].tolist()[0] is True and frame["bears_on_tip"].tolist()[0] is False
    assert frame["yielded"].isna().tolist() == [False, True]
    assert frame["bears_on_tip"].isna().tolist() == [False, True]
    pq.write_table(summary_table(rows), tmp_path / "chunk.parquet")
    back = pd.read_parquet(tmp_path / "chunk.parquet")
    assert str(back["yielded"].dtype) == "boolean" and back["yielded"].isna().tolist() == [
        False, True]

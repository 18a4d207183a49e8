"""The lay table: sweeps/lay_table.toml and ``pipelay-fast table``."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from pipelay_fast.cli import main
from pipelay_fast.study.dataset import read_summary
from pipelay_fast.study.laytable import format_lay_table, lay_table
from pipelay_fast.study.runner import run_sweep
from pipelay_fast.study.sweep import Sweep
from pipelay_fast.study.sweep_file import load_sweep

LAY_TABLE = Path(__file__).resolve().parents[1] / "sweeps" / "lay_table.toml"


@pytest.fixture(scope="module")
def sweep():
    return load_sweep(LAY_TABLE)


def test_lay_table_file_covers_both_depth_ranges(sweep):
    """S-lay 30 to 300 m with the S67 stinger kept at the vessel (its ends at
    fixed heights below the surface), J-lay 100 to 2000 m with the hang-off 5 m
    above the surface; every case solved for a target top tension."""
    depths = {"S": [], "J": []}
    for c in sweep.cases():
        d = c.case.environment.water_depth
        assert c.source.target is not None and c.source.target["vary"] == "lay.top_tension"
        depths[c.case.lay.method].append(d)
        if c.case.lay.method == "S":
            st = c.case.lay.stinger
            assert (st.lower, st.upper, st.a) == ((d - 25.5, 265.0), (d + 5.0, 400.0), -0.0012)
        else:
            assert c.case.lay.top[0] == d + 5.0
    assert depths["S"] == [30.0 + 30.0 * i for i in range(10)]
    assert (min(depths["J"]), max(depths["J"])) == (100.0, 2000.0)


@pytest.fixture(scope="module")
def results(sweep, tmp_path_factory):
    """The lay table's shallowest and deepest cases of each method."""
    ends = {"S": (30.0, 300.0), "J": (100.0, 2000.0)}
    scenes = tuple(dataclasses.replace(s, axes={"depth": ends[s.name]}) for s in sweep.scenes)
    out = tmp_path_factory.mktemp("lay") / "out"
    run_sweep(Sweep("lay_ends", scenes), out, workers=1, progress=False)
    return out


def test_targets_are_met_at_the_ends_of_both_ranges(results):
    table = read_summary(results)
    assert (table["status"] == "ok").all(), table["message"].tolist()
    strain = table[table["method"] == "S"]["sagbend_max_strain"]
    assert strain.tolist() == pytest.approx([0.0012, 0.0012], rel=1e-6)
    lcc = table[table["method"] == "J"]["sagbend_lcc_utilisation"]
    assert lcc.tolist() == pytest.approx([0.8, 0.8], rel=1e-6)
    # deeper water needs more tension, for both methods
    by = table.set_index(["scene", "water_depth"])["top_tension"]
    assert by[("S", 300.0)] > by[("S", 30.0)] and by[("J", 2000.0)] > by[("J", 100.0)]


def test_lay_table_orders_and_prints_in_display_units(results, capsys):
    table = lay_table(results)
    assert table["scene"].tolist() == ["S", "S", "J", "J"]
    assert table["water_depth"].tolist() == [30.0, 300.0, 100.0, 2000.0]
    text = format_lay_table(table)
    lines = text.splitlines()
    assert lines[0].split()[:4] == ["scene", "lay", "depth", "m"]
    row = table.iloc[1]
    s300 = next(line for line in lines if line.split()[:4] == ["S", "S", "2d", "300.0"])
    for value in (f"{row['top_tension'] / 1e3:.1f}", f"{row['layback']:.1f}",
                  f"{row['tdp_tension'] / 1e3:.1f}", f"{row['departure_angle_deg']:.2f}",
                  f"{100 * row['sagbend_max_strain']:.3f}", f"{row['max_utilisation']:.3f}"):
        assert value in s300.split()
    j100 = next(line for line in lines if line.split()[:4] == ["J", "J", "2d", "100.0"])
    assert j100.split().count("n/a") == 4  # a, tip clearance, overbend strain and utilisation
    assert "  sagbend_max_strain = 0.0012 by lay.top_tension" in lines
    assert main(["table", str(results)]) == 0
    assert capsys.readouterr().out.strip() == text


def test_failed_rows_print_their_message(tmp_path):
    spec = {"name": "far", "set": {"solver.element_length": 8.0}, "scenes": [
        {"name": "S67", "case": "s67",
         "target": {"tip_clearance": 5.0, "vary": "lay.top_tension", "bounds": [6e5, 1.2e6]}}]}
    run_sweep(load_sweep(spec), tmp_path / "out", workers=1, progress=False)
    text = format_lay_table(lay_table(tmp_path / "out"))
    assert "failed: TargetError: target tip_clearance = 5.0 m is not reached" in text


def test_table_of_an_empty_directory_is_a_usage_error(tmp_path, capsys):
    assert main(["table", str(tmp_path)]) == 2
    assert "no summary table" in capsys.readouterr().err

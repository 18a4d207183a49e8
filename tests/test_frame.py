"""The vessel frame (``lay.frame``): the waterline frame gives the seabed
frame's bits, the depth axis moves only the seabed, and the bad inputs are
refused naming their key and value."""

from __future__ import annotations

import dataclasses
from decimal import Decimal
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

import pipelay_fast as pf
from pipelay_fast.input.frame import raised, vessel_note
from pipelay_fast.study.dataset import read_summary
from pipelay_fast.study.runner import run_sweep
from pipelay_fast.study.sweep import Sweep, target_bounds
from pipelay_fast.study.sweep_file import load_sweep
from tests.helpers import EXAMPLES, refused

SWEEPS = Path(__file__).resolve().parents[1] / "sweeps"


def waterline(name, lay):
    """The bundled example ``name`` with its lay table replaced by ``lay`` in
    the waterline frame."""
    tables = pf.load_case(EXAMPLES / f"{name}.toml").to_dict()
    tables["lay"] = {**{k: v for k, v in tables["lay"].items() if k not in ("top", "stinger")},
                     **lay, "frame": "waterline"}
    return pf.load_case(tables)


S67_WATERLINE = {"stinger": {"a": -0.0012, "lower": [-25.5, 265.0], "upper": [5.0, 400.0]}}
S125_WATERLINE = {"stinger": {"a": -0.0011, "lower": [-47.0, 305.0], "upper": [3.0, 440.0]}}


def same_bits(a, b):
    """Every profile column and summary value of two Results identical (the
    solve time aside, and the case id, a hash of the tables as written)."""
    assert a.columns.keys() == b.columns.keys()
    for key in a.columns:
        x, y = np.asarray(a.columns[key]), np.asarray(b.columns[key])
        assert np.array_equal(x, y, equal_nan=x.dtype.kind in "fc"), key
    for key, value in a.summary.items():
        if key not in ("solve_seconds", "case_id"):
            other = b.summary[key]
            assert value == other or (value != value and other != other), key


@pytest.mark.parametrize(("name", "lay"), [("s67", S67_WATERLINE), ("s125", S125_WATERLINE)])
def test_the_papers_scenes_in_the_waterline_frame_give_the_same_bits(name, lay):
    """S67 (tip 25.5 m below the water, upper end 5 m above) and S125 (47 m
    below, 3 m above): the seabed-frame lay equals the example's, and the
    solve gives the same bits."""
    seabed = pf.load_case(EXAMPLES / f"{name}.toml")
    case = waterline(name, lay)
    assert case.lay == seabed.lay and case.given_lay.frame == "waterline"
    assert case.given_lay.stinger.lower == tuple(lay["stinger"]["lower"])
    same_bits(pf.solve(case), pf.solve(seabed))


@pytest.mark.parametrize("name", ["s67_rollers", "s67_radius"])
def test_roller_stingers_written_as_decimal_elevations_give_the_same_bits(name):
    """S67 on its 23 rollers, and on rollers placed on a radius from the
    top, written as elevations (the heights less 67 m, in decimal): the
    seabed-frame lay is the example's, and the solve (through the roller
    guide's quadratic stinger) gives the same bits. The conversion adds
    decimals, where the float sum 67.0 + e misses some rollers by an ulp."""
    seabed = pf.load_case(EXAMPLES / f"{name}.toml")
    lay = seabed.to_dict()["lay"]
    lay["top"][0] = float(Decimal(repr(lay["top"][0])) - 67)
    given = lay["stinger"].get("rollers", [])
    for roller in given:
        roller[0] = float(Decimal(repr(roller[0])) - 67)
    case = waterline(name, {k: lay[k] for k in ("top", "top_angle", "stinger")})
    assert case.lay == seabed.lay
    if given:
        assert any(67.0 + e != x for (e, _), (x, _) in zip(given, seabed.lay.stinger.rollers,
                                                          strict=True))
    same_bits(pf.solve(case), pf.solve(seabed))


def test_the_conversion_is_the_correctly_rounded_decimal_sum():
    """raised(d, e) is the float nearest the exact sum of the decimals d and
    e (fractions), for depths and elevations of one and two decimals."""
    rng = np.random.default_rng(7)
    for _ in range(2000):
        d = f"{rng.integers(100, 30000) / 10:.1f}"
        e = f"{rng.integers(-9000, 2000) / 100:.2f}"
        assert raised(float(d), float(e)) == float(Fraction(d) + Fraction(e)), (d, e)
    assert raised(30.0, -25.3) == 4.7 != 30.0 + -25.3


def test_the_case_keeps_its_frame_through_its_tables():
    """to_dict writes the elevations as given; load_case reads them back to the
    same case; a seabed-frame case's tables have no frame key."""
    case = waterline("s67", S67_WATERLINE)
    tables = case.to_dict()
    assert tables["lay"]["frame"] == "waterline"
    assert tables["lay"]["stinger"]["lower"] == [-25.5, 265.0]
    assert pf.load_case(tables) == case
    assert "frame" not in pf.load_case(EXAMPLES / "s67.toml").to_dict()["lay"]
    assert case != pf.load_case(EXAMPLES / "s67.toml")  # equal lays, different tables


@pytest.mark.parametrize("depth", [30.0, 45.3, 150.0, 300.0])
def test_water_depth_moves_the_seabed_and_not_the_vessel(depth):
    case = waterline("s67", S67_WATERLINE).with_changes({"environment.water_depth": depth})
    st = case.lay.stinger
    assert st.lower == (float(Fraction(str(depth)) - Fraction("25.5")), 265.0)
    assert st.upper == case.lay.top == (float(Fraction(str(depth)) + 5), 400.0)
    assert st.a == -0.0012 and case.given_lay.stinger.lower == (-25.5, 265.0)


# --------------------------------------------------------------------------- bad input


def test_an_unknown_frame_is_refused():
    message = refused(pf.load_case(EXAMPLES / "s67.toml"), {"lay.frame": "sea"})
    assert message.startswith("lay.frame = 'sea' must be one of 'seabed', 'waterline'")


@pytest.mark.parametrize(("changes", "start"), [
    ({"environment.water_depth": 20.0}, "lay.stinger.lower = [-25.5, 265.0] is below the seabed"),
    ({"lay.stinger.lower": [-70.0, 265.0]},
     "lay.stinger.lower = [-70.0, 265.0] is below the seabed"),
])
def test_a_waterline_tip_below_the_seabed_is_refused(changes, start):
    message = refused(waterline("s67", S67_WATERLINE), changes)
    assert message.startswith(start) and "environment.water_depth" in message


def test_a_waterline_hang_off_below_the_seabed_is_refused():
    case = waterline("j125", {"top": [5.0, 440.0]})
    message = refused(case, {"lay.top": [-130.0, 440.0]})
    assert message.startswith("lay.top = [-130.0, 440.0] is not above the seabed")


def test_a_waterline_roller_below_the_seabed_is_refused():
    seabed = pf.load_case(EXAMPLES / "s67_rollers.toml")
    rollers = [[x - 67.0, z] for x, z in seabed.lay.stinger.rollers]
    case = waterline("s67_rollers", {"top": [5.0, 400.0], "top_angle": seabed.lay.top_angle,
                                     "stinger": {"rollers": rollers}})
    message = refused(case, {"environment.water_depth": 20.0})
    assert message.startswith(f"lay.stinger.rollers[22] = {rollers[-1]} is below the seabed")


def test_a_stinger_copied_into_shallower_water_is_noted_in_the_message():
    """The issue's case: the S67 stinger copied into 45 m of water stands
    72 - 45 = 27 m above it, its tip 45 - 41.5 = 3.5 m below. It solves, and
    the result's message says so, naming the key and its value; in its own
    depth the message is empty."""
    s67 = pf.load_case(EXAMPLES / "s67.toml")
    copied = pf.solve(s67.with_changes({"environment.water_depth": 45.0}))
    assert copied.summary["status"] == "ok"
    message = copied.summary["message"]
    assert message.startswith("lay.stinger.upper = [72.0, 400.0] stands 27 m above the still "
                              "water (lay.frame = 'seabed', environment.water_depth = 45.0 m)")
    assert "(lay.stinger.lower = [41.5, 265.0]) is only 3.5 m below it" in message
    assert pf.solve(s67).summary["message"] == ""


@pytest.mark.parametrize(("name", "changes", "start", "tip"), [
    ("s67", {"lay.stinger.upper": [30.0, 400.0]},
     "lay.stinger.upper = [30.0, 400.0] stands 30 m", "is only 25.5 m below it"),
    ("s67_rollers", {"environment.water_depth": 45.0},
     "lay.top = [72.0, 400.0] stands 27 m", "the last roller = [41.5, 265.0]) is only 3.5 m"),
])
def test_the_note_names_the_vessel_end_in_the_cases_frame(name, changes, start, tip):
    """The note's rule on the case's own geometry: the vessel end's height
    above the water against the tip's depth below it, in either frame; a
    roller stinger's vessel end is lay.top and its tip the last roller."""
    base = pf.load_case(EXAMPLES / f"{name}.toml")
    if name == "s67":
        base = waterline("s67", S67_WATERLINE)
    case = base.with_changes(changes)
    note = vessel_note(case.given_lay, case.lay, case.environment.water_depth)
    assert note.startswith(start) and tip in note
    assert vessel_note(base.given_lay, base.lay, base.environment.water_depth) == ""


def test_a_depth_axis_on_a_seabed_frame_case_is_refused():
    sweep = {"case": "s67", "vary": {"depth": [60.0, 90.0]}}
    with pytest.raises(ValueError, match=r"^vary\.depth = \[60\.0, 90\.0\] needs a vessel in "
                                         r"the waterline frame.*lay\.frame = 'seabed'"):
        load_sweep(sweep)
    scene = {"name": "A", "case": "s67", "vary": {"depth": [60.0]}}
    with pytest.raises(ValueError, match=r"^scenes\[0\]\.vary\.depth = \[60\.0\]"):
        load_sweep({"scenes": [scene]})


# --------------------------------------------------------------------------- depth sweeps


def hand_shifted(method, depth):
    """The lay table's case at ``depth`` [m] built in the seabed frame, its
    vessel heights shifted by hand, as sweeps/lay_table.toml wrote them
    before the waterline frame."""
    still = {"environment.current.speed": 0.0, "environment.water_depth": depth}
    if method == "S":
        return pf.load_case(EXAMPLES / "s67.toml").with_changes(
            still | {"lay.stinger.lower": [depth - 25.5, 265.0],
                     "lay.stinger.upper": [depth + 5.0, 400.0], "name": "S"})
    return pf.load_case(EXAMPLES / "j125.toml").with_changes(
        still | {"lay.top": [depth + 5.0, 440.0], "pipe.inner_diameter": 0.55, "name": "J"})


@pytest.mark.parametrize("file", ["lay_table.toml", "depth.toml"])
def test_a_depth_sweep_gives_the_hand_shifted_cases(file):
    """Case by case, the depth axis of one vessel in the waterline frame gives
    the hand-shifted seabed-frame case: every table equal in the seabed frame,
    with the lay table's brackets (100 kN + 1.3 w x_tip; 1.05 times the
    hanging weight)."""
    sweep = load_sweep(SWEEPS / file)
    cases = sweep.cases()
    assert {c.scene for c in cases} == {"S", "J"}
    for c in cases:
        depth = c.values["depth"]
        hand = hand_shifted(c.scene, depth)
        for part in ("pipe", "environment", "seabed", "lay", "solver", "checks"):
            assert getattr(c.case, part) == getattr(hand, part), (c.scene, depth, part)
        lo = (1e5 + 1.3 * 1241.0 * (depth - 25.5) if c.scene == "S"
              else 1.05 * (3306.0 * depth + 7287.0 * 5.0))
        assert target_bounds(c.source.target, c.case)[0] == pytest.approx(lo, rel=1e-12)


def test_a_depth_sweep_solves_as_the_hand_shifted_cases(tmp_path):
    """The depth sweep's answers at two depths of each vessel are the bits of
    the target solve of the hand-shifted case on the same bracket."""
    sweep = load_sweep(SWEEPS / "depth.toml")
    scenes = tuple(dataclasses.replace(s, axes={"depth": ends})
                   for s, ends in zip(sweep.scenes, ((60.0, 150.0), (250.0, 2000.0)),
                                      strict=True))
    run_sweep(Sweep("ends", scenes), tmp_path / "out", workers=1, progress=False)
    rows = read_summary(tmp_path / "out").set_index(["scene", "water_depth"])
    for scene in scenes:
        t = scene.target
        for depth in scene.axes["depth"]:
            hand = hand_shifted(scene.name, depth)
            result = pf.solve_for(hand, {t["column"]: t["goal"]}, t["vary"],
                                  target_bounds(t, hand))
            row = rows.loc[(scene.name, depth)]
            assert row["status"] == "ok", row["message"]
            assert row["target_value"] == result.target["value"]
            assert row["layback"] == result.summary["layback"]
            assert row[t["column"]] == pytest.approx(t["goal"], rel=1e-6)


def test_select_chooses_a_at_each_depth_of_a_depth_axis(tmp_path):
    """A scene over a and depth: one selection row per depth, its grid the
    cases of that depth alone (the least peak stress of the grid is that
    depth's), refined by solves at that depth; the text tells the depths
    apart."""
    from pipelay_fast.study.select import select
    from pipelay_fast.study.select_format import format_selection

    sweep = {"name": "ad", "set": {"solver.element_length": 8.0, "lay.frame": "waterline"},
             "scenes": [{"name": "S", "case": "s67", "stinger_lower": [-25.5, 265.0],
                         "stinger_upper": [5.0, 400.0], "water_depth": 100.0,
                         "vary": {"a": [-0.0010, -0.0012, -0.0014], "depth": [67.0, 80.0]}}]}
    root = tmp_path / "ad"
    run_sweep(load_sweep(sweep), root, workers=1, progress=False)
    summary = read_summary(root)
    grid = select(root, refine=False)
    refined = select(root, write=False)
    assert grid["water_depth"].tolist() == refined["water_depth"].tolist() == [67.0, 80.0]
    for depth, row in zip((67.0, 80.0), grid.itertuples(), strict=True):
        rows = summary[summary["water_depth"] == depth]
        assert len(rows) == 3 and row.n_grid == 3
        assert row.min_max_von_mises == rows["max_von_mises"].min()
    # 67 m: the least stress inside the grid, refined by solves at that depth,
    # not the scene case's 100 m (80 m: least at the grid's end, no solve)
    assert refined["n_solves"].iloc[0] > 0
    assert refined["min_max_von_mises"].iloc[0] <= grid["min_max_von_mises"].iloc[0]
    text = format_selection(refined)
    assert "S@67m" in text and "S@80m" in text
    pytest.importorskip("matplotlib")
    from pipelay_fast.study.plot import plot_sweep

    select(root)  # (written: the figure reads it)
    panels = [ax for ax in plot_sweep(root).axes if ax.get_visible()]
    assert [ax.get_title().split(",")[1] for ax in panels] == [" depth 67 m", " depth 80 m"]
    for ax, depth in zip(panels, (67.0, 80.0), strict=True):  # each its depth's 3 cases
        rows = summary[summary["water_depth"] == depth].sort_values("a")
        (overbend,) = [line for line in ax.get_lines() if line.get_label() == "overbend"]
        assert np.allclose(overbend.get_ydata(), rows["overbend_max_von_mises"] / 1e6,
                           rtol=1e-12)


def test_a_depth_bracket_survives_the_stored_spec():
    """sweep.json's spec gives back the scenes' frame and depth-moved
    brackets: at 300 m the S bracket starts 1613.3 N/m x 270 m above its
    107 259.85 N at 30 m."""
    sweep = load_sweep(SWEEPS / "lay_table.toml")
    back = Sweep.from_spec(sweep.to_spec())
    assert back.scenes == sweep.scenes
    case = next(c for c in back.cases() if c.scene == "S" and c.values["depth"] == 300.0)
    assert case.case.given_lay.frame == "waterline"
    lo, hi = target_bounds(case.source.target, case.case)
    assert (lo, hi) == (pytest.approx(107259.85 + 1613.3 * 270.0, rel=1e-15), 3e6)

"""Sweep files: parsing, refusal of bad files, expansion into cases and chains.

No case is solved here (see test_sweep_run.py).
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from pipelay_fast import load_case
from pipelay_fast.cli import main
from pipelay_fast.output.results import case_id
from pipelay_fast.study.sweep import MAX_CHAIN_LENGTH, chains
from pipelay_fast.study.sweep_file import load_sweep

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "pipelay_fast" / "examples"


def sweep_of(**tables):
    return load_sweep({"case": "j125", **tables})


def test_ranges_include_both_ends():
    sweep = sweep_of(vary={
        "current_speed": {"start": 0.0, "stop": 1.0, "num": 5},
        "current_heading": {"start": 0.0, "stop": 90.0, "step": 30.0},
        "top_tension": [5e5, 6e5]})
    axes = sweep.scenes[0].axes
    assert axes["current_speed"] == (0.0, 0.25, 0.5, 0.75, 1.0)
    assert axes["current_heading"] == (0.0, 30.0, 60.0, 90.0)
    assert axes["top_tension"] == (5e5, 6e5)
    a = load_sweep(ROOT / "sweeps" / "paper.toml").scene("S67").axes["a"]
    assert len(a) == 13 and a[0] == -0.0009 and a[-1] == -0.0021
    assert all(math.isclose(y - x, -0.0001, rel_tol=1e-9) for x, y in zip(a, a[1:], strict=False))


def test_case_ids_are_those_of_the_cases_and_stable():
    spec = {"set": {"solver.element_length": 8.0}, "vary": {"current_speed": [0.0, 1.0]}}
    first, again = sweep_of(**spec).cases(), sweep_of(**spec).cases()
    assert [c.case_id for c in first] == [c.case_id for c in again]
    base = load_case(EXAMPLES / "j125.toml")
    direct = [case_id(base.with_changes({"solver.element_length": 8.0,
                                         "environment.current.speed": v})) for v in (0.0, 1.0)]
    assert [c.case_id for c in first] == direct
    assert len(set(direct)) == 2


@pytest.mark.parametrize("values", [
    {"a": -0.0011}, {"a": -0.0013, "current_speed": 0.5, "current_heading": 90.0},
    {"top_tension": 6e5}, {"bottom_tension": 2e5, "a": -0.001}, {"pipe_length": 600.0}])
def test_cases_are_the_base_case_with_the_values_changed(values):
    scene = load_sweep({"case": "s67", "set": {"solver.element_length": 4.0}}).scenes[0]
    keys = {"a": "lay.stinger.a", "current_speed": "environment.current.speed",
            "current_heading": "environment.current.heading"}
    changes = {keys[k]: v for k, v in values.items() if k in keys}
    for tension in ("top_tension", "bottom_tension", "pipe_length"):
        if tension in values:
            changes.update({"lay.top_tension": None, f"lay.{tension}": values[tension]})
    expected = scene.case.with_changes(changes)
    assert scene.case_for(values) == expected
    assert case_id(scene.case_for(values)) == case_id(expected)


def test_tension_axis_replaces_the_base_tension():
    (case,) = sweep_of(vary={"bottom_tension": [3e5]}).cases()
    assert case.case.lay.top_tension is None and case.case.lay.bottom_tension == 3e5
    assert case.inputs["given_bottom_tension"] == 3e5 and math.isnan(
        case.inputs["given_top_tension"])


@pytest.mark.parametrize(("tables", "message"), [
    ({"case": "j125", "vary": {"aa": [1.0]}}, "unknown key vary.aa (did you mean vary.a?)"),
    ({"case": "j125", "vary": {"a": {"start": -1e-3, "stop": -2e-3, "step": 1e-4}}},
     "vary.a.step = 0.0001 must be non-zero and lead from -0.001 to -0.002"),
    ({"case": "j125", "vary": {"current_speed": [0.0, "1"]}},
     "vary.current_speed[1] = '1' must be a finite number"),
    ({"case": "j125", "vary": {"current_speed": [1.0, 1.0]}}, "repeats the value 1.0"),
    ({"case": "j125", "vary": {"current_speed": {"start": 0, "stop": 1}}},
     "vary.current_speed needs exactly one of"),
    ({"case": "j125", "sett": {}}, "unknown table sett (did you mean set?)"),
    ({"case": "j126"}, "case = 'j126' is neither a bundled example nor a file"),
    ({"vary": {}}, "missing key case"),
    ({"case": "j125", "scenes": [{"name": "J 125"}]},
     "scenes[0].name = 'J 125' must be a non-empty name"),
    ({"case": "j125", "scenes": [{"name": "A"}, {"name": "A"}]},
     "scenes[1].name = 'A' is used by an earlier scene"),
    ({"case": "j125", "scenes": [{"name": "A"}, {"name": "B"}]},
     "scenes[1] = 'B' has the same case as scene 'A'"),
    ({"case": "j125", "scenes": [{"name": "A", "water_depth": -5.0}]},
     "scenes[0] (A): environment.water_depth = -5.0 must be positive"),
    ({"case": "j125", "scenes": [{"name": "A", "stinger_lower": [1.0, 2.0]}]},
     "scenes[0].stinger_lower = [1.0, 2.0] does not apply to a scene with method = 'J'"),
    ({"case": "s67", "scenes": [{"name": "A", "method": "J"}]},
     "scenes[0] (A): missing required key lay.top"),
    ({"case": "j125", "scenes": [{"name": "A", "vary": {"tension": [1.0]}}]},
     "unknown key scenes[0].vary.tension"),
    ({"case": "j125", "set": {"solver.element_lenght": 8.0}},
     "unknown key solver.element_lenght (did you mean solver.element_length?)"),
])
def test_bad_sweep_files_are_refused_naming_the_key(tables, message):
    with pytest.raises(ValueError) as err:
        load_sweep(tables).cases()
    assert message in str(err.value)


def test_bad_sweep_file_names_the_file_and_exits_2(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text('case = "j125"\n[vary]\ncurrent_speed = { start = 0.0, stop = 1.0, num = 0 }\n')
    assert main(["sweep", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert f"{path}: vary.current_speed.num = 0 must be a positive integer" in err
    assert not (tmp_path / "out").exists()


def test_impossible_combinations_are_cases_with_their_error():
    sweep = load_sweep({"case": "s67", "vary": {"a": [-0.0012, 0.02]}})
    good, dip = sweep.cases()
    assert good.case is not None and good.error == ""
    assert dip.case is None and "lay.stinger.a = 0.02 must not be positive" \
        in dip.error
    assert dip.inputs["a"] == 0.02 and dip.inputs["method"] == "S"
    assert len(dip.case_id) == 16 and dip.case_id != good.case_id
    negative = load_sweep({"case": "j125", "vary": {"bottom_tension": [-1e4]}}).cases()[0]
    assert "lay.bottom_tension = -10000.0 must be positive" in negative.error


def test_chains_run_along_a_then_current():
    sweep = load_sweep({"vary": {"a": [-1e-3, -1.1e-3, -1.2e-3], "current_speed": [0.0, 1.0]},
                        "scenes": [{"name": "S", "case": "s67"}, {"name": "J", "case": "j125"}]})
    groups = chains(sweep.cases())
    s_chains = [g for g in groups if g[0].scene == "S"]
    assert len(s_chains) == 2  # one per current speed
    for g in s_chains:
        assert [c.values["a"] for c in g] == [-1e-3, -1.1e-3, -1.2e-3]
        assert len({c.values["current_speed"] for c in g}) == 1
    (j_chain,) = [g for g in groups if g[0].scene == "J"]  # J-lay: no a, chain on current
    assert [c.values for c in j_chain] == [{"current_speed": 0.0}, {"current_speed": 1.0}]
    assert all(math.isnan(c.inputs["a"]) for c in j_chain)


def test_long_chains_are_cut_at_the_same_places_whatever_the_run():
    n = MAX_CHAIN_LENGTH + 5
    sweep = sweep_of(vary={"top_tension": {"start": 5e5, "stop": 6e5, "num": n}})
    lengths = [len(g) for g in chains(sweep.cases())]
    assert lengths == [MAX_CHAIN_LENGTH, 5]


def test_scene_geometry_and_method():
    sweep = load_sweep({"case": "s67", "scenes": [
        {"name": "deep", "water_depth": 80.0, "stinger_upper": [75.0, 400.0]},
        {"name": "J", "method": "J", "top": [60.0, 400.0]}],
        "vary": {"a": [-0.0012]}})
    deep, jlay = (c.case for c in sweep.cases())
    assert deep.environment.water_depth == 80.0
    assert deep.lay.top == (75.0, 400.0)  # the pipe's top follows the stinger's upper end
    assert jlay.lay.method == "J" and jlay.lay.stinger is None and jlay.lay.top == (60.0, 400.0)


def test_dry_run_prints_the_cases_per_scene(capsys):
    assert main(["sweep", str(ROOT / "sweeps" / "paper.toml"), "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert "sweep paper: 54 cases" in out
    assert [line.split()[:3] for line in out.splitlines() if line.startswith("S67")] == \
        [["S67", "26", "2"]]


@pytest.mark.parametrize("name", ["paper", "paper_fixed_length", "quick", "rollers",
                                  "lay_table"])
def test_a_sweep_builds_each_case_as_with_changes_does(name):
    """Each case of the bundled sweep files, built from the scene's tables
    with only the changed tables validated anew, equals the case
    ``with_changes`` gives, and so does its id (``case_id`` of that case,
    with the scene's target when it has one; the id hashed anew from the
    case's ``to_dict()``, not read from the ids the sweep remembered)."""
    from pipelay_fast.output.results import tables_id
    from pipelay_fast.study.sweep import _changes, _with_target

    sweep = load_sweep(ROOT / "sweeps" / f"{name}.toml")
    for c in sweep.cases():
        slow = c.source.case.with_changes(_changes(c.values))
        assert c.case == slow, c
        assert c.case_id == _with_target(tables_id(slow.to_dict()), c.source), c

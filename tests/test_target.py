"""Target solves (pf.solve_for) and sweep files with a [target] table."""

from __future__ import annotations

import math

import pytest

import pipelay_fast as pf
from pipelay_fast.study.dataset import read_summary
from pipelay_fast.study.runner import run_sweep
from pipelay_fast.study.sweep_file import load_sweep
from tests.helpers import EXAMPLES


@pytest.fixture(scope="module")
def s67():
    return pf.load_case(EXAMPLES / "s67.toml")


@pytest.fixture(scope="module")
def j125():
    return pf.load_case(EXAMPLES / "j125.toml")


@pytest.mark.parametrize(("name", "target", "vary", "bounds"), [
    ("s67", {"tip_clearance": 0.3}, "lay.top_tension", (600e3, 1200e3)),
    ("s67", {"sagbend_lcc_utilisation": 0.2}, "lay.top_tension", (300e3, 900e3)),
    ("s67", {"overbend_max_strain": 0.0012}, "lay.stinger.a", (-0.0019, -0.0009)),
    ("j125", {"layback": 350.0}, "lay.top_tension", (300e3, 900e3)),
    ("j125", {"tdp_tension": 300e3}, "lay.top_tension", (300e3, 900e3)),
])
def test_target_is_met_to_1e6(request, name, target, vary, bounds):
    """The returned case meets the target to 1e-6, and so does the same case
    solved again from cold (the answer is the case's, not the warm path's)."""
    case = request.getfixturevalue(name)
    result = pf.solve_for(case, target, vary, bounds)
    ((column, goal),) = target.items()
    assert result.summary[column] == pytest.approx(goal, rel=1e-6)
    value = result.target["value"]
    assert bounds[0] <= value <= bounds[1]
    assert result.case == case.with_changes({vary: value})
    cold = pf.solve(case.with_changes({vary: value})).summary[column]
    assert cold == pytest.approx(goal, rel=1e-6)
    assert result.target["column"] == column and result.target["solves"] >= 2


def test_unreachable_target_names_the_values_at_the_bounds(s67):
    """The message carries the column at both bounds, solved independently here."""
    bounds = (600e3, 1200e3)
    ends = [pf.solve(s67.with_changes({"lay.top_tension": b})).summary["tip_clearance"]
            for b in bounds]
    assert max(ends) < 5.0
    with pytest.raises(pf.TargetError) as err:
        pf.solve_for(s67, {"tip_clearance": 5.0}, "lay.top_tension", bounds)
    text = str(err.value)
    assert "target tip_clearance = 5.0 m is not reached for lay.top_tension" in text
    for end in ends:
        assert f"{end:.6g}"[:6] in text


@pytest.mark.parametrize(("args", "message"), [
    (({"tip_clearence": 0.3}, "lay.top_tension", (6e5, 1.2e6)), "not a numeric summary column"),
    (({"tip_clearance": 0.3, "layback": 300.0}, "lay.top_tension", (6e5, 1.2e6)),
     "must name one summary column"),
    (({"tip_clearance": math.nan}, "lay.top_tension", (6e5, 1.2e6)), "must be a finite number"),
    (({"tip_clearance": 0.3}, "lay.method", (6e5, 1.2e6)), "vary = 'lay.method' is not a numeric"),
    (({"tip_clearance": 0.3}, "lay.bottom_tension", (6e5, 1.2e6)), "is not a numeric key"),
    (({"tip_clearance": 0.3}, "lay.top_tension", (1.2e6, 6e5)), "lo < hi"),
    # inputs the summary repeats are not targets
    (({"stinger_radius": 300.0}, "lay.top_tension", (6e5, 1.2e6)), "not a numeric summary column"),
    (({"roller_shift": 0.1}, "lay.top_tension", (6e5, 1.2e6)), "not a numeric summary column"),
])
def test_bad_target_arguments_are_refused(s67, args, message):
    with pytest.raises(ValueError, match=message):
        pf.solve_for(s67, *args)


SWEEP = {
    "name": "targets",
    "set": {"solver.element_length": 8.0},
    "target": {"sagbend_lcc_utilisation": 0.2, "vary": "lay.top_tension",
               "bounds": [300e3, 1200e3]},
    "scenes": [
        {"name": "J125", "case": "j125"},
        {"name": "S67", "case": "s67", "vary": {"a": [-0.0012, -0.0014]}},
        {"name": "S67tip", "case": "s67", "water_depth": 68.0,
         "target": {"tip_clearance": 5.0, "vary": "lay.top_tension", "bounds": [6e5, 1.2e6]}},
    ],
}


def test_sweep_solves_each_case_for_its_target(tmp_path):
    sweep = load_sweep(SWEEP)
    run_sweep(sweep, tmp_path / "out", workers=1, progress=False)
    table = read_summary(tmp_path / "out")
    ok = table[table["status"] == "ok"]
    assert sorted(ok["scene"]) == ["J125", "S67", "S67"]
    assert ok["sagbend_lcc_utilisation"].tolist() == pytest.approx([0.2] * 3, rel=1e-6)
    assert ok["target_value"].tolist() == pytest.approx(ok["top_tension"].tolist(), rel=1e-9)
    assert set(ok["target"]) == {
        "sagbend_lcc_utilisation = 0.2 by lay.top_tension in [300000.0, 1200000.0]"}
    (failed,) = table[table["status"] == "failed"].itertuples()
    assert failed.scene == "S67tip" and "TargetError" in failed.message
    assert failed.target.startswith("tip_clearance = 5.0 m")


def test_target_changes_the_case_ids():
    plain = {**SWEEP, "scenes": SWEEP["scenes"][:1]}
    plain.pop("target")
    ids = {c.case_id for c in load_sweep(plain).cases()}
    targeted = {c.case_id for c in load_sweep({**SWEEP, "scenes": SWEEP["scenes"][:1]}).cases()}
    assert ids.isdisjoint(targeted)


@pytest.mark.parametrize(("change", "message"), [
    ({"vary": {"top_tension": [5e5, 6e5]}},
     "target.vary = 'lay.top_tension' is varied by the axis"),
    ({"target": {"vary": "lay.top_tension", "bounds": [1.0, 2.0]}}, "must name exactly one"),
    ({"target": {"layback": 300.0, "bounds": [1.0, 2.0]}}, "missing key target.vary"),
    ({"target": {"layback": 300.0, "vary": "lay.top_tension", "bounds": [2.0, 1.0]}},
     "target.bounds = \\[2.0, 1.0\\] must have lo < hi"),
    ({"target": {"laybak": 300.0, "vary": "lay.top_tension", "bounds": [1.0, 2.0]}},
     "unknown key target.laybak \\(did you mean target.layback\\?\\)"),
    ({"target": {"layback": 300.0, "vary": "lay.pipe_length", "bounds": [1.0, 2.0]}},
     "target.vary = 'lay.pipe_length' is not a numeric key"),
])
def test_bad_sweep_targets_are_refused(change, message):
    with pytest.raises(ValueError, match=message):
        load_sweep({**SWEEP, **change})


def test_select_refines_a_with_the_scenes_target(tmp_path):
    """A sweep over a whose cases are solved for a sagbend utilisation: the
    equal-peaks a that select refines is a case solved for the target too."""
    spec = {"name": "a_target", "set": {"solver.element_length": 8.0},
            "target": {"sagbend_lcc_utilisation": 0.18, "vary": "lay.top_tension",
                       "bounds": [300e3, 1200e3]},
            "scenes": [{"name": "S67", "case": "s67",
                        "vary": {"a": [-0.0010, -0.0012, -0.0014, -0.0016]}}]}
    from pipelay_fast.study.select import select

    run_sweep(load_sweep(spec), tmp_path / "out", workers=1, progress=False)
    (row,) = select(tmp_path / "out").itertuples()
    assert -0.0016 < row.a_equal_peaks < -0.0010
    case = load_sweep(spec).scenes[0].case.with_changes({"lay.stinger.a": row.a_equal_peaks})
    at = pf.solve_for(case, {"sagbend_lcc_utilisation": 0.18}, "lay.top_tension",
                      (300e3, 1200e3)).summary
    assert row.equal_peaks_von_mises == pytest.approx(at["max_von_mises"], rel=1e-5)
    assert row.equal_peaks_max_utilisation == pytest.approx(at["max_utilisation"], rel=1e-5)

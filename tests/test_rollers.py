"""The roller stinger (``[lay.stinger]`` with ``rollers`` or ``radius``).

Each roller is a point contact of the contact mechanism (a node over the
roller's material point, its branch by the complementarity): the kernel's
answers on three points against the continuous beam of small-deflection
theory are in tests/test_points.py. Here the engine's answers through the
case:

* rollers on the paper's S67 curve converge to the continuous stinger's
  answer as their spacing shrinks (12, 6, 3, 1.5 m);
* the reactions of the rollers, the seabed and the top balance the weight;
* lowering the tip rollers lifts the pipe off them, and raising the tip
  roller lifts it off the rollers above, one by one, each reaction falling
  linearly (fixed contacts, small deflections) to zero where the pipe
  leaves, never pulling;
* in 3D under a lateral current V rollers hold the pipe on the stinger's
  plane and flat rollers let it swing, mirrored by the current's heading;
* the rollers placed on a radius lie on its circle;
* bad roller stingers are refused, naming the key.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from scipy.integrate import quad

import pipelay_fast as pf
from pipelay_fast.input.case import RollerStinger
from pipelay_fast.output.io import read_units
from pipelay_fast.study.dataset import read_rollers, read_summary
from pipelay_fast.study.runner import run_sweep
from pipelay_fast.study.select import select
from pipelay_fast.study.sweep_file import load_sweep

from .helpers import EXAMPLES, weights


def example_case(name):
    return pf.load_case(EXAMPLES / f"{name}.toml")


def still_s67(**changes):
    """S67 in still water with its bottom tension given (the top tension an
    answer), held at the top along the stinger's tangent."""
    base = example_case("s67")
    st = base.lay.stinger
    return base.with_changes({"environment.current.speed": 0.0, "lay.top_tension": None,
                              "lay.bottom_tension": 471e3,
                              "lay.top_angle": float(st.angle(st.upper[1])), **changes})


def on_rollers(case, spacing, **changes):
    st = case.lay.stinger
    return case.with_changes({"lay.stinger": {"rollers": st.roller_positions(spacing)},
                              "lay.top": list(st.upper), **changes})


def test_rollers_converge_to_the_continuous_stinger():
    """Rollers on the paper's curve: the sagbend peak, touchdown and top
    tension approach the continuous stinger's as the spacing shrinks
    (within 0.5 % and 0.2 m at 3 m), and so does the rollers' total
    reaction, the continuous stinger's integrated one (within 1 % at 1.5 m,
    each halving of the spacing bringing it closer: the first roller lies a
    spacing below the held top, which takes that span's share)."""
    cont = pf.solve(still_s67())
    ref = cont.summary
    support = cont.profile["stinger_reaction"].sum()
    errors = {}
    for spacing in (12.0, 6.0, 3.0, 1.5):
        res = pf.solve(on_rollers(still_s67(), spacing))
        sm = res.summary
        errors[spacing] = (abs(sm["sagbend_max_von_mises"] / ref["sagbend_max_von_mises"] - 1.0),
                           abs(sm["tdp_z"] - ref["tdp_z"]),
                           abs(sm["top_tension"] / ref["top_tension"] - 1.0),
                           abs(res.rollers["reaction"].sum() / support - 1.0))
    sag, tdp, top, _total = errors[3.0]
    assert sag < 5e-3 and top < 5e-3 and tdp < 0.2
    assert errors[1.5][3] < 0.01
    totals = [errors[sp][3] for sp in (12.0, 6.0, 3.0, 1.5)]
    assert all(b < a for a, b in zip(totals[:-1], totals[1:], strict=True))
    tdps = [errors[sp][1] for sp in (12.0, 6.0, 3.0)]
    assert all(b < a for a, b in zip(tdps[:-1], tdps[1:], strict=True))


def test_reactions_balance_the_weight():
    """A submerged S67 on rollers in still water: the constraint forces of
    every node (rollers, seabed, top, the held lower end) carry the weight,
    w L, vertically, and horizontally balance the bottom tension the lower
    end is pulled back with (frictionless rollers, no drag), to 1e-6."""
    case = on_rollers(still_s67(**{"environment.water_depth": 80.0}), 6.0)
    res = pf.solve(case)
    prof = res.profile
    weight = weights(case)[0] * prof["s"].iloc[-1]  # submerged, from the pipe's data
    assert prof["reaction_x"].sum() == pytest.approx(weight, rel=1e-6)
    assert prof["reaction_z"].sum() == pytest.approx(case.lay.bottom_tension, rel=1e-6)
    # the rollers' reactions are their nodes' constraint forces, normal to the pipe
    ro = res.rollers
    nodes = np.searchsorted(prof["s"].to_numpy(), ro["s"].to_numpy())
    force = np.hypot(prof["reaction_x"].to_numpy()[nodes], prof["reaction_z"].to_numpy()[nodes])
    assert force == pytest.approx(ro["reaction"].to_numpy(), rel=1e-9, abs=1e-6 * weight)


def test_lowering_the_tip_rollers_lifts_the_pipe_off_them_continuously():
    """The last three rollers lowered in 5 cm steps, each solve warm from the
    last: no roller pulls; the tip roller's reaction falls linearly with the
    drop while the contacts hold (small deflections), so the line through its
    last two values crosses zero within the step where it lifts off."""
    case = example_case("s67_rollers")
    base = [list(p) for p in case.lay.stinger.rollers]
    prev = None
    drops, tip = [], []
    for drop in np.arange(0.0, 0.56, 0.05):
        rollers = [p[:] for p in base]
        for j in (-3, -2, -1):
            rollers[j][0] -= drop
        prev = pf.solve(case.with_changes({"lay.stinger.rollers": rollers}), warm=prev)
        ro = prev.rollers
        assert (ro["reaction"] >= 0.0).all()
        assert (ro["reaction"][~ro["in_contact"]] == 0.0).all()
        assert (ro["clearance"][~ro["in_contact"]] > 0.0).all()
        drops.append(drop)
        tip.append(float(ro["reaction"].iloc[-1]))
    tip = np.array(tip)
    off = int(np.flatnonzero(tip == 0.0)[0])
    assert off >= 3 and (np.diff(tip[1:off]) < 0.0).all()
    slope = (tip[off - 1] - tip[off - 2]) / (drops[off - 1] - drops[off - 2])
    crossing = drops[off - 1] - tip[off - 1] / slope
    assert drops[off - 1] < crossing <= drops[off]
    # and the pipe stays off it once it has left
    assert (tip[off:] == 0.0).all()


def test_raising_the_tip_roller_lifts_the_pipe_off_the_rollers_above_it_one_by_one():
    """The last roller raised in 5 cm steps (each solve warm from the last):
    the pipe leaves the rollers above it one by one, from the tip up, and
    never returns to one it left; no roller pulls; while the other contacts
    hold, a roller's reaction is linear in the raise (small deflections), so
    the line through its last two values before it leaves crosses zero
    within the step where it leaves."""
    case = example_case("s67_rollers").with_changes({"lay.stinger.shifted": [22]})
    raises = np.arange(0.0, 0.61, 0.05)
    prev, reactions, contact = None, [], []
    for d in raises:
        prev = pf.solve(case.with_changes({"lay.stinger.height_shift": float(d)}), warm=prev)
        assert (prev.rollers["reaction"] >= 0.0).all()
        reactions.append(prev.rollers["reaction"].to_numpy())
        contact.append(prev.rollers["in_contact"].to_numpy())
    reactions, contact = np.array(reactions), np.array(contact)
    assert contact[:, -1].all()  # the raised roller carries the pipe
    left = [j for j in range(contact.shape[1] - 1) if contact[0, j] and not contact[-1, j]]
    assert len(left) >= 5
    off = {j: int(np.flatnonzero(~contact[:, j])[0]) for j in left}
    for j, k in off.items():
        assert not contact[k:, j].any()  # once off, off
    order = sorted(left, key=lambda j: off[j])
    assert all(a > b for a, b in zip(order[:-1], order[1:], strict=True))  # from the tip up
    checked = 0
    for j, k in off.items():
        if k < 2 or not (contact[k - 1] == contact[k - 2]).all():
            continue  # another roller left between the two values: not one line
        slope = (reactions[k - 1, j] - reactions[k - 2, j]) / (raises[k - 1] - raises[k - 2])
        crossing = raises[k - 1] - reactions[k - 1, j] / slope
        assert raises[k - 1] < crossing <= raises[k] + 1e-12
        checked += 1
    assert checked >= 3


def test_a_target_solve_lowers_the_tip_roller_to_a_clearance():
    """solve_for over the tip roller's height: a direct solve at the height
    found clears the tip roller by the goal, and the pipe leaves the roller
    above it."""
    case = example_case("s67_rollers").with_changes({"lay.stinger.shifted": [22]})
    found = pf.solve_for(case, target={"tip_clearance": 0.05},
                         vary="lay.stinger.height_shift", bounds=(-0.8, 0.0))
    shift = found.target["value"]
    assert -0.8 < shift < 0.0
    direct = pf.solve(case.with_changes({"lay.stinger.height_shift": shift}))
    assert direct.rollers["clearance"].iloc[-1] == pytest.approx(0.05, abs=1e-6)
    assert not direct.rollers["in_contact"].iloc[-1]
    assert direct.summary["last_roller_in_contact"] == len(direct.rollers) - 2


@pytest.fixture(scope="module")
def lateral():
    """S67 on rollers in 3D under a 1 m/s current across the lay (+y and -y),
    with V rollers and with flat ones."""
    case = example_case("s67_rollers")
    out = {}
    for kind in ("v", "flat"):
        for heading in (90.0, -90.0):
            out[kind, heading] = pf.solve(case.with_changes({
                "environment.current.heading": heading, "lay.stinger.roller_type": kind}))
    return out


def test_v_rollers_hold_the_pipe_laterally(lateral):
    res = lateral["v", 90.0]
    assert res.summary["dimension"] == "3d"
    ro, prof = res.rollers, res.profile
    y = np.interp(ro["s"], prof["s"], prof["y"])
    bearing = ro["in_contact"].to_numpy()
    assert bearing.sum() > 10
    assert np.abs(y[bearing]).max() < 1e-9
    # holding, in all, against a current towards +y (one by one they
    # alternate: the rollers pin y, not y', and the suspended span's pull at
    # the tip bends the pipe from roller to roller, as a continuous beam)
    assert ro["lateral_reaction"].sum() < -1e3
    assert (ro["lateral_reaction"][~bearing] == 0.0).all()
    _assert_lateral_balance(res)


def _assert_lateral_balance(res):
    """Every lateral constraint force (the rollers', the seabed's friction,
    the held ends') against the current's drag on the deformed pipe,
    integrated independently at the nodes (a quadrature error of about 2e-3
    on these 4 m elements)."""
    from tests.test_friction import lateral_drag

    drag = lateral_drag(res.case, res.profile)
    assert drag > 1e4
    assert res.profile["reaction_y"].sum() + drag == pytest.approx(0.0, abs=3e-3 * drag)


def test_flat_rollers_let_the_pipe_swing(lateral):
    res = lateral["flat", 90.0]
    ro, prof = res.rollers, res.profile
    y = np.interp(ro["s"], prof["s"], prof["y"])
    assert (ro["lateral_reaction"] == 0.0).all()
    assert y[-1] > 1.0  # the tip's rollers, far from the held top
    _assert_lateral_balance(res)  # (the seabed and the ends alone hold it)
    # and further than V rollers let it
    assert (res.summary["max_lateral_deflection"]
            > lateral["v", 90.0].summary["max_lateral_deflection"])


@pytest.mark.parametrize("kind", ["v", "flat"])
def test_a_current_from_the_other_side_mirrors_the_lay(lateral, kind):
    a, b = lateral[kind, 90.0], lateral[kind, -90.0]
    scale = np.abs(a.profile["y"]).max()
    assert np.abs(a.profile["y"] + b.profile["y"]).max() < 1e-7 * scale
    assert a.rollers["reaction"].to_numpy() == pytest.approx(b.rollers["reaction"].to_numpy(),
                                                             rel=1e-7, abs=1e-3)
    assert (a.rollers["lateral_reaction"].to_numpy()
            == pytest.approx(-b.rollers["lateral_reaction"].to_numpy(), rel=1e-7, abs=1e-3))


def test_rollers_placed_on_a_quadratic_lie_on_it_evenly():
    """Stinger.roller_positions: on the curve, from below the upper end to the
    tip, equal arcs apart (arc lengths by adaptive quadrature of the curve's
    speed, sqrt(1 + x'(z)^2))."""
    st = example_case("s67").lay.stinger
    pts = np.array(st.roller_positions(6.0))
    assert pts[:, 0] == pytest.approx(st.height(pts[:, 1]), abs=1e-12)
    assert pts[-1] == pytest.approx(st.lower, abs=1e-9)
    ends = np.concatenate([[st.upper[1]], pts[:, 1]])
    arcs = [quad(lambda z: math.hypot(1.0, st.slope(z)), lo, hi)[0]
            for hi, lo in zip(ends[:-1], ends[1:], strict=True)]
    assert len(arcs) == round(sum(arcs) / 6.0)
    assert np.array(arcs) == pytest.approx(sum(arcs) / len(arcs), rel=1e-8)


def test_rollers_placed_on_a_radius_lie_on_its_circle():
    """A straight then a circular path from the top along its angle: the
    rollers on the straight lie on the top's line, those on the arc at the
    radius from the circle's centre (below the path, normal to the top's
    direction at the straight's end), a path length ``spacing`` apart; the
    rounded heights are multiples of the step, within half a step."""
    top, angle = (72.0, 400.0), 5.0
    st = RollerStinger(radius=300.0, arc_length=100.0, spacing=7.0, straight_length=20.0)
    pts = st.positions(top, angle)
    assert len(pts) == math.floor(120.0 / 7.0)
    t = np.radians(angle)
    direction = np.array([-math.sin(t), -math.cos(t)])  # (x, z) down the path
    normal = np.array([-math.cos(t), math.sin(t)])  # towards the centre (below the path)
    straight = np.arange(1, len(pts) + 1) * 7.0 <= 20.0
    rel = pts[straight] - np.array(top)
    assert np.abs(rel @ normal).max() < 1e-9
    centre = np.array(top) + 20.0 * direction + 300.0 * normal
    assert np.abs(np.hypot(*(pts[~straight] - centre).T) - 300.0).max() < 1e-9
    arc_pts = pts[~straight]
    chords = np.hypot(*np.diff(arc_pts, axis=0).T)
    assert chords == pytest.approx(2.0 * 300.0 * math.sin(7.0 / 600.0), rel=1e-12)
    rounded = RollerStinger(radius=300.0, arc_length=100.0, spacing=7.0, straight_length=20.0,
                            height_step=0.05).positions(top, angle)
    steps = rounded[:, 0] / 0.05
    assert np.abs(steps - np.round(steps)).max() < 1e-9
    assert np.abs(rounded[:, 0] - pts[:, 0]).max() <= 0.025 + 1e-12
    assert rounded[:, 1] == pytest.approx(pts[:, 1], abs=0.0)


def test_the_pipe_rests_on_the_rollers_it_bears_on_and_clears_the_others():
    """The radius example: at each roller's arc length the profile's pipe
    axis passes through the roller where it bears, and above it by the
    reported clearance (measured here along the normal of the profile's
    angle) where it does not; a roller the pipe clears carries nothing."""
    res = pf.solve(example_case("s67_radius"))
    prof, ro = res.profile, res.rollers
    k = np.searchsorted(prof["s"].to_numpy(), ro["s"].to_numpy())
    assert prof["s"].to_numpy()[k] == pytest.approx(ro["s"].to_numpy(), abs=0.0)  # a node each
    x, z = prof["x"].to_numpy()[k], prof["z"].to_numpy()[k]
    theta = np.radians(prof["angle_deg"].to_numpy()[k])
    normal = np.cos(theta) * (x - ro["x"].to_numpy()) - np.sin(theta) * (z - ro["z"].to_numpy())
    on = ro["in_contact"].to_numpy()
    assert 0 < on.sum() < len(ro)
    assert np.abs(normal[on]).max() < 1e-9
    assert normal[~on] == pytest.approx(ro["clearance"][~on].to_numpy(), abs=1e-9)
    assert (ro["clearance"][~on] > 0.0).all() and (ro["reaction"][~on] == 0.0).all()
    assert (prof["contact"].to_numpy()[k] == np.where(on, "roller", "free")).all()


def test_a_warm_start_carries_contacts_not_the_roller_type(lateral):
    """Flat rollers warm from a V-roller answer: the flat answer (the warm
    start carries the contact state, not the neighbour's roller type)."""
    case = example_case("s67_rollers").with_changes({"environment.current.heading": 90.0,
                                                     "lay.stinger.roller_type": "flat"})
    warm = pf.solve(case, warm=lateral["v", 90.0])
    cold = lateral["flat", 90.0]
    assert (warm.rollers["lateral_reaction"] == 0.0).all()
    assert warm.summary["max_lateral_deflection"] == pytest.approx(
        cold.summary["max_lateral_deflection"], rel=1e-6)


def test_a_roller_answer_does_not_warm_start_a_j_lay():
    res = pf.solve(example_case("s67_rollers"))
    with pytest.raises(ValueError, match="warm: lay.method 'J'|rollers"):
        pf.solve(example_case("j125"), warm=res)


def test_solve_writes_the_roller_table(tmp_path):
    from pipelay_fast.output.io import write_result
    from pipelay_fast.output.results import ROLLER_UNITS

    res = pf.solve(example_case("s67_rollers"))
    paths = write_result(res, tmp_path)
    assert [p.name for p in paths] == ["summary.parquet", "profile.parquet", "rollers.parquet"]
    back = pd.read_parquet(tmp_path / "rollers.parquet")
    pd.testing.assert_frame_equal(back, res.rollers)
    assert read_units(tmp_path / "rollers.parquet") == ROLLER_UNITS
    summary = pd.read_parquet(tmp_path / "summary.parquet")
    assert summary["last_roller_in_contact"].iloc[0] == res.summary["last_roller_in_contact"]
    plain = write_result(pf.solve(example_case("s67")), tmp_path / "quadratic")
    assert len(plain) == 2
    assert pd.read_parquet(plain[0])["last_roller_in_contact"].isna().all()


@pytest.mark.parametrize("changes, key", [
    ({"lay.stinger.rollers": [[71.0, 394.0], [71.5, 388.0]]}, "lay.stinger.rollers[1]"),
    ({"lay.stinger.rollers": [[73.0, 394.0], [71.0, 388.0]]}, "lay.stinger.rollers[0]"),
    ({"lay.stinger.rollers": [[71.0, 394.0], [-1.0, 300.0]]}, "lay.stinger.rollers[1]"),
    ({"lay.stinger.rollers": []}, "lay.stinger.rollers"),
    ({"lay.stinger.rollers": [[71.0, 394.0]], "lay.stinger.a": -0.001}, "lay.stinger.rollers"),
    ({"lay.stinger.height_step": 0.05}, "lay.stinger.height_step"),
    ({"lay.stinger.roller_type": ["v", "flat"]}, "lay.stinger.roller_type"),
    ({"lay.stinger.roller_type": "u"}, "lay.stinger.roller_type"),
    ({"lay.top_angle": None}, "lay.top_angle"),
    ({"lay.top": None}, "lay.top"),
    ({"lay.stinger.straight_length": 10.0}, "lay.stinger.straight_length"),
    ({"lay.stinger.shifted": [23]}, "lay.stinger.shifted"),
    ({"lay.stinger.shifted": [1, 1]}, "lay.stinger.shifted"),
])
def test_bad_roller_stingers_are_refused_naming_the_key(changes, key):
    case = example_case("s67_rollers")
    with pytest.raises(ValueError, match=key.replace("[", r"\[").replace("]", r"\]")):
        case.with_changes(changes)


@pytest.mark.parametrize("changes, key", [
    ({"lay.stinger.spacing": None}, "lay.stinger.spacing"),
    ({"lay.stinger.arc_length": 700.0}, "lay.stinger.arc_length"),  # turns it to 93 deg
    ({"lay.stinger.spacing": 200.0}, "lay.stinger.spacing"),
    ({"lay.top_angle": "pinned"}, "lay.top_angle"),
    ({"lay.stinger.radius": -5.0}, "lay.stinger.radius"),
    ({"lay.stinger.rollers": [[71.0, 394.0]]}, "lay.stinger.radius"),
    ({"lay.stinger.radius": None}, "lay.stinger.radius"),  # a path without its radius
])
def test_bad_roller_paths_are_refused_naming_the_key(changes, key):
    case = example_case("s67_radius")
    with pytest.raises(ValueError, match=key):
        case.with_changes(changes)


def test_a_warm_start_needs_the_same_rollers():
    case = example_case("s67_rollers")
    res = pf.solve(case)
    fewer = case.with_changes({"lay.stinger.rollers": [list(p) for p in
                                                        case.lay.stinger.rollers[:-1]]})
    with pytest.raises(ValueError, match="rollers"):
        pf.solve(fewer, warm=res)


RADIUS_SWEEP = {"name": "radius", "set": {"solver.element_length": 8.0},
                "scenes": [{"name": "S67R", "case": "s67_radius",
                            "vary": {"stinger_radius": [400.0, 450.0, 500.0]}},
                           {"name": "S67T", "case": "s67_rollers",
                            "set": {"lay.stinger.shifted": [22]},
                            "vary": {"roller_shift": [-0.1, 0.0, 0.1]}}]}


@pytest.fixture(scope="module")
def radius_sweep(tmp_path_factory):
    root = tmp_path_factory.mktemp("rollers") / "radius"
    run_sweep(load_sweep(RADIUS_SWEEP), root, workers=1, progress=False)
    return root


def test_a_roller_sweep_writes_each_case_s_rollers(radius_sweep):
    """The rollers table holds every case's roller table, as a direct solve
    gives it, with its case id (the sweep's warm from its neighbour, the
    direct one cold: their meshes differ a little, 4e-8 in the reactions)."""
    summary = read_summary(radius_sweep)
    rollers = read_rollers(radius_sweep)
    assert (summary["status"] == "ok").all() and len(summary) == 6
    row = summary[(summary["scene"] == "S67R") & (summary["stinger_radius"] == 450.0)].iloc[0]
    mine = rollers[rollers["case_id"] == row["case_id"]].sort_values("roller")
    direct = pf.solve(example_case("s67_radius").with_changes(
        {"solver.element_length": 8.0, "lay.stinger.radius": 450.0})).rollers
    assert len(mine) == len(direct) == 23
    for column in ("x", "z", "s", "reaction", "clearance"):
        np.testing.assert_allclose(mine[column].to_numpy(), direct[column].to_numpy(),
                                   rtol=1e-6, atol=1e-9 * direct["reaction"].max(),
                                   err_msg=column)
    assert (mine["in_contact"].to_numpy() == direct["in_contact"].to_numpy()).all()
    assert row["last_roller_in_contact"] == int(np.flatnonzero(direct["in_contact"])[-1])
    shifted = summary[summary["scene"] == "S67T"].sort_values("roller_shift")
    assert shifted["roller_shift"].tolist() == [-0.1, 0.0, 0.1]
    assert shifted["a"].isna().all() and shifted["stinger_radius"].isna().all()


def test_select_chooses_the_radius_and_the_shift_of_least_stress(radius_sweep):
    """By a's rules: the least peak stress, refined between the grid points
    around the grid's least; a direct solve at the choice gives that stress
    (to 1e-5: the refinement's solve is warm, on its neighbour's mesh at 8 m
    elements), no more than the grid's."""
    table = select(radius_sweep)
    assert read_units(radius_sweep / "selection.parquet")["stinger_radius_min_stress"] == "m"
    by_scene = {row.scene: row for row in table.itertuples()}
    radius, shift = by_scene["S67R"], by_scene["S67T"]
    assert (radius.variable, shift.variable) == ("stinger_radius", "roller_shift")
    assert math.isnan(radius.a_min_stress) and math.isnan(radius.roller_shift_min_stress)
    grid = read_summary(radius_sweep)
    for row, scene, key, column in ((radius, "S67R", "lay.stinger.radius", "stinger_radius"),
                                    (shift, "S67T", "lay.stinger.height_shift",
                                     "roller_shift")):
        cases = grid[grid["scene"] == scene]
        chosen = getattr(row, f"{column}_min_stress")
        assert cases[column].min() < chosen < cases[column].max()
        assert row.min_max_von_mises <= cases["max_von_mises"].min()
        base = example_case("s67_radius" if scene == "S67R" else "s67_rollers")
        extra = {} if scene == "S67R" else {"lay.stinger.shifted": [22]}
        at = pf.solve(base.with_changes({"solver.element_length": 8.0, key: chosen, **extra}))
        assert at.summary["max_von_mises"] == pytest.approx(row.min_max_von_mises, rel=1e-5)


def test_a_scene_varies_one_stinger_axis():
    spec = {"name": "bad", "scenes": [{"name": "X", "case": "s67_radius", "vary": {
        "stinger_radius": [400.0, 450.0], "roller_shift": [0.0, 0.1]}}]}
    with pytest.raises(ValueError, match="both vary the stinger"):
        load_sweep(spec)


def test_select_prints_the_roller_choices(radius_sweep):
    from pipelay_fast.study.select_format import format_selection

    table = select(radius_sweep, write=False)
    text = format_selection(table)
    assert "stinger_radius[m]" in text and "roller_shift[m]" in text
    # each scene's first line prints its variable with its unit, then the value of least stress
    for _, row in table.iterrows():
        label = f"{row['variable']}[m]"
        tokens = next(ln.split() for ln in text.splitlines()
                      if ln.split()[:1] == [row["scene"]] and label in ln.split())
        printed = float(tokens[tokens.index(label) + 1])
        assert printed == pytest.approx(row[row["variable"] + "_min_stress"], rel=1e-4, abs=1e-6)


@pytest.mark.parametrize("axis, case", [("a", "s67_rollers"), ("stinger_radius", "s67_rollers"),
                                        ("roller_shift", "s67"), ("stinger_radius", "s67")])
def test_a_stinger_axis_the_scene_s_stinger_lacks_is_refused(axis, case):
    spec = {"name": "bad", "scenes": [{"name": "X", "case": case,
                                       "vary": {axis: [1.0, 2.0]}}]}
    with pytest.raises(ValueError, match=f"the axis '{axis}' needs"):
        load_sweep(spec)


def test_the_answer_does_not_depend_on_the_guide_s_mesh(monkeypatch):
    """The guide (the quadratic fitted through the rollers) is only where a
    roller solve starts: solved on the case's own elements instead of twice
    as long ones, the rollers' answer (mesh graded anew at the case's sizes)
    is the same to the solver's tolerance, bearing on the same rollers."""
    from pipelay_fast.engine import guess, tuning

    case = pf.load_case("pipelay_fast/examples/s67_rollers.toml")
    coarse = pf.solve(case)
    guess._GUIDES.clear()  # (the guide is built once per case)
    monkeypatch.setattr(tuning, "GUIDE_COARSENING", 1.0)
    fine = pf.solve(case)
    guess._GUIDES.clear()  # (the guide is built once per case)
    assert coarse.summary["n_elements"] > fine.summary["n_elements"]  # (the longer laid pipe)
    for key in ("max_von_mises", "overbend_max_moment", "top_tension", "max_roller_reaction"):
        assert coarse.summary[key] == pytest.approx(fine.summary[key], rel=1e-8), key
    assert coarse.summary["tdp_z"] == pytest.approx(fine.summary["tdp_z"], abs=1e-6)
    np.testing.assert_array_equal(coarse.rollers["in_contact"], fine.rollers["in_contact"])


@pytest.mark.parametrize("example", ["s67_rollers", "s125_rollers"])
def test_the_mesh_follows_touchdown_and_the_rollers_as_its_grading_does(example):
    """The roller problem's mesh (graded at touchdown, a plain node over each
    roller) moves with those boundaries by the rates its grading has: moved
    by d = 5 cm, it differs from the mesh graded anew (mesh.graded_nodes) by
    less than 1e-2 d, and by more than 16 times less at d / 8 (the error is
    of higher order than d, though the grading's kinks keep it from a clean
    d^2; with the zones' shares, the rollers' rates before, 3.5 cm off at
    d = 5 cm); between rollers, in uniform stretches, the rates are linear
    (to 1e-10 m: round-off of the central differences)."""
    from pipelay_fast.engine.boundaries import touchdown_position
    from pipelay_fast.engine.mesh import graded_nodes
    from pipelay_fast.engine.solver import _from_guide
    from pipelay_fast.input.limits import IterationBudget
    from pipelay_fast.kernels.layout import B_PT

    case = pf.load_case(EXAMPLES / f"{example}.toml")
    pb, _ = _from_guide(case, IterationBudget(case.solver.max_iterations_total))
    nodes, rates = pb.bnodes, pb.mesh.grade_b
    assert nodes[0] >= 0 and (nodes[B_PT:] >= 0).all()
    total, s_t, over = float(pb.s[-1]), touchdown_position(pb), pb.s[nodes[B_PT:]]

    def graded(move):
        return graded_nodes(total, [s_t + move[0], total], pb.stats["h_max"],
                            pb.stats["h_min"], nodes=over + move[B_PT:])

    np.testing.assert_allclose(graded(np.zeros(nodes.size)), pb.s, rtol=0, atol=1e-12)
    for b in [0, *range(B_PT, nodes.size)]:  # each boundary alone
        errors = []
        for d in (0.05, 0.05 / 8):
            move = np.zeros(nodes.size)
            move[b] = d
            moved = graded(move)
            assert moved.size == pb.s.size
            errors.append(np.abs(moved - (pb.s + move @ rates)).max())
        if errors[0] < 1e-10:  # between uniform stretches: linear
            continue
        assert errors[0] < 1e-2 * 0.05, b
        assert errors[1] < errors[0] / 16.0, b


def test_a_warm_start_s_mesh_moves_with_its_neighbour_s_grading():
    """Every roller raised 2 cm from a solved neighbour: Newton moves
    touchdown and the rollers' material points, and the neighbour's mesh
    follows them with its grading's rates (Problem.grade_b), so after the
    first pass it is still the mesh graded at the boundaries found
    (boundaries.graded_on_boundaries: no node 2 % of h_min off). Moved in
    the zones of three flexural lengths, as warm starts were before, it was
    3.75 cm off (h_min 0.5 m) and was graded anew: half an iteration more a
    case in a sweep of the rollers' heights."""
    from pipelay_fast.engine.boundaries import graded_on_boundaries
    from pipelay_fast.engine.solver import _solve_gravity
    from pipelay_fast.engine.tuning import ON_FOCUS
    from pipelay_fast.engine.warm import warm_problem
    from pipelay_fast.input.limits import IterationBudget

    case = pf.load_case(EXAMPLES / "s67_rollers.toml")
    neighbour = pf.solve(case).state
    for shift in (0.02, -0.02):
        shifted = case.with_changes({"lay.stinger.height_shift": shift})
        pb = warm_problem(shifted, neighbour)
        pb, _react, _stats = _solve_gravity(shifted, pb,
                                            IterationBudget(case.solver.max_iterations_total))
        moved = np.abs(pb.s - neighbour.s).max()
        assert moved > ON_FOCUS * pb.stats["h_min"]  # (the mesh did move)
        assert graded_on_boundaries(shifted, pb), shift


"""The vessel's trim (``lay.trim_deg`` about ``lay.trim_pivot``,
:mod:`pipelay_fast.input.trim`): the stinger, top, firing line and rollers
turned as one body, positive the stern (towards -z) down.

Checked against rotations written here with NumPy's rotation matrix: the
turned quadratic stinger's kernel geometry (height, slope, curvature)
against the vessel's parabola sampled and rotated; a trimmed roller stinger
and a trimmed J-lay against the same geometry turned by hand and solved
untrimmed; the trimmed quadratic stinger's solved contact nodes on the
rotated curve; a trim of 0 the untrimmed solve to the bit."""

from __future__ import annotations

import math

import numpy as np
import pytest

import pipelay_fast as pf
from pipelay_fast.engine.supports import line_height
from pipelay_fast.input.lay import Stinger
from pipelay_fast.input.trim import TrimmedStinger, trimmed
from pipelay_fast.kernels import layout as L
from pipelay_fast.kernels.supports import support_angle, support_gap, support_height
from tests.helpers import load

PIVOT = (70.0, 330.0)  # (x, z) [m]: ahead of S67's tip, behind its upper end
VESSEL = Stinger(a=-0.0012, lower=(41.5, 265.0), upper=(72.0, 400.0))  # S67's


def rotation(deg: float) -> np.ndarray:
    """The trim's matrix on (x, z): counter-clockwise seen with z to the
    right and x up (the stern, at -z, down for a positive trim)."""
    t = math.radians(deg)
    return np.array([[math.cos(t), math.sin(t)], [-math.sin(t), math.cos(t)]])


def turn(points, deg: float, pivot=PIVOT) -> np.ndarray:
    """``points`` (n, 2) of (x, z) [m] turned by ``deg`` about ``pivot``."""
    p = np.asarray(pivot, dtype=float)
    return (np.asarray(points, dtype=float) - p) @ rotation(deg).T + p


# ----------------------------------------------------------------- geometry


def test_a_positive_trim_puts_the_stern_down():
    st = TrimmedStinger(VESSEL, math.radians(2.0), PIVOT)
    assert st.lower[0] < VESSEL.lower[0] and st.upper[0] > VESSEL.upper[0]
    assert float(st.angle(st.lower[1])) == pytest.approx(
        float(VESSEL.angle(VESSEL.lower[1])) + 2.0, abs=1e-12)


@pytest.mark.parametrize("deg", [-20.0, -1.0, 1e-9, 1.0, 5.0, 20.0])
def test_the_kernel_curve_is_the_rotated_parabola(deg):
    """support_height's (f, f', f'') at the z of points of the vessel's
    parabola rotated by a NumPy matrix: f their x, f' the tangent turned by
    the trim, and the curvature f''/(1 + f'^2)^(3/2) the parabola's. The
    Python twins (line_height, TrimmedStinger) give the kernel's bits."""
    st = TrimmedStinger(VESSEL, math.radians(deg), PIVOT)
    row = st.support_row()
    a, b, c = VESSEL.a, VESSEL.b, VESSEL.c
    u = np.linspace(VESSEL.lower[1] - 40.0, VESSEL.upper[1], 41)
    pts = turn(np.stack([(a * u + b) * u + c, u], axis=1), deg)
    slope = np.tan(np.arctan(2 * a * u + b) + math.radians(deg))
    kappa = 2 * a / (1 + (2 * a * u + b) ** 2) ** 1.5
    for (x, z), fp_ref, k_ref in zip(pts, slope, kappa, strict=True):
        f, fp, fpp = support_height(L.SUP_CURVE, row, z)
        assert f == pytest.approx(x, rel=0.0, abs=1e-11)
        assert fp == pytest.approx(fp_ref, rel=1e-11)
        assert fpp / (1 + fp * fp) ** 1.5 == pytest.approx(k_ref, rel=1e-10)
        assert support_angle(L.SUP_CURVE, row, z) == pytest.approx(math.atan(fp_ref), rel=1e-12)
        assert support_gap(L.SUP_CURVE, row, x + 0.5, z, 0.0) == pytest.approx(0.5, abs=1e-11)
        assert line_height(L.SUP_CURVE, row, z) == (f, fp)
        assert (float(st.height(z)), float(st.slope(z))) == (f, fp)
        assert float(st.curvature(z)) == pytest.approx(k_ref, rel=1e-11)
    zs = pts[:, 1]
    np.testing.assert_array_equal(line_height(L.SUP_CURVE, row, zs)[0], st.height(zs))
    ends = turn([VESSEL.lower, VESSEL.upper], deg)
    np.testing.assert_allclose([st.lower, st.upper], ends, rtol=0.0, atol=1e-12)


@pytest.mark.parametrize("deg", [-3.0, 1.0])
def test_turned_arc_lengths_and_special_points(deg):
    """The arc between two points is the vessel's between their originals;
    z_at_arc inverts it; the level point is level, the seabed crossing at x = 0."""
    st = TrimmedStinger(VESSEL, math.radians(deg), PIVOT)
    a, b, c = VESSEL.a, VESSEL.b, VESSEL.c
    u = np.array([250.0, 300.0, 390.0])
    (x0, z0), (x1, z1), (x2, z2) = turn(np.stack([(a * u + b) * u + c, u], axis=1), deg)
    assert float(st.arc_length(z0, z2)) == pytest.approx(
        float(VESSEL.arc_length(u[0], u[2])), rel=1e-12)
    assert float(st.z_at_arc(z1, float(VESSEL.arc_length(u[1], u[0])))) == pytest.approx(
        z0, abs=1e-9)
    level = st.level_z()
    assert float(st.slope(level)) == pytest.approx(0.0, abs=1e-12)
    assert float(st.height(st.seabed_z())) == pytest.approx(0.0, abs=1e-9)


def test_trim_zero_is_the_lay_itself():
    case = load("s67", **{"lay.trim_deg": 0.0, "lay.trim_pivot": list(PIVOT)})
    assert trimmed(case.lay) is case.lay and isinstance(case.lay.stinger, Stinger)
    assert pf.load_case(case.to_dict()) == case


# ----------------------------------------------------------------- refusals


@pytest.mark.parametrize(("name", "changes", "key"), [
    ("s67", {"lay.trim_deg": 1.0}, "lay.trim_pivot"),
    ("s67", {"lay.trim_deg": 90.0, "lay.trim_pivot": [70.0, 330.0]}, "lay.trim_deg"),
    ("s67", {"lay.trim_deg": 10.0, "lay.trim_pivot": [70.0, 1000.0]}, "lay.trim_deg"),  # tip
    ("s67", {"lay.trim_deg": 75.0, "lay.trim_pivot": [70.0, 330.0]}, "lay.trim_deg"),  # steep
    ("j125", {"lay.top_angle": 89.5, "lay.trim_deg": 1.0, "lay.trim_pivot": [130.0, 440.0]},
     "lay.trim_deg"),
    ("s67_rollers", {"lay.trim_deg": 60.0, "lay.trim_pivot": [72.0, 400.0]}, "lay.trim_deg"),
])
def test_a_trim_that_leaves_a_lay_is_refused_naming_the_key(name, changes, key):
    with pytest.raises(ValueError, match=key.replace(".", r"\.")):
        load(name, **changes)


# ----------------------------------------------------------------- solves


def summary(result) -> dict:
    """The summary but its timing, case id and trim, NaN as None (to compare)."""
    return {k: None if isinstance(v, float) and math.isnan(v) else v
            for k, v in result.summary.items() if k not in ("solve_seconds", "case_id")}


@pytest.mark.parametrize("name", ["s67", "s125", "s67_rollers", "j125"])
def test_trim_zero_gives_the_untrimmed_bits(name):
    plain = pf.solve(load(name))
    zero = pf.solve(load(name, **{"lay.trim_deg": 0.0, "lay.trim_pivot": [50.0, 350.0]}))
    assert summary(zero) == summary(plain)
    np.testing.assert_array_equal(zero.profile.to_numpy(), plain.profile.to_numpy())


def by_hand(name: str, deg: float, pivot, **changes) -> pf.Case:
    """The case with its top, firing line and rollers turned here, untrimmed."""
    case = load(name, **changes)
    lay = case.lay
    hand = {"lay.top": turn([lay.top], deg, pivot)[0].tolist()}
    if not isinstance(lay.top_angle, str) and lay.top_angle is not None:
        hand["lay.top_angle"] = lay.top_angle + deg
    if lay.has_rollers:  # (a radius path's placed on the vessel, then turned)
        hand["lay.stinger"] = {"rollers": turn(lay.roller_positions(), deg, pivot).tolist(),
                               "roller_type": lay.stinger.roller_type}
    return case.with_changes(hand)


COMPARED = ("top_tension", "bottom_tension", "tdp_z", "top_angle_deg", "departure_angle_deg",
            "max_von_mises", "overbend_max_moment", "sagbend_max_moment", "layback")


@pytest.mark.parametrize(("name", "changes"), [
    ("s67_rollers", {}),
    ("s67_radius", {}),
    ("j125", {"lay.top_angle": 85.0}),
])
@pytest.mark.parametrize("deg", [-1.0, 1.0])
def test_trimmed_rollers_and_jlay_are_the_geometry_turned_by_hand(name, changes, deg):
    pivot = [60.0, 380.0]
    base = load(name, **changes)
    trim = pf.solve(base.with_changes({"lay.trim_deg": deg, "lay.trim_pivot": pivot}))
    hand = pf.solve(by_hand(name, deg, pivot, **changes))
    assert trim.summary["status"] == hand.summary["status"] == "ok"
    for key in COMPARED:
        got, ref = trim.summary[key], hand.summary[key]
        if isinstance(ref, float) and math.isnan(ref):
            assert math.isnan(got), key
        else:
            assert got == pytest.approx(ref, rel=1e-9, abs=1e-9), key
    if name == "j125":  # a prescribed firing line: the top angle moves by the trim
        untrimmed = pf.solve(base).summary["top_angle_deg"]
        assert trim.summary["top_angle_deg"] - untrimmed == pytest.approx(deg, abs=1e-9)


@pytest.mark.parametrize("name", ["s67", "s125", "s67_3d"])
@pytest.mark.parametrize("deg", [-1.0, 1.0])
def test_trimmed_quadratic_stinger_holds_the_pipe_on_the_rotated_curve(name, deg):
    """S67, S125 and S67 in 3D trimmed: the nodes the stinger holds lie on the vessel's
    parabola once turned back by a NumPy matrix; the firing line is the
    turned tangent; the departure angle moves with the trim, by less than
    it (the lift-off slides along the turned stinger to where the catenary
    leaves it, or the pipe bends over the tip), and is the turned stinger's
    tangent at lift-off (steeper over the tip while it bears on it)."""
    base = load(name)
    vessel = base.lay.stinger
    case = base.with_changes({"lay.trim_deg": deg, "lay.trim_pivot": list(PIVOT)})
    res, plain = pf.solve(case), pf.solve(base)
    sm = res.summary
    assert sm["status"] == "ok"
    prof = res.profile
    held = (prof["contact"] == "stinger").to_numpy()
    x, z = prof["x"].to_numpy(), prof["z"].to_numpy()
    back = turn(np.stack([x, z], axis=1), -deg)  # into the vessel's frame
    gap = back[:, 0] - ((vessel.a * back[:, 1] + vessel.b) * back[:, 1] + vessel.c)
    assert held.sum() > 10
    assert np.abs(gap[held]).max() < 1e-9
    assert np.abs(prof["y"].to_numpy()[held]).max() < 1e-9  # (3D: on the stinger's plane)
    vessel_top = float(vessel.angle(vessel.upper[1]))
    assert sm["top_angle_deg"] == pytest.approx(vessel_top + deg, abs=1e-9)
    moved = sm["departure_angle_deg"] - plain.summary["departure_angle_deg"]
    assert 0.2 * abs(deg) < moved * np.sign(deg) < abs(deg)
    tangent = float(case.lay.stinger.angle(sm["liftoff_z"]))
    if sm["bears_on_tip"]:
        assert sm["departure_angle_deg"] > tangent
    else:
        assert sm["departure_angle_deg"] == pytest.approx(tangent, abs=1e-9)


def test_a_pivot_moved_along_the_trims_chord_only_shifts_the_answer_in_z():
    """Turning by t about p + v with v = (1, tan(t/2)) d is turning about p
    and moving by (0, sin(t) d + (1 - cos(t)) tan(t/2) d): on a flat seabed
    the same lay, shifted along z (the turned curve's coefficients differ)."""
    deg, d = 1.0, 40.0
    t = math.radians(deg)
    p2 = [PIVOT[0] + d, PIVOT[1] + math.tan(t / 2) * d]
    shift = math.sin(t) * d + (1 - math.cos(t)) * math.tan(t / 2) * d
    one = pf.solve(load("s67", **{"lay.trim_deg": deg, "lay.trim_pivot": list(PIVOT)}))
    two = pf.solve(load("s67", **{"lay.trim_deg": deg, "lay.trim_pivot": p2}))
    for key in ("top_tension", "bottom_tension", "departure_angle_deg", "max_von_mises"):
        assert two.summary[key] == pytest.approx(one.summary[key], rel=1e-7), key
    assert two.summary["tdp_z"] - one.summary["tdp_z"] == pytest.approx(shift, abs=1e-5)


def test_a_waterline_trim_turns_the_seabed_frame_twins_numbers():
    """The pivot is converted with the lay (an elevation raised by the depth,
    exactly) before the trim turns it: S67 in the waterline frame trimmed is
    its seabed-frame twin trimmed, equal lays."""
    tables = load("s67").to_dict()
    tables["lay"] = {**{k: v for k, v in tables["lay"].items() if k not in ("top", "stinger")},
                     "stinger": {"a": -0.0012, "lower": [-25.5, 265.0], "upper": [5.0, 400.0]},
                     "frame": "waterline", "trim_deg": 1.5, "trim_pivot": [3.0, 330.0]}
    water = pf.load_case(tables)
    twin = load("s67", **{"lay.trim_deg": 1.5, "lay.trim_pivot": [70.0, 330.0]})
    assert water.lay == twin.lay and water.given_lay.trim_pivot == (3.0, 330.0)
    assert pf.load_case(water.to_dict()) == water


def test_a_trimmed_roller_stingers_guide_is_not_trimmed_again():
    from pipelay_fast.engine.guess import guide_case
    case = load("s67_rollers", **{"lay.trim_deg": 1.0, "lay.trim_pivot": [60.0, 380.0]})
    guide = guide_case(case)
    assert guide.lay.stinger.lower == tuple(case.lay.roller_positions()[-1])
    assert guide.lay.top == case.lay.top and guide.given_lay.trim_deg == 0.0


def test_trim_is_a_sweep_axis():
    from pipelay_fast.study.sweep import AXES
    from pipelay_fast.study.sweep_file import load_sweep
    assert AXES["trim"] == ("lay.trim_deg", "trim_deg", "deg")
    sweep = load_sweep({"case": "s67", "set": {"lay.trim_pivot": list(PIVOT)},
                        "vary": {"trim": [-1.0, 0.0, 1.0]}})
    cases = sweep.cases()
    assert [c.case.given_lay.trim_deg for c in cases] == [-1.0, 0.0, 1.0]
    for c in cases:
        st = c.case.lay.stinger
        ref = turn([VESSEL.lower], c.values["trim"])[0]
        np.testing.assert_allclose(st.lower, ref, rtol=0.0, atol=1e-12)


def test_a_trim_keeps_the_stingers_curvature_pin_jump_and_strain_check():
    """The pinned top's tension jump (EI kappa_U)^2 / (2 EI) and the bending
    strain check read the curvature, which a turn leaves as it is: the jump
    of the trimmed stinger is the closed form's of the vessel's parabola,
    kappa_U = 2a / (1 + x'(z_U)^2)^(3/2), x'(z_U) the chord's slope plus
    a (z_U - z_L)."""
    from pipelay_fast.engine.model import pin_jump
    trim = {"lay.trim_deg": 2.0, "lay.trim_pivot": list(PIVOT)}
    pinned = load("s67", **{"lay.top_angle": "pinned"})
    (x_l, z_l), (x_u, z_u) = VESSEL.lower, VESSEL.upper
    slope_u = (x_u - x_l) / (z_u - z_l) + VESSEL.a * (z_u - z_l)
    kappa_u = 2.0 * VESSEL.a / (1.0 + slope_u**2) ** 1.5
    ei = pinned.pipe.bending_stiffness
    jump = (ei * kappa_u) ** 2 / (2.0 * ei)
    assert pin_jump(pinned) == pytest.approx(jump, rel=1e-12)
    assert pin_jump(pinned.with_changes(trim)) == pytest.approx(jump, rel=1e-12)
    res = pf.solve(pinned.with_changes(trim))
    assert res.summary["status"] == "ok"
    tight = {"solver.max_strain": 1e-4}
    with pytest.raises(ValueError, match=r"lay\.stinger\.a = -0\.0012 bends"):
        load("s67", **tight)
    with pytest.raises(ValueError, match=r"lay\.stinger\.a = -0\.0012 bends"):
        load("s67", **tight, **trim)

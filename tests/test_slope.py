"""The sloped seabed (``seabed.slope_deg``) against a planar elastica written
here, independent of the engine: scipy's ``solve_bvp`` over the suspended
span with touchdown on the inclined line x = (z - z0) tan(alpha) (on it,
tangent to it, no moment there), the top pinned at its point (J-lay) or
lift-off on the stinger's curve (S-lay: on it, tangent to it, the moment
its curvature's, and the rod's first integral Te + M^2 / (2 EI) - W(x)
carried from the top); plus slope 0 against the flat seabed's bits
and the refusals.

The rod, inextensible, in the plane (z, x): z' = cos(theta), x' =
sin(theta), theta' = M / EI, M' = H sin(theta) - V cos(theta), V' = w(x),
H constant; Te = H cos(theta) + V sin(theta). Scaled by the length l =
x_top and the force w l.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_bvp

import pipelay_fast as pf
from tests.helpers import weights

SLOPES = (-8.0, -4.0, 0.0, 4.0, 8.0)


def _case(name: str, slope: float, origin: float, **more):
    """The example ``name`` planar and inextensible, no current, no checks,
    on a seabed of ``slope`` [deg] through x = 0 at z = ``origin`` [m]."""
    return pf.load_case(name).with_changes({
        "environment.current.speed": 0.0, "checks": None, "pipe.extensible": False,
        "seabed.slope_deg": slope, "seabed.slope_origin": origin, **more})


def _rod(ell, beta):
    """The scaled rod's right-hand side: states (x, z, theta, m, v), scaled
    by l and w l; parameters (span length / l, h / (w l)); beta = w l^3 / EI;
    the span submerged (the weight uniform)."""
    def rhs(_t, y, p):
        span, h = p
        th, m, v = y[2], y[3], y[4]
        c, s = np.cos(th), np.sin(th)
        return np.vstack([span * s, span * c, span * beta * m, span * (h * s - v * c),
                          span * np.ones_like(th)])
    return rhs


def _guess(alpha, x0, z0, x1, z1, n=200):
    """A straight-line start from touchdown (x0, z0) to (x1, z1), scaled,
    with the seabed's angle at touchdown blended into the chord's."""
    t = np.linspace(0.0, 1.0, n)
    chord = math.atan2(x1 - x0, z1 - z0)
    th = alpha + (chord - alpha) * np.minimum(2.0 * t, 1.0)
    y = np.vstack([x0 + (x1 - x0) * t**1.5, z0 + (z1 - z0) * t, th, 0.0 * t,
                   np.tan(th)])
    return t, y, math.hypot(x1 - x0, z1 - z0)


def _touchdown_bc(ya, tan_a, alpha, z_o):
    """On the line, tangent to it, no moment (scaled)."""
    return [ya[0] - tan_a * (ya[1] - z_o), ya[2] - alpha, ya[3]]


def _answer(sol, ell, force, ei, beta):
    """Touchdown z [m], Te there [N], the peak sagbend moment [N m] (the
    largest positive M), the span's end z [m] and Te [N]."""
    t = np.linspace(0.0, 1.0, 20001)
    y = sol.sol(t)
    h = sol.p[1]

    def te(k):
        return force * (h * np.cos(y[2, k]) + y[4, k] * np.sin(y[2, k]))

    m = y[3] * force * ell
    return {"tdp_z": y[1, 0] * ell, "tdp_tension": te(0), "sag_moment": float(m.max()),
            "end_z": y[1, -1] * ell, "end_tension": te(-1)}


def jlay_reference(case):
    """The J-lay span of ``case`` (pinned top, top tension given, submerged)."""
    w, _ = weights(case)
    ei = case.pipe.bending_stiffness
    x_top, z_top = case.lay.top
    ell, force = x_top, w * x_top
    beta = w * ell**3 / ei
    alpha = math.radians(case.seabed.slope_deg)
    tan_a, z_o = math.tan(alpha), case.seabed.slope_origin / ell
    tt = case.lay.top_tension / force
    h0 = tt - 1.0  # the flat catenary's
    z_td = z_top / ell - h0 * math.acosh(1.0 + 1.0 / h0)
    t, y, length = _guess(alpha, tan_a * (z_td - z_o), z_td, 1.0, z_top / ell)

    def bc(ya, yb, p):
        te = p[1] * np.cos(yb[2]) + yb[4] * np.sin(yb[2])
        return np.array(_touchdown_bc(ya, tan_a, alpha, z_o)
                        + [yb[0] - 1.0, yb[1] - z_top / ell, yb[3], te - tt])

    sol = solve_bvp(_rod(ell, beta), bc, t, y, p=[length * 1.2, h0], tol=1e-9,
                    max_nodes=200000)
    assert sol.success, sol.message
    return _answer(sol, ell, force, ei, beta)


def slay_reference(case):
    """The S-lay span of ``case`` from touchdown to lift-off on the quadratic
    stinger (its tip clear), the top at the stinger's upper end (pinned, or
    held along the stinger's tangent)."""
    w, w_dry = weights(case)
    ei = case.pipe.bending_stiffness
    st = case.lay.stinger
    a, b, c = st.a, st.b, st.c
    depth = case.environment.water_depth
    x_u = st.upper[0]
    ell, force = x_u, w * x_u
    beta = w * ell**3 / ei
    alpha = math.radians(case.seabed.slope_deg)
    tan_a, z_o = math.tan(alpha), case.seabed.slope_origin / ell
    # the first integral Te + M^2/(2EI) - W(x), W(x) = int_0^x w dx, from the top: a
    # pinned one carries no moment, one held along the stinger its curvature's
    rise_u = w * depth + w_dry * (x_u - depth)
    fp_u = 2.0 * a * st.upper[1] + b
    m_u = 0.0 if case.lay.top_angle == "pinned" else ei * 2.0 * a / (1.0 + fp_u**2) ** 1.5
    const = (case.lay.top_tension + 0.5 * m_u**2 / ei - rise_u) / force
    z_tip, x_tip = st.lower[1], st.lower[0]
    h0 = const + x_tip
    z_td = z_tip / ell - h0 * math.acosh(1.0 + x_tip / ell / h0)
    t, y, length = _guess(alpha, tan_a * (z_td - z_o), z_td, x_tip / ell, z_tip / ell)

    def bc(ya, yb, p):
        z = yb[1] * ell
        fp = 2.0 * a * z + b
        kappa = 2.0 * a / (1.0 + fp * fp) ** 1.5
        te = p[1] * np.cos(yb[2]) + yb[4] * np.sin(yb[2])
        return np.array(_touchdown_bc(ya, tan_a, alpha, z_o)
                        + [yb[0] - ((a * z + b) * z + c) / ell, yb[2] - math.atan(fp),
                           yb[3] - ei * kappa / (force * ell),
                           te + 0.5 * yb[3] ** 2 * beta - yb[0] - const])

    sol = solve_bvp(_rod(ell, beta), bc, t, y, p=[length * 1.1, h0], tol=1e-9,
                    max_nodes=200000)
    assert sol.success, sol.message
    out = _answer(sol, ell, force, ei, beta)
    assert out["end_z"] > z_tip  # lift-off on the curve, the tip clear
    return out


def _engine(case):
    r = pf.solve(case)
    sm = r.summary
    assert sm["status"] == "ok"
    return sm


def _compare(sm, ref, lift: bool):
    """Relative differences of the engine's answer from the reference, and
    positions' differences [m]."""
    out = {"tdp_tension": sm["bottom_tension"] / ref["tdp_tension"] - 1.0,
           "sag_moment": sm["sagbend_max_moment"] / ref["sag_moment"] - 1.0,
           "tdp_z": sm["tdp_z"] - ref["tdp_z"]}
    if lift:
        out["liftoff_z"] = sm["liftoff_z"] - ref["end_z"]
    return out


@pytest.mark.parametrize("slope", SLOPES)
def test_jlay_on_a_slope_matches_the_elastica(slope):
    """J125 (its top submerged: water 150 m) on slopes from -8 to +8 deg
    through x = 0 at z = 134 m: the tension at touchdown and the sagbend's
    peak moment within 0.3 %, touchdown within 1 cm, of the reference."""
    case = _case("j125_2d", slope, 134.0, **{"environment.water_depth": 150.0})
    d = _compare(_engine(case), jlay_reference(case), lift=False)
    assert abs(d["tdp_tension"]) < 3e-3, d
    assert abs(d["sag_moment"]) < 3e-3, d
    assert abs(d["tdp_z"]) < 0.01, d


@pytest.mark.parametrize("slope", SLOPES)
def test_slay_on_a_slope_matches_the_elastica(slope):
    """S67 on slopes from -8 to +8 deg through x = 0 at z = 60 m: the
    tension at touchdown and the sagbend's peak moment within 0.3 %,
    touchdown and lift-off within 1 cm, of the reference."""
    case = _case("s67", slope, 60.0)
    d = _compare(_engine(case), slay_reference(case), lift=True)
    assert abs(d["tdp_tension"]) < 3e-3, d
    assert abs(d["sag_moment"]) < 3e-3, d
    assert abs(d["tdp_z"]) < 0.01, d
    assert abs(d["liftoff_z"]) < 0.01, d


@pytest.mark.parametrize(("name", "dimension"), [("j125_2d", "2d"), ("s67", "2d"),
                                                 ("s67", "3d")])
def test_slope_zero_is_the_flat_seabed_to_the_bit(name, dimension):
    """A seabed of slope 0 through any origin is the flat seabed: the same
    answer to the bit (its arithmetic reduces exactly: tan 0 = sin 0 = 0,
    cos 0 = 1)."""
    flat = pf.load_case(name).with_changes({"checks": None, "solver.dimension": dimension})
    zero = flat.with_changes({"seabed.slope_deg": 0.0, "seabed.slope_origin": 123.4})
    a, b = pf.solve(flat), pf.solve(zero)
    assert a.summary["status"] == "ok"
    for col, values in a.columns.items():
        assert np.array_equal(values, b.columns[col]), col
    for key, value in a.summary.items():
        if key not in ("case_id", "solve_seconds"):
            assert value == b.summary[key] or value != value, key  # (NaN: not applicable)


def test_the_seabed_line_under_the_pipe():
    """The laid pipe lies on the plane x = (z - z0) tan(alpha), touchdown
    too (the summary's ``tdp_x``, and ``seabed_depth_at_tdp`` the water
    depth less it), and the seabed's normal reaction over each laid node
    balances the pipe's weight per length's normal share, w cos(alpha), over
    the laid stretch (its nodes' reactions summed over their length,
    touchdown's node apart)."""
    case = _case("j125_2d", 6.0, 150.0)
    r = pf.solve(case)
    cols = r.columns
    tan_a = math.tan(math.radians(6.0))
    laid = np.asarray(cols["contact"]) == "seabed"
    x, z = np.asarray(cols["x"]), np.asarray(cols["z"])
    assert np.abs(x[laid] - (z[laid] - 150.0) * tan_a).max() < 1e-9
    sm = r.summary
    assert sm["tdp_x"] == pytest.approx((sm["tdp_z"] - 150.0) * tan_a, abs=1e-9)
    assert abs(sm["tdp_x"]) > 1.0  # (touchdown off the origin's level: the plane matters)
    assert sm["seabed_depth_at_tdp"] == pytest.approx(
        case.environment.water_depth - sm["tdp_x"], abs=1e-9)
    s = np.asarray(cols["s"])
    k = np.flatnonzero(laid)[1:-2]  # inner laid nodes, away from touchdown's reaction
    w, _ = weights(case)
    share = 0.5 * (s[k + 1] - s[k - 1])
    per_length = np.asarray(cols["seabed_reaction"])[k] / share
    assert per_length == pytest.approx(w * math.cos(math.radians(6.0)), rel=1e-6)


@pytest.mark.parametrize(("changes", "key"), [
    ({"seabed.slope_deg": 30.5}, "seabed.slope_deg"),
    ({"seabed.slope_deg": -31.0}, "seabed.slope_deg"),
    ({"seabed.slope_deg": float("nan")}, "seabed.slope_deg"),
    ({"seabed.slope_deg": "steep"}, "seabed.slope_deg"),
    ({"seabed.slope_deg": True}, "seabed.slope_deg"),
    ({"seabed.slope_origin": float("inf")}, "seabed.slope_origin"),
    ({"seabed.slope_deg": 5.0, "lay.top_tension": None, "lay.bottom_tension": 4e5},
     "lay.bottom_tension"),
    ({"seabed.slope_deg": 20.0, "seabed.slope_origin": 0.0}, "lay.top"),
])
def test_a_bad_slope_is_refused_naming_the_key(changes, key):
    """A slope beyond 30 deg either way, one that is not a finite number, a
    seabed above the vessel's top (J125's top (130, 440): 20 deg through
    z = 0 is at 160 m there), and what a slope does not support (a given
    bottom tension) are refused naming the key."""
    base = pf.load_case("j125_2d").with_changes({"environment.current.speed": 0.0})
    with pytest.raises(ValueError, match=key.replace(".", r"\.")):
        base.with_changes(changes)


def test_thirty_degrees_is_accepted():
    """The limit itself is a valid input."""
    case = pf.load_case("j125_2d").with_changes({"environment.current.speed": 0.0,
                                                 "seabed.slope_deg": -30.0})
    assert case.seabed.slope_deg == -30.0


@pytest.mark.parametrize(("name", "origin"), [("j125_2d", 134.0), ("s67", 60.0)])
@pytest.mark.parametrize("slope", [-6.0, 6.0])
def test_3d_without_lateral_load_is_the_plane_answer_on_a_slope(name, origin, slope):
    """In 3D with no lateral load the sloped seabed's answer is the planar
    one (the nodal frames turn x and z, y untouched): tension at touchdown,
    touchdown, the sagbend's peak moment and stress to 1e-9."""
    base = _case(name, slope, origin)
    a = _engine(base.with_changes({"solver.dimension": "2d"}))
    b = _engine(base.with_changes({"solver.dimension": "3d"}))
    for key in ("bottom_tension", "tdp_z", "sagbend_max_moment", "max_von_mises"):
        assert b[key] == pytest.approx(a[key], rel=1e-9), key

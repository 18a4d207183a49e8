"""Checks of the independent reference solutions in ``tests/reference``.

The package's results are compared against these references, so they are
verified here against closed forms, asymptotics, global equilibrium and an
independent integrator. Run with ``-s`` to print the J125 numbers.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad, simpson, solve_ivp

from tests.reference.catenary import (
    catenary_profile,
    natural_catenary,
    natural_catenary_two_weights,
)
from tests.reference.elastica import jlay_elastica

# ---------------------------------------------------------------- the paper's pipe
from tests.reference.paper import EI, W_DRY, W_SUB

EI_REAL = EI
EI_TINY = 1e-6 * 2.59e8  # [N m^2]: flexural length ~ 2.5 cm
DEPTH, X_TOP, Z_TOP = 125.0, 130.0, 440.0  # J125 hang-off 5 m above the water

J125_CASES = {
    "T_top=580kN pinned": {"T_top": 580e3},
    "T_bottom=150kN pinned": {"T_bottom": 150e3},
    "T_bottom=20kN pinned": {"T_bottom": 20e3},
    "T_bottom=100kN top 90deg": {"T_bottom": 100e3, "top_angle_deg": 90.0},
}


def weight_rise(x):
    """int_0^x w dx [N]."""
    return W_SUB * min(x, DEPTH) + W_DRY * max(x - DEPTH, 0.0)


@pytest.fixture(scope="module")
def j125():
    return {
        name: jlay_elastica(EI_REAL, W_SUB, W_DRY, DEPTH, X_TOP, Z_TOP, **kw)
        for name, kw in J125_CASES.items()
    }


# ---------------------------------------------------------------- natural catenary
CATENARY_TABLE = [  # (w [N/m], x_top [m], T_bottom [N]); slack, moderate, near-taut
    (1243.0, 130.0, 5e3),
    (1243.0, 125.0, 398.5e3),
    (500.0, 67.0, 2e6),
    (80.0, 1000.0, 1e4),
]


@pytest.mark.parametrize(("w", "x_top", "H"), CATENARY_TABLE)
def test_natural_catenary_identities(w, x_top, H):
    c = natural_catenary(w, x_top, T_bottom=H)
    a = H / w
    assert c["H"] == H
    assert c["T_top"] == pytest.approx(H + w * x_top, rel=1e-14)
    L, span = c["suspended_length"], c["horizontal_span"]
    assert L**2 == pytest.approx(x_top**2 + 2 * x_top * a, rel=1e-12)
    assert x_top == pytest.approx(a * (math.cosh(span / a) - 1), rel=1e-10)
    assert L == pytest.approx(a * math.sinh(span / a), rel=1e-10)
    assert math.tan(math.radians(c["top_angle_deg"])) == pytest.approx(L / a, rel=1e-10)
    # top tension = H / cos(top angle) for a cable
    assert c["T_top"] == pytest.approx(H / math.cos(math.radians(c["top_angle_deg"])), rel=1e-10)
    back = natural_catenary(w, x_top, T_top=c["T_top"])
    for key in ("H", "suspended_length", "horizontal_span", "top_angle_deg"):
        assert back[key] == pytest.approx(c[key], rel=1e-10)


def test_natural_catenary_refuses_bad_input():
    with pytest.raises(ValueError):
        natural_catenary(1.0, 10.0)
    with pytest.raises(ValueError):
        natural_catenary(1.0, 10.0, T_top=5.0, T_bottom=1.0)
    with pytest.raises(ValueError):
        natural_catenary(1.0, 10.0, T_top=9.0)  # H = T_top - w x_top < 0


@pytest.mark.parametrize("H", [20e3, 150e3, 398.5e3])
def test_two_weights_against_quadrature(H):
    """Independent route: a cable has Fz = H, Fx(s) = int_0^s w ds, tan(theta) =
    Fx / H; integrate sin/cos theta numerically to the surface and the top."""
    c = natural_catenary_two_weights(W_SUB, W_DRY, DEPTH, X_TOP, T_bottom=H)
    L1, L = c["surface_length"], c["suspended_length"]

    def theta(s):
        Fx = W_SUB * s if s <= L1 else W_SUB * L1 + W_DRY * (s - L1)
        return math.atan2(Fx, H)

    def integral(f, a, b):
        return quad(lambda s: f(theta(s)), a, b, epsabs=0, epsrel=1e-13, limit=200)[0]

    assert integral(math.sin, 0, L1) == pytest.approx(DEPTH, rel=1e-11)
    assert integral(math.cos, 0, L1) == pytest.approx(c["surface_span"], rel=1e-11)
    assert DEPTH + integral(math.sin, L1, L) == pytest.approx(X_TOP, rel=1e-11)
    assert c["surface_span"] + integral(math.cos, L1, L) == pytest.approx(
        c["horizontal_span"], rel=1e-11
    )
    assert c["T_top"] == pytest.approx(H + weight_rise(X_TOP), rel=1e-14)
    assert c["T_top"] == pytest.approx(H / math.cos(math.radians(c["top_angle_deg"])), rel=1e-10)
    back = natural_catenary_two_weights(W_SUB, W_DRY, DEPTH, X_TOP, T_top=c["T_top"])
    for key in ("H", "suspended_length", "horizontal_span", "top_angle_deg"):
        assert back[key] == pytest.approx(c[key], rel=1e-10)


def test_two_weights_reduce_to_one():
    for x_top in (130.0, 125.0, 60.0):  # above, at and below the surface
        one = natural_catenary(W_SUB, x_top, T_bottom=1e5)
        two = natural_catenary_two_weights(W_SUB, W_SUB, DEPTH, x_top, T_bottom=1e5)
        for key in ("H", "T_top", "suspended_length", "horizontal_span", "top_angle_deg"):
            assert two[key] == pytest.approx(one[key], rel=1e-12)
    # a top under water ignores w_dry
    under = natural_catenary_two_weights(W_SUB, W_DRY, DEPTH, 100.0, T_top=3e5)
    assert under["H"] == pytest.approx(natural_catenary(W_SUB, 100.0, T_top=3e5)["H"])


def test_two_weights_continuity_at_surface():
    H = 150e3
    c = natural_catenary_two_weights(W_SUB, W_DRY, DEPTH, X_TOP, T_bottom=H)
    L1, h = c["surface_length"], 1e-3
    p = catenary_profile(W_SUB, W_DRY, DEPTH, H, L1 + h * np.arange(-2.0, 3.0))
    assert p["x"][2] == pytest.approx(DEPTH, rel=1e-12)
    assert p["z"][2] == pytest.approx(c["surface_span"], rel=1e-12)

    def one_sided(i):  # dx/dz between points 2 and i
        return (p["x"][i] - p["x"][2]) / (p["z"][i] - p["z"][2])

    # one-sided differences, Richardson-extrapolated (error O(h^2 kappa^2))
    slope_below = 2 * one_sided(1) - one_sided(0)
    slope_above = 2 * one_sided(3) - one_sided(4)
    surface = math.tan(math.radians(c["surface_angle_deg"]))
    assert slope_below == pytest.approx(surface, abs=1e-8)
    assert slope_above == pytest.approx(surface, abs=1e-8)
    # ... whereas the curvature jumps by the weight ratio (kappa = w cos^2(theta) / H)
    curv = catenary_profile(W_SUB, W_DRY, DEPTH, H, L1 + 1e-9 * np.array([-1.0, 1.0]))
    assert curv["curvature"][1] / curv["curvature"][0] == pytest.approx(W_DRY / W_SUB, rel=1e-6)
    # tension follows T(x) = H + int w dx along the profile
    s = np.linspace(0.0, c["suspended_length"], 50)
    prof = catenary_profile(W_SUB, W_DRY, DEPTH, H, s)
    expected = [H + weight_rise(x) for x in prof["x"]]
    np.testing.assert_allclose(prof["tension"], expected, rtol=1e-10)
    assert prof["x"][-1] == pytest.approx(X_TOP, rel=1e-12)


# ---------------------------------------------------------------- elastica
@pytest.mark.parametrize("tension", [{"T_top": 580e3}, {"T_bottom": 150e3}])
def test_elastica_small_EI_is_the_catenary(tension):
    """EI -> 0: the elastica is the catenary plus boundary layers of the flexural
    length. At the TDP (tension H) the outer catenary's vertex sits lam_b =
    sqrt(EI/H) beyond the real TDP; at the pinned top (tension T_top) the moment
    falls to zero over lam_t = sqrt(EI/T_top), turning the tangent back by
    kappa_top * lam_t. Raw agreement is O(lam/L) ~ 1e-4; with these first-order
    corrections it is O(lam^2)."""
    e = jlay_elastica(EI_TINY, W_SUB, W_DRY, DEPTH, X_TOP, Z_TOP, **tension)
    c = natural_catenary_two_weights(W_SUB, W_DRY, DEPTH, X_TOP, **tension)
    H = c["H"]
    tdp_cat = Z_TOP - c["horizontal_span"]
    assert e["bottom_tension"] == pytest.approx(H, rel=1e-9)
    assert e["top_tension"] == pytest.approx(c["T_top"], rel=1e-9)
    assert e["tdp_z"] == pytest.approx(tdp_cat, rel=3e-4)
    assert e["suspended_length"] == pytest.approx(c["suspended_length"], rel=3e-4)
    assert e["top_angle_deg"] == pytest.approx(c["top_angle_deg"], rel=3e-4)

    lam_b, lam_t = math.sqrt(EI_TINY / H), math.sqrt(EI_TINY / c["T_top"])
    kappa_top = math.cos(math.radians(c["top_angle_deg"])) ** 2 * W_DRY / H
    assert e["tdp_z"] == pytest.approx(tdp_cat - lam_b, abs=1e-4)
    assert e["suspended_length"] == pytest.approx(c["suspended_length"] + lam_b, abs=1e-4)
    top_corrected = c["top_angle_deg"] - math.degrees(kappa_top * lam_t)
    assert e["top_angle_deg"] == pytest.approx(top_corrected, abs=1e-5)

    # away from the layers: theta and M = EI * kappa of the shifted catenary
    L, L1 = e["suspended_length"], e["surface_length"]
    s = np.concatenate([np.linspace(1.0, L1 - 1.0, 40), np.linspace(L1 + 1.0, L - 1.0, 10)])
    p = e["profile"](s)
    cat = catenary_profile(W_SUB, W_DRY, DEPTH, H, s - lam_b)
    np.testing.assert_allclose(np.radians(p["theta_deg"]), cat["theta"], atol=1e-6)
    np.testing.assert_allclose(p["moment"], EI_TINY * cat["curvature"], rtol=1e-4)
    assert np.all(p["moment"] > 0)  # sagging: concave up, positive moment


def _segments(e):
    """(start, end, w) of the wet and dry stretches [m, m, N/m]."""
    L, L1 = e["suspended_length"], e["surface_length"]
    return [(0.0, L1, W_SUB), (L1, L, W_DRY)]


def _dense(e, n=4001):
    """Profile on a dense grid per segment (odd count, for Simpson)."""
    return [(e["profile"](np.linspace(a, b, n)), w) for a, b, w in _segments(e)]


def _check_elastica(e, kw):
    L = e["suspended_length"]
    M_scale = max(e["max_moment"], 1.0)
    # geometry and end conditions
    assert e["x"][0] == pytest.approx(0.0, abs=1e-9)
    assert e["z"][0] == pytest.approx(e["tdp_z"], abs=1e-9)
    assert e["x"][-1] == pytest.approx(X_TOP, rel=1e-9)
    assert e["z"][-1] == pytest.approx(Z_TOP, rel=1e-12)
    assert e["moment"][0] == pytest.approx(0.0, abs=1e-8 * M_scale)
    assert e["s"][-1] == pytest.approx(L, rel=1e-14)
    assert np.all(e["x"][1:] > 0.0)  # the span never dips into the seabed
    if "top_angle_deg" in kw:
        assert e["top_angle_deg"] == pytest.approx(kw["top_angle_deg"], abs=1e-7)
    else:
        assert e["top_moment"] == pytest.approx(0.0, abs=1e-8 * M_scale)
    if "T_top" in kw:
        assert e["top_tension"] == pytest.approx(kw["T_top"], rel=1e-9)
    else:
        assert e["bottom_tension"] == pytest.approx(kw["T_bottom"], rel=1e-12)
    # unit tangent: dx/ds = sin theta, dz/ds = cos theta (inextensible)
    for p, _ in _dense(e):
        th = np.radians(p["theta_deg"])
        np.testing.assert_allclose(np.gradient(p["x"], p["s"])[1:-1], np.sin(th)[1:-1], atol=1e-6)
        np.testing.assert_allclose(np.gradient(p["z"], p["s"])[1:-1], np.cos(th)[1:-1], atol=1e-6)
    # EI theta' = M, in integral form: theta(s) - theta(0) = int_0^s M / EI ds
    for p, _ in _dense(e):
        rise = simpson(p["moment"], x=p["s"]) / EI_REAL
        th = np.radians(p["theta_deg"])
        assert th[-1] - th[0] == pytest.approx(rise, abs=1e-8)
    # global vertical equilibrium: Fx(L) - Fx(0) = int w ds
    weight = sum(w * (b - a) for a, b, w in _segments(e))
    vertical = e["top_vertical_force"] + e["seabed_reaction"]  # Fx(L) - Fx(0)
    assert vertical == pytest.approx(weight, rel=1e-8)
    assert e["seabed_reaction"] >= 0.0  # Fx(0) <= 0: the seabed pushes up
    # global moment equilibrium of the suspended span about the TDP:
    # M(L) - M(0) + z_L Fx(L) - x_L Fz - int w (z - z_tdp) ds = 0
    moment_of_weight = sum(simpson(w * (p["z"] - e["tdp_z"]), x=p["s"]) for p, w in _dense(e))
    zL = Z_TOP - e["tdp_z"]
    balance = (
        e["top_moment"]
        + zL * e["top_vertical_force"]
        - X_TOP * e["bottom_tension"]
        - moment_of_weight
    )
    assert abs(balance) < 1e-8 * (zL * e["top_vertical_force"])
    # Te(L) = T_bottom + int_0^x_top w dx - M(L)^2 / (2 EI)  (exact for the elastica)
    expected_top = e["bottom_tension"] + weight_rise(X_TOP) - e["top_moment"] ** 2 / (2 * EI_REAL)
    assert e["top_tension"] == pytest.approx(expected_top, rel=1e-8)
    # the sagbend peak is a stationary point of M (zero shear) ...
    assert e["max_moment"] == pytest.approx(max(e["sagbend_moment"], abs(e["top_moment"])))
    assert e["sagbend_moment"] > 0.0
    if "top_angle_deg" in kw:  # ... a clamped top may carry the largest moment
        assert e["max_moment"] >= e["sagbend_moment"]
    else:  # ... and with a pinned top it is the largest |M| of the span
        assert e["sagbend_moment"] >= np.max(np.abs(e["moment"])) * (1 - 1e-12)


def _ode(w, Fz):
    def f(s, y):
        x, z, th, M, Fx = y
        return [math.sin(th), math.cos(th), M / EI_REAL, Fz * math.sin(th) - Fx * math.cos(th), w]

    return f


def _check_against_ivp(e, n_blocks=30):
    """Independent integrator: from the BVP state at the start of each block,
    integrate the ODE with DOP853 to the block's end and compare (blocks are much
    shorter than the flexural length, so shooting is well conditioned there)."""
    Fz = e["bottom_tension"]
    for a, b, w in _segments(e):
        edges = np.linspace(a, b, n_blocks + 1)
        p = e["profile"](edges)
        Y = np.vstack([p["x"], p["z"], np.radians(p["theta_deg"]), p["moment"], p["Fx"]])
        for i in range(n_blocks):
            r = solve_ivp(
                _ode(w, Fz), (edges[i], edges[i + 1]), Y[:, i], method="DOP853",
                rtol=1e-12, atol=1e-12,
            )
            end = r.y[:, -1]
            np.testing.assert_allclose(end[:3], Y[:3, i + 1], atol=1e-7)
            assert end[3] == pytest.approx(Y[3, i + 1], abs=1e-7 * e["max_moment"])
            assert end[4] == pytest.approx(Y[4, i + 1], abs=1e-9 * e["top_vertical_force"])


@pytest.mark.parametrize("name", list(J125_CASES))
def test_j125_elastica(j125, name):
    e, kw = j125[name], J125_CASES[name]
    _check_elastica(e, kw)
    _check_against_ivp(e)
    flex = math.sqrt(EI_REAL / e["bottom_tension"])
    print(
        f"\nJ125 {name}: tdp_z = {e['tdp_z']:.4f} m, top angle = {e['top_angle_deg']:.4f} deg,"
        f" max |M| = {e['max_moment'] / 1e3:.3f} kN m (sagbend {e['sagbend_moment'] / 1e3:.3f},"
        f" top {e['top_moment'] / 1e3:.3f}), suspended length = {e['suspended_length']:.4f} m,"
        f" T_bottom = {e['bottom_tension'] / 1e3:.4f} kN, T_top = {e['top_tension'] / 1e3:.4f} kN,"
        f" TDP reaction = {e['seabed_reaction'] / 1e3:.4f} kN, sqrt(EI/T_b) = {flex:.1f} m"
    )


def test_j125_bending_stiffens_the_span(j125):
    """Real EI vs the catenary: the TDP moves away from the vessel and the span
    lengthens; for 20 kN the flexural length ~ 113 m is comparable to the depth."""
    for name, kw in J125_CASES.items():
        if "top_angle_deg" in kw:
            continue
        e = j125[name]
        c = natural_catenary_two_weights(W_SUB, W_DRY, DEPTH, X_TOP, **kw)
        assert e["tdp_z"] < Z_TOP - c["horizontal_span"]
        assert e["suspended_length"] > c["suspended_length"]
        assert e["top_tension"] == pytest.approx(c["T_top"], rel=1e-9)  # pinned: exact
    assert math.sqrt(EI_REAL / 20e3) == pytest.approx(113.4, abs=0.1)


def test_j125_top_or_bottom_tension_same_solution(j125):
    e = j125["T_top=580kN pinned"]
    f = jlay_elastica(EI_REAL, W_SUB, W_DRY, DEPTH, X_TOP, Z_TOP, T_bottom=e["bottom_tension"])
    for key in ("tdp_z", "suspended_length", "top_angle_deg", "max_moment", "top_tension"):
        assert f[key] == pytest.approx(e[key], rel=1e-8)


@pytest.mark.parametrize("name", ["T_top=580kN pinned", "T_bottom=100kN top 90deg"])
def test_j125_tolerance_converged(j125, name):
    """The answers do not move when the collocation tolerance is tightened."""
    e = j125[name]
    f = jlay_elastica(EI_REAL, W_SUB, W_DRY, DEPTH, X_TOP, Z_TOP, tol=1e-10, **J125_CASES[name])
    for key in ("tdp_z", "suspended_length", "top_angle_deg", "max_moment", "top_tension"):
        assert f[key] == pytest.approx(e[key], rel=2e-8)


def test_elastica_top_under_water_single_segment():
    """Top below the surface: one weight; small EI again gives the catenary."""
    e = jlay_elastica(EI_TINY, W_SUB, W_DRY, DEPTH, 100.0, 400.0, T_bottom=150e3)
    c = natural_catenary(W_SUB, 100.0, T_bottom=150e3)
    assert e["surface_length"] is None
    lam = math.sqrt(EI_TINY / 150e3)
    assert e["tdp_z"] == pytest.approx(400.0 - c["horizontal_span"] - lam, abs=1e-4)
    assert e["top_tension"] == pytest.approx(c["T_top"], rel=1e-9)
    assert e["seabed_reaction"] >= 0.0


def test_elastica_refuses_bad_input():
    with pytest.raises(ValueError):
        jlay_elastica(EI_REAL, W_SUB, W_DRY, DEPTH, X_TOP, Z_TOP)

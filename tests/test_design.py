"""Lay design answers in the summary: layback, touchdown tension, departure
angle, tip clearance, peak strains and the DNV-ST-F101 utilisations, each
against numbers obtained independently (the elastica references, the profile's
nodes with a Hermite interpolation written here, the standard's equations
evaluated here with the collapse pressure from ``numpy.roots``)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

import pipelay_fast as pf
from tests.helpers import EXAMPLES, elastica_for, slay_elastica_for

CHECKS = {"checks.overbend_strain_limit": 0.0025, "checks.ovality": 0.01,
          "checks.fabrication": "UOE", "checks.current_load": "functional", "pipe.smts": 531e6}
DESIGN = ("layback", "tip_clearance", "departure_angle_deg", "tdp_tension",
          "overbend_max_strain", "sagbend_max_strain", "overbend_strain_utilisation",
          "sagbend_lcc_utilisation", "sagbend_lcc_axial_ratio", "max_utilisation")


@pytest.fixture(scope="module")
def s67():
    """S67 in still water, inextensible (as the planar elastica), no [checks]."""
    return pf.load_case(EXAMPLES / "s67.toml").with_changes(
        {"environment.current.speed": 0.0, "pipe.extensible": False, "checks": None})


@pytest.fixture(scope="module")
def j125_stiff():
    return pf.load_case(EXAMPLES / "j125.toml").with_changes(
        {"pipe.extensible": False, "checks": None})


@pytest.mark.parametrize("a", [-0.0012, -0.0009])
def test_slay_layback_tension_angle_match_elastica(s67, a):
    """Lift-off (a = -0.0012) and tip regime (-0.0009): layback to the
    reference touchdown within 5 cm, touchdown tension (the reference's
    bottom tension: no axial friction) to 1e-4, departure angle (at lift-off
    or the tip) within 0.05 deg."""
    case = s67.with_changes({"lay.stinger.a": a})
    ref = slay_elastica_for(case)
    sm = pf.solve(case).summary
    z_top = case.lay.stinger.upper[1]
    assert abs(sm["layback"] - (z_top - ref["tdp_z"])) < 0.05
    assert sm["layback"] == pytest.approx(z_top - sm["tdp_z"], abs=1e-9)
    assert sm["tdp_tension"] == pytest.approx(ref["bottom_tension"], rel=1e-4)
    assert abs(sm["departure_angle_deg"] - ref["liftoff_angle_deg"]) < 0.05


def test_jlay_layback_tension_angle_match_elastica(j125_stiff):
    """J125: layback from the hang-off to the reference touchdown within 5 cm,
    touchdown tension to 1e-4, departure angle (the hang-off's) within 0.05
    deg; no stinger, so no tip clearance and no overbend."""
    ref = elastica_for(j125_stiff, T_top=j125_stiff.lay.top_tension)
    sm = pf.solve(j125_stiff).summary
    z_top = j125_stiff.lay.top[1]
    assert abs(sm["layback"] - (z_top - ref["tdp_z"])) < 0.05
    assert sm["tdp_tension"] == pytest.approx(ref["bottom_tension"], rel=1e-4)
    assert abs(sm["departure_angle_deg"] - ref["top_angle_deg"]) < 0.05
    assert math.isnan(sm["tip_clearance"]) and math.isnan(sm["overbend_max_strain"])
    assert sm["sagbend_max_strain"] > 0.0


def test_no_checks_leaves_utilisations_nan(s67):
    sm = pf.solve(s67).summary
    for key in ("overbend_strain_utilisation", "sagbend_lcc_utilisation",
                "sagbend_lcc_axial_ratio", "max_utilisation"):
        assert math.isnan(sm[key]), key
    assert set(DESIGN) <= set(pf.output.results.SUMMARY_UNITS)


def test_tip_clearance_zero_when_bearing(s67):
    sm = pf.solve(s67.with_changes({"lay.stinger.a": -0.0009})).summary
    assert sm["tip_reaction"] > 0.0
    assert sm["tip_clearance"] == 0.0


def _hermite(p, k, xi):
    """Cubic Hermite of the profile's nodes k, k+1 at xi: (point, tangent) in
    (x, z), the slopes from the nodal angle (|r'| = 1, inextensible)."""
    s = p["s"].to_numpy()
    th = np.radians(p["angle_deg"].to_numpy())
    pos = np.stack([p["x"].to_numpy(), p["z"].to_numpy()], axis=1)
    slope = np.stack([np.sin(th), np.cos(th)], axis=1)
    h = s[k + 1] - s[k]
    n = [2 * xi**3 - 3 * xi**2 + 1, xi**3 - 2 * xi**2 + xi, -2 * xi**3 + 3 * xi**2, xi**3 - xi**2]
    dn = [6 * xi**2 - 6 * xi, 3 * xi**2 - 4 * xi + 1, -6 * xi**2 + 6 * xi, 3 * xi**2 - 2 * xi]
    point = n[0] * pos[k] + h * n[1] * slope[k] + n[2] * pos[k + 1] + h * n[3] * slope[k + 1]
    tangent = (dn[0] * pos[k] + h * dn[1] * slope[k] + dn[2] * pos[k + 1]) / h \
        + dn[3] * slope[k + 1]
    return point, tangent


def _normal_distance(profile, tip):
    """Distance from ``tip`` to the centreline at the foot of its normal:
    the root of (r - tip) . r' = 0 on the element where it changes sign."""
    best = math.inf
    for k in range(len(profile) - 1):
        def foot(xi, k=k):
            point, tangent = _hermite(profile, k, xi)
            return float((point - tip) @ tangent)
        if foot(0.0) * foot(1.0) <= 0.0:
            xi = brentq(foot, 0.0, 1.0, xtol=1e-14)
            best = min(best, float(np.linalg.norm(_hermite(profile, k, xi)[0] - tip)))
    return best


@pytest.mark.parametrize("a", [-0.0012, -0.0014, -0.0019])
def test_tip_clearance_is_normal_distance_to_centreline(s67, a):
    case = s67.with_changes({"lay.stinger.a": a})
    result = pf.solve(case)
    assert result.summary["tip_reaction"] == 0.0
    expected = _normal_distance(result.profile, np.array(case.lay.stinger.lower))
    assert result.summary["tip_clearance"] == pytest.approx(expected, rel=1e-6, abs=1e-12)


def test_tip_clearance_grows_as_cube_of_liftoff_distance(s67):
    """The pipe leaves the stinger with its position, slope and curvature,
    so its gap grows as the cube of the distance from lift-off: the slope
    of log(clearance) against log(liftoff_z - z_tip) is 3."""
    a_values = [-0.0012, -0.0013, -0.0014, -0.0016]
    rows = [pf.solve(s67.with_changes({"lay.stinger.a": a})).summary for a in a_values]
    dist = np.array([r["liftoff_z"] - s67.lay.stinger.lower[1] for r in rows])
    clearance = np.array([r["tip_clearance"] for r in rows])
    slope = np.polyfit(np.log(dist), np.log(clearance), 1)[0]
    assert slope == pytest.approx(3.0, abs=0.1)


def _collapse_by_roots(d, t, e, nu, fy, alpha_fab, f0):
    """p_c [Pa]: the real root of DNV-ST-F101 eq. 5.11's cubic in (0, p_p)."""
    p_el = 2 * e * (t / d) ** 3 / (1 - nu**2)
    p_p = fy * alpha_fab * 2 * t / d
    roots = np.roots([1.0, -p_el, -(p_p**2 + p_el * p_p * f0 * d / t), p_el * p_p**2])
    real = roots[np.abs(roots.imag) < 1e-6 * abs(roots).max()].real
    (p_c,) = real[(real > 0) & (real < min(p_el, p_p))]
    return p_c


def _lcc_by_hand(p, m_sd, s_sd, contents_density=0.0, contents_level=0.0):
    """DNVGL-ST-F101's load-controlled combined-loading criterion for the
    paper's pipe in 67 m of water (SMYS 448 MPa, SMTS 531 MPa), per node of
    the profile ``p`` with design moment ``m_sd`` and effective force
    ``s_sd``: the external-overpressure form (p_min the contents pressure)
    where p_e >= p_i, the internal-overpressure form elsewhere."""
    d, di, e, nu = 0.61, 0.58, 207e9, 0.3
    t = (d - di) / 2
    fy, fu = 448e6 * 0.96, 531e6 * 0.96
    beta = (60 - d / t) / 90  # 15 <= D/t = 40.7 <= 60
    alpha_c = (1 - beta) + beta * fu / fy
    m_p, s_p = fy * (d - t) ** 2 * t, fy * math.pi * (d - t) * t
    p_c = _collapse_by_roots(d, t, e, nu, fy, 0.85, 0.01)
    p_b = 2 * t / (d - t) * min(fy, fu / 1.15) * 2 / math.sqrt(3)
    g = 1.15 * 1.04
    x = p["x"].to_numpy()
    p_e = 1025.0 * 9.81 * np.clip(67.0 - x, 0.0, None)
    p_i = contents_density * 9.81 * np.clip(contents_level - x, 0.0, None)
    bend = (g * np.abs(m_sd) / (alpha_c * m_p) + (g * s_sd / (alpha_c * s_p)) ** 2) ** 2
    ratio = (p_i - p_e) / p_b
    alpha_p = np.where(ratio < 2 / 3, 1 - beta, 1 - 3 * beta * (1 - ratio))
    return np.where(p_e >= p_i, bend + (g * (p_e - p_i) / p_c) ** 2,
                    bend + (alpha_p * ratio / alpha_c) ** 2)


def _sagbend(sm, p):
    s = p["s"].to_numpy()
    beyond = s >= np.interp(sm["tdp_z"], p["z"], p["s"])
    hog = beyond & (p["moment_y"].to_numpy() < 0)
    return beyond & ~hog & (s <= np.interp(sm["liftoff_z"], p["z"], p["s"]))


# DNVGL-ST-F101 Table 4-4, ULS load effect factor combinations (gamma_F, gamma_E)
COMBINATIONS = ((1.2, 0.7), (1.1, 1.3))


def test_current_factored_as_environmental_by_hand():
    """The default current_load: the functional effects are those of the
    case without current (solved here), matched by length from the top; the
    design moment gamma_F gamma_c M_F + gamma_E (M - M_F) and the same for
    the effective force, for combinations a (1.2, 0.7) and b (1.1, 1.3),
    node by node the larger. Under combination b alone the current raises
    the utilisation more than factoring it as functional does (gamma_E 1.3
    above gamma_F 1.1)."""
    case = pf.load_case(EXAMPLES / "s67.toml").with_changes(
        {**CHECKS, "checks.current_load": None})
    assert case.checks.current_load == "environmental"
    sm, p = (lambda r: (r.summary, r.profile))(pf.solve(case))
    still = pf.solve(case.with_changes({"environment.current": None})).profile
    from_top, still_from_top = p["s"].iloc[-1] - p["s"], still["s"].iloc[-1] - still["s"]
    m_f = np.interp(from_top, still_from_top[::-1], still["moment_y"][::-1])
    t_f = np.interp(from_top, still_from_top[::-1], still["effective_tension"][::-1])
    m = p["moment_y"].to_numpy()
    te = p["effective_tension"].to_numpy()
    lcc = np.max([_lcc_by_hand(p, g_f * m_f + g_e * (m - m_f), g_f * t_f + g_e * (te - t_f))
                  for g_f, g_e in COMBINATIONS], axis=0)
    sag = _sagbend(sm, p)
    assert sm["sagbend_lcc_utilisation"] == pytest.approx(lcc[sag].max(), rel=1e-9)
    only_b = case.with_changes({"checks.gamma_F": 1.1, "checks.gamma_E": 1.3})
    environmental = pf.solve(only_b).summary
    functional = pf.solve(only_b.with_changes({"checks.current_load": "functional"})).summary
    assert environmental["sagbend_lcc_utilisation"] > functional["sagbend_lcc_utilisation"]


def test_strain_and_lcc_utilisation_by_hand():
    """S67 with its current, lifting off: the overbend strain utilisation and
    the sagbend LCC utilisation evaluated here, node by node, from the
    profile and the inputs: DNVGL-ST-F101's external-overpressure form,
    gamma_m = 1.15, gamma_SC = 1.04 (low), gamma_c = 1, alpha_U = 0.96,
    alpha_fab = 0.85 (UOE), f0 = 0.01, t2 = t; everything functional, so of
    combinations a (gamma_F = 1.2) and b (1.1) a governs; given the pair
    (1.1, 1.3), b alone is checked."""
    case = pf.load_case(EXAMPLES / "s67.toml").with_changes(CHECKS)
    result = pf.solve(case)
    sm, p = result.summary, result.profile
    d, di = 0.61, 0.58
    t = (d - di) / 2
    e = 207e9
    area = math.pi * (d**2 - di**2) / 4
    s_tdp = np.interp(sm["tdp_z"], p["z"], p["s"])
    beyond = p["s"].to_numpy() >= s_tdp
    hog = beyond & (p["moment_y"].to_numpy() < 0)
    s_lo = np.interp(sm["liftoff_z"], p["z"], p["s"])
    sag = beyond & ~hog & (p["s"].to_numpy() <= s_lo)
    strain = np.abs(p["wall_tension"].to_numpy()) / (e * area) \
        + p["curvature"].to_numpy() * d / 2
    assert sm["overbend_max_strain"] == pytest.approx(strain[hog].max(), rel=1e-12)
    assert sm["sagbend_max_strain"] == pytest.approx(strain[sag].max(), rel=1e-12)
    assert sm["overbend_strain_utilisation"] == pytest.approx(strain[hog].max() / 0.0025,
                                                              rel=1e-12)
    by_factor = {g_f: _lcc_by_hand(p, g_f * 1.0 * p["moment"].to_numpy(),
                                   g_f * 1.0 * p["effective_tension"].to_numpy())
                 for g_f, _ in COMBINATIONS}
    lcc = np.maximum(by_factor[1.2], by_factor[1.1])
    assert sm["sagbend_lcc_utilisation"] == pytest.approx(lcc[sag].max(), rel=1e-9)
    assert sm["sagbend_lcc_utilisation"] == pytest.approx(by_factor[1.2][sag].max(), rel=1e-9)
    # |S_Sd|/S_p at the peak, S_p = f_y pi (D - t) t: well inside the stated 0.4
    peak = np.flatnonzero(sag)[np.argmax(lcc[sag])]
    s_p = 448e6 * 0.96 * math.pi * (d - t) * t
    axial = 1.2 * abs(p["effective_tension"].to_numpy()[peak]) / s_p
    assert sm["sagbend_lcc_axial_ratio"] == pytest.approx(axial, rel=1e-9)
    assert 0.0 < sm["sagbend_lcc_axial_ratio"] < 0.4
    only_b = pf.solve(case.with_changes({"checks.gamma_F": 1.1, "checks.gamma_E": 1.3})).summary
    assert only_b["sagbend_lcc_utilisation"] == pytest.approx(by_factor[1.1][sag].max(),
                                                              rel=1e-9)
    assert sm["max_utilisation"] == max(sm["overbend_strain_utilisation"],
                                        sm["sagbend_lcc_utilisation"])
    assert 0.0 < sm["sagbend_lcc_utilisation"] < 1.0


def test_lcc_under_internal_overpressure_by_hand():
    """S67 with contents of 100 kg/m3 whose free surface stands 700 m above
    the sea (a pressurised pipe): the contents pressure exceeds the external
    one all along, so every sagbend section takes the internal-overpressure
    form, evaluated here node by node from the profile; the pressure term
    raises the utilisation above the bending part alone."""
    contents = {"pipe.contents_density": 100.0, "pipe.contents_level": 767.0}
    case = pf.load_case(EXAMPLES / "s67.toml").with_changes({**CHECKS, **contents})
    result = pf.solve(case)
    sm, p = result.summary, result.profile
    x = p["x"].to_numpy()
    assert np.all(100.0 * (767.0 - x) > 1025.0 * np.clip(67.0 - x, 0.0, None))
    m, te = p["moment"].to_numpy(), p["effective_tension"].to_numpy()
    lcc = np.maximum(*(_lcc_by_hand(p, g_f * m, g_f * te, 100.0, 767.0)
                       for g_f, _ in COMBINATIONS))
    sag = _sagbend(sm, p)
    assert sm["sagbend_lcc_utilisation"] == pytest.approx(lcc[sag].max(), rel=1e-9)
    bending_only = _lcc_by_hand(p, 1.2 * m, 1.2 * te, 1025.0, 67.0)  # flooded: p_i = p_e
    assert sm["sagbend_lcc_utilisation"] > bending_only[sag].max() > 0.0


def test_jlay_lcc_is_interior_peak():
    """J125 with checks: no overbend strain utilisation; the sagbend LCC
    utilisation is the span's largest, here not at an end."""
    case = pf.load_case(EXAMPLES / "j125.toml").with_changes(CHECKS)
    sm = pf.solve(case).summary
    assert math.isnan(sm["overbend_strain_utilisation"])
    assert sm["max_utilisation"] == sm["sagbend_lcc_utilisation"] > 0.0


def test_power_basis_is_the_hermite(s67):
    """tip_clearance's power basis (:func:`.kernels.geometry._at`) gives the
    same centreline as the elements' Hermite shape functions
    (:func:`.kernels.element_shapes.hermite`), its slope and its curvature too."""
    from pipelay_fast.kernels.element_shapes import hermite
    from pipelay_fast.kernels.geometry import _at

    p = pf.solve(s67.with_changes({"lay.stinger.a": -0.0014})).profile
    s = p["s"].to_numpy()
    th = np.radians(p["angle_deg"].to_numpy())
    r = np.stack([p["x"].to_numpy(), p["z"].to_numpy()], axis=1)
    rp = np.stack([np.sin(th), np.cos(th)], axis=1)
    origin = np.zeros(2)
    gap, slope_xi, curve_xi = np.empty(2), np.empty(2), np.empty(2)
    n, dn, ddn = np.empty(4), np.empty(4), np.empty(4)
    scale = max(np.abs(r).max(), 1.0)
    worst = 0.0
    for e in range(s.size - 1):
        le = s[e + 1] - s[e]
        for xi in (0.0, 0.3, 0.77, 1.0):
            hermite(xi, le, n, dn, ddn)
            nodal = (r[e], rp[e], r[e + 1], rp[e + 1])
            point, slope, curvature = (sum(f[j] * nodal[j] for j in range(4))
                                       for f in (n, dn, ddn))
            _at(r, rp, s, e, xi, origin, gap, slope_xi, curve_xi)
            np.testing.assert_allclose(gap, point, rtol=0, atol=1e-12 * scale)
            np.testing.assert_allclose(slope_xi / le, slope, rtol=0, atol=1e-12)
            # the power basis's c2, c3 are differences of coordinates of size
            # `scale`: their round-off (a few eps scale), divided by le^2,
            # bounds the curvature's (measured 5 eps: 1.1e-12 1/m on 0.5 m
            # elements 400 m from the origin)
            worst = max(worst, np.abs(curve_xi / le**2 - curvature).max() * le**2 / scale)
    assert worst < 1e-14

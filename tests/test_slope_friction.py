"""Seabed friction on a sloped seabed with a current (3D): friction in the
seabed's plane with the normal force N from the plane, lateral (along y,
mu_y = 0.5) and axial (along the plane's line in the (x, z) plane, mu_z =
0.3), two independent springs: the cone is the rectangle |f_y| <= mu_y N,
|f_t| <= mu_z N. The answer's admissibility, checked here on J125 (150 m
of water, the plane through x = 0 at z = 134 m) at -5 and +5 deg under the
paper's power-law current across the lay (heading 90 deg, and -90 deg for
its mirror image): the seabed contacts push, the reactions, the drag, the
weight and the bottom tension along the plane balance, friction stays in
its cone (and reaches it where the pipe slides), and the mirrored current
gives the mirrored answer. The friction rows of the tangent on the slope
are checked against central differences of the residual."""

from __future__ import annotations

import math

import numpy as np
import pytest

import pipelay_fast as pf
from pipelay_fast.kernels import layout as L
from pipelay_fast.kernels.types import load_factors
from tests.helpers import friction_system
from tests.reference.drag import drag_vector
from tests.test_hard_cases import weight_of

SLOPES = (-5.0, 5.0)


def _solved(slope: float, heading: float, **more):
    """(case, profile) of J125 3D on the slope under the current, with
    lateral and axial friction."""
    case = pf.load_case("j125_3d").with_changes({
        "checks": None, "environment.water_depth": 150.0, "seabed.slope_deg": slope,
        "seabed.slope_origin": 134.0, "environment.current.speed": 1.0,
        "environment.current.heading": heading, "seabed.axial_friction": 0.3, **more})
    res = pf.solve(case)
    assert res.summary["status"] == "ok" and res.summary["dimension"] == "3d"
    # the bottom tension the lower end carries: the load applied there (the
    # effective_tension column is the nodal multiplier plus EI k^2, at s = 0
    # a few hundred N off it where axial friction steepens the tension)
    res.profile.attrs["tb"] = float(res.state.tb[0])
    return case, res.profile


@pytest.fixture(scope="module")
def answers():
    """(case, profile) per (slope, heading), on the rigid seabed."""
    return {(slope, heading): _solved(slope, heading)
            for slope in SLOPES for heading in (90.0, -90.0)}


def _cone(case, prof, bed, n):
    """|f_y| / (mu_y N) at the seabed nodes ``bed`` with normal forces ``n``."""
    return np.abs(prof["reaction_y"].to_numpy()[bed]) / (case.seabed.lateral_friction * n)


def _unbalance(case, prof, tb, a):
    """(the sum of the constraints' forces (the reactions, friction
    included), the drag, the weight and the bottom tension ``tb`` [N]
    pulling the lower end down the plane's line -tb (sin a, 0, cos a), the
    weight w, the drag) [N], the plane at ``a`` [rad]."""
    w = weight_of(case, prof)
    drag = drag_vector(case, prof)
    total = prof[["reaction_x", "reaction_y", "reaction_z"]].sum().to_numpy() + drag
    return total - np.array([w + tb * math.sin(a), 0.0, tb * math.cos(a)]), w, drag


def _in_plane(prof, bed, a):
    """(normal, along the plane's line) components [N] of the reactions in
    the (x, z) plane at the seabed nodes ``bed``, the plane at ``a`` [rad]:
    its normal (cos a, -sin a), its tangent (sin a, cos a)."""
    rx, rz = (prof[key].to_numpy()[bed] for key in ("reaction_x", "reaction_z"))
    return (rx * math.cos(a) - rz * math.sin(a), rx * math.sin(a) + rz * math.cos(a))


@pytest.mark.parametrize("slope", SLOPES)
def test_friction_on_a_slope_is_admissible(answers, slope):
    case, prof = answers[slope, 90.0]
    assert case.environment.current.profile == "power"
    a = math.radians(slope)
    bed = (prof["contact"] == "seabed").to_numpy() & (prof["s"] > 0.0).to_numpy()
    n = prof["seabed_reaction"].to_numpy()[bed]
    # the contacts push (the normal reaction), and carry the weight where the
    # pipe rests: w cos(a) per metre normal to the plane
    assert n.min() >= 0.0 and bed.sum() > 20
    # the cone in the plane, with the normal force from the plane; the
    # sliding pipe at its edge (the vertical part of N, N cos(a), would
    # leave it at cos(5 deg) = 0.9962 of the edge)
    ratio = _cone(case, prof, bed, n)
    assert ratio.max() <= 1.0 + 1e-6
    assert (np.abs(ratio - 1.0) < 1e-6).sum() > 10
    # axial: the reaction's part along the plane's line is the axial
    # friction (the normal part is N), within mu_z N and at it where the
    # laid pipe slides along the line (the two springs are independent: a
    # node may be at both edges)
    normal, along = _in_plane(prof, bed, a)
    np.testing.assert_allclose(normal, n, rtol=1e-9, atol=1e-9 * n.max())
    axial = np.abs(along) / (case.seabed.axial_friction * n)
    assert axial.max() <= 1.0 + 1e-6 and (np.abs(axial - 1.0) < 1e-6).sum() > 10
    # the balance: the constraints' forces (the seabed's normal and
    # friction, the vessel's), the drag, the weight and the bottom tension
    # pulling the lower end down the plane's line, -Tb (sin a, 0, cos a)
    total, w, drag = _unbalance(case, prof, prof.attrs["tb"], a)
    assert abs(total[0]) < 1e-4 * w and abs(total[2]) < 1e-4 * w, total / w
    assert abs(total[1]) < 2e-3 * abs(drag[1]), total[1] / drag[1]


@pytest.mark.parametrize("slope", SLOPES)
def test_the_mirrored_current_gives_the_mirrored_answer(answers, slope):
    """Heading -90 deg is heading 90 deg mirrored in the plane y = 0: y and
    the lateral reactions change sign, the rest is the same (to 1e-9)."""
    _case, a = answers[slope, 90.0]
    _case, b = answers[slope, -90.0]
    scale = a["seabed_reaction"].abs().max()
    for key, sign in (("y", -1.0), ("reaction_y", -1.0), ("x", 1.0), ("z", 1.0),
                      ("seabed_reaction", 1.0), ("effective_tension", 1.0)):
        ref = a[key].to_numpy()
        tol = 1e-9 * (scale if "reaction" in key else max(np.abs(ref).max(), 1.0))
        np.testing.assert_allclose(b[key].to_numpy(), sign * ref, rtol=0, atol=tol, err_msg=key)


@pytest.mark.parametrize("slope", SLOPES)
def test_friction_on_an_elastic_slope_is_admissible(slope):
    """The elastic seabed (1e6 N/m per m) on the slope: its nodal normal
    forces N (the ``seabed_reaction`` column: k times the normal
    penetration over the node's share) push along the plane's normal (cos a,
    0, -sin a); friction stays in the cone mu_y N and reaches it where the
    pipe slides; the forces balance to 5e-4 of the weight (the nodal
    lumping of the foundation, against the elements' Gauss points)."""
    case, prof = _solved(slope, 90.0, **{"seabed.stiffness": 1e6})
    a = math.radians(slope)
    n_all = prof["seabed_reaction"].to_numpy()
    bed = (prof["contact"] == "seabed").to_numpy() & (prof["s"] > 0.0).to_numpy()
    assert n_all.min() >= 0.0 and bed.sum() > 20
    ratio = _cone(case, prof, bed, n_all[bed])
    assert ratio.max() <= 1.0 + 1e-6 and (np.abs(ratio - 1.0) < 1e-6).sum() > 10
    total, w, drag = _unbalance(case, prof, prof.attrs["tb"], a)
    total += n_all.sum() * np.array([math.cos(a), 0.0, -math.sin(a)])
    assert abs(total[0]) < 5e-4 * w and abs(total[2]) < 5e-4 * w, total / w
    assert abs(total[1]) < 2e-3 * abs(drag[1]), total[1] / drag[1]


@pytest.mark.parametrize("slope", SLOPES)
def test_the_tilted_springs_tangent_is_the_derivative_of_their_forces(slope):
    """On the slope the axial spring acts along the plane's line e = (sin a,
    cos a) in (x, z), stretched by e . r - anchor, and W is the reaction
    normal to the plane, n . (G_x, G_z) with n = (cos a, -sin a): the
    friction's rows of the tangent (x, y and z of the last laid nodes, the
    springs set to stick and slide off their kinks) are the central
    difference of its residual, and its forces are -mu clip(d / d_slip) W
    along y and along e."""
    case = pf.load_case("j125_3d").with_changes({
        "checks": None, "environment.water_depth": 150.0, "seabed.slope_deg": slope,
        "seabed.slope_origin": 134.0, "environment.current.speed": 1.0,
        "environment.current.heading": 90.0, "environment.current.profile": "linear",
        "seabed.axial_friction": 0.3})
    pb = pf.solve(case).state
    pb.settings.factors[:] = load_factors(1.0, True)
    nd, ndn = pb.nd, pb.ndn
    s, residual, dense, friction_only = friction_system(pb)

    a = math.radians(slope)
    t_x, t_z = math.sin(a), math.cos(a)
    on_bed = np.flatnonzero(pb.contacts.bed_active)[-8:]
    slip = pb.props[L.FRICTION_SLIP]
    stretch = np.resize([0.5, 1.5, -0.4, -1.3], on_bed.size) * slip
    along = t_x * pb.u[on_bed * ndn] + t_z * pb.u[on_bed * ndn + nd - 1]
    pb.contacts.fric[on_bed, L.FR_Y] = pb.u[on_bed * ndn + 1] - stretch
    pb.contacts.fric[on_bed, L.FR_Z] = along + stretch[::-1]
    pb.contacts.fric[on_bed, L.FR_S] = pb.s[on_bed]
    g_el = residual(pb.u, False, False)[0]
    w = math.cos(a) * g_el[on_bed * ndn] - math.sin(a) * g_el[on_bed * ndn + nd - 1]
    assert np.all(w > 0.0)
    force = g_el - residual(pb.u, False)[0]  # friction on the pipe
    clip_y = np.clip(stretch / slip, -1.0, 1.0)
    clip_t = np.clip(-stretch[::-1] / slip, -1.0, 1.0)
    f_t = -pb.props[L.MU_Z] * clip_t * w
    np.testing.assert_allclose(force[on_bed * ndn + 1], -pb.props[L.MU_Y] * clip_y * w,
                               rtol=1e-10)
    np.testing.assert_allclose(force[on_bed * ndn], t_x * f_t, rtol=1e-10)
    np.testing.assert_allclose(force[on_bed * ndn + nd - 1], t_z * f_t, rtol=1e-10)
    rows = np.concatenate([on_bed * ndn, on_bed * ndn + 1, on_bed * ndn + nd - 1])
    k = dense(residual(pb.u, True)[1]) - dense(residual(pb.u, True, False)[1])
    cols = np.arange(max(0, on_bed[0] - 1) * ndn, min(pb.nn, on_bed[-1] + 2) * ndn)
    for j in cols:
        h = 1e-7 * max(1.0, abs(pb.u[j])) if j % ndn != 2 * nd else 1e-3
        if j % ndn in (0, nd - 1):
            h = 1e-9  # x and z: each moves W (the x and z rows' stiffness, 1e10 N/m)
        up, dn = pb.u.copy(), pb.u.copy()
        up[j] += h
        dn[j] -= h
        fd = (friction_only(up)[rows] - friction_only(dn)[rows]) / (2 * h)
        scale = np.abs(k[rows]).max(axis=1) + 1.0
        np.testing.assert_allclose(k[rows, j] / scale, fd / scale, atol=2e-5, err_msg=str(j))


@pytest.mark.parametrize("slope", SLOPES)
def test_axial_friction_on_a_slope_in_2d_is_admissible(slope):
    """J125 2D on the slope under the current along the lay (heading 0 deg):
    axial friction alone, in the plane, within mu_z N of the normal reaction
    N and at it where the pipe slides; the forces balance with the applied
    bottom tension along the plane to 1e-4 of the weight."""
    case = pf.load_case("j125_2d").with_changes({
        "checks": None, "environment.water_depth": 150.0, "seabed.slope_deg": slope,
        "seabed.slope_origin": 134.0, "environment.current.speed": 1.0,
        "environment.current.heading": 0.0, "seabed.axial_friction": 0.3})
    res = pf.solve(case)
    assert res.summary["status"] == "ok" and res.summary["dimension"] == "2d"
    prof, a = res.profile, math.radians(slope)
    bed = (prof["contact"] == "seabed").to_numpy() & (prof["s"] > 0.0).to_numpy()
    n = prof["seabed_reaction"].to_numpy()[bed]
    assert n.min() >= 0.0 and bed.sum() > 10
    normal, along = _in_plane(prof, bed, a)
    np.testing.assert_allclose(normal, n, rtol=1e-9, atol=1e-9 * n.max())
    ratio = np.abs(along) / (case.seabed.axial_friction * n)
    assert ratio.max() <= 1.0 + 1e-6 and (np.abs(ratio - 1.0) < 1e-6).sum() > 5
    total, w, _drag = _unbalance(case, prof, float(res.state.tb[0]), a)
    assert abs(total[0]) < 1e-4 * w and abs(total[2]) < 1e-4 * w, total / w

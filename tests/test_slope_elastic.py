"""The elastic seabed on a sloped plane (``seabed.slope_deg`` with
``seabed.stiffness`` a number): in the element kernels, the tangent and
dG/dle against central differences and the load against the closed form
k (x_b - x) cos(a) along the plane's normal; solved, a stiff foundation
against the rigid sloped seabed, and the touchdown offset's scaling with the
foundation's length (4 EI / k)^(1/4)."""

import math

import numpy as np
import pytest

from pipelay_fast.kernels import layout as L
from pipelay_fast.kernels.assembly import element_force
from tests.test_element import make_props, random_state

ANGLE = math.radians(8.0)
Z0 = 0.7  # where the plane passes through x = 0 [m]


def _props(angle, k=1e5, **more):
    """The element tests' props on the plane x = tan(angle) (z - Z0)."""
    props, sec = make_props(bed_k=k, **more)
    props[L.SEABED_TAN] = math.tan(angle)
    props[L.SEABED_Z0] = Z0
    return props, sec


def _state(nd, seed, angle, le=1.7):
    """A random element state with both nodes 0.3 m below the plane."""
    rng = np.random.default_rng(seed)
    ue = random_state(nd, rng, x0=0.0, chord=le)
    ndn = 2 * nd + 1
    for node in (0, ndn):
        ue[node] = math.tan(angle) * (ue[node + nd - 1] - Z0) - 0.3
    return ue


@pytest.mark.parametrize("angle", [ANGLE, -ANGLE])
@pytest.mark.parametrize("nd", [2, 3])
@pytest.mark.parametrize("seed", [1, 2])
def test_tangent_on_a_sloped_plane_matches_central_difference(angle, nd, seed):
    props, sec = _props(angle)
    ue = _state(nd, seed, angle)
    ne = ue.size

    def g_of(u, ke=None):
        out = np.zeros(ne)
        element_force(nd, 1.7, u, props, sec, np.zeros((0, 2)), 0.0, out,
                      np.zeros((ne, ne)) if ke is None else ke, ke is not None)
        return out

    kfd = np.zeros((ne, ne))
    for j, step in enumerate(np.where(np.arange(ne) % (2 * nd + 1) == 2 * nd, 1e-2,
                                      1e-6 * np.maximum(1.0, np.abs(ue)))):
        du = np.zeros(ne)
        du[j] = step
        kfd[:, j] = (g_of(ue + du) - g_of(ue - du)) / (2.0 * step)
    ke = np.zeros((ne, ne))
    g_of(ue, ke)
    scale = np.abs(kfd).max(axis=1, keepdims=True) + 1e-30
    assert np.max(np.abs(ke - kfd) / scale) < 2e-6
    # the z rows on the x and z columns: the normal's z component, 0 on the flat seabed
    ndn = 2 * nd + 1
    xs, zs = np.array([0, ndn]), np.array([nd - 1, ndn + nd - 1])
    np.testing.assert_allclose(ke[np.ix_(zs, xs)], kfd[np.ix_(zs, xs)], rtol=1e-5)
    np.testing.assert_allclose(ke[np.ix_(zs, zs)], kfd[np.ix_(zs, zs)], rtol=1e-5, atol=1e-6)


@pytest.mark.parametrize("nd", [2, 3])
@pytest.mark.parametrize("le", [0.5, 4.0])
def test_length_derivative_on_a_sloped_plane_matches_central_difference(nd, le):
    """dG/dle at fixed unknowns against a central difference in le, per
    block of rows (positions, tangents, multipliers) to 1e-8 of its scale."""
    props, sec = _props(ANGLE)
    ue = _state(nd, 11, ANGLE, le)

    def g_of(length, dfe=None):
        out = np.zeros(ue.size)
        element_force(nd, length, ue, props, sec, np.zeros((0, 2)), 0.0, out,
                      np.zeros((ue.size, ue.size)), False, dfe)
        return out

    dfe = np.full(ue.size, np.nan)
    g_of(le, dfe)
    step = 1e-5 * le
    diff = (g_of(le + step) - g_of(le - step)) / (2.0 * step)
    ndn = 2 * nd + 1
    blocks = (np.r_[0:nd, ndn:ndn + nd], np.r_[nd:2 * nd, ndn + nd:ndn + 2 * nd],
              np.array([2 * nd, ndn + 2 * nd]))
    errors = [np.abs(dfe[b] - diff[b]).max() / np.abs(diff[b]).max() for b in blocks]
    assert max(errors) < 1e-8, errors


@pytest.mark.parametrize("nd", [2, 3])
def test_a_straight_element_sunk_under_the_plane_is_pushed_along_its_normal(nd):
    """A straight element lying along the plane at a normal depth d below it
    (lam = 0, no bending): the rows of G sum to -(integral of q), q = k d
    (cos a, -sin a), d its depth times cos(a): the force is normal to the
    plane, k times the normal penetration per metre of pipe."""
    k = 2e5
    props, sec = _props(ANGLE, k=k, extensible=False)
    props[L.H_CONT] = -100.0  # contents flooded: the weight a constant, whatever x
    ndn = 2 * nd + 1
    le, d = 3.0, 0.25
    ca, sa = math.cos(ANGLE), math.sin(ANGLE)
    ue = np.zeros(2 * ndn)
    for node, s in ((0, 0.0), (ndn, le)):  # along the plane, d below it normally
        ue[node] = s * sa - d * ca
        ue[node + nd - 1] = Z0 + s * ca + d * sa
        ue[node + nd] = sa
        ue[node + 2 * nd - 1] = ca
    fe, ke = np.zeros(2 * ndn), np.zeros((2 * ndn, 2 * ndn))
    table = np.zeros((0, 2))
    element_force(nd, le, ue, props, sec, table, 0.0, fe, ke, False)
    qx, qz = -fe[0] - fe[ndn], -fe[nd - 1] - fe[ndn + nd - 1]
    props[L.SEABED_K] = 0.0
    element_force(nd, le, ue, props, sec, table, 0.0, fe, ke, False)
    qx -= -fe[0] - fe[ndn]
    qz -= -fe[nd - 1] - fe[ndn + nd - 1]
    assert qx == pytest.approx(k * d * le * ca, rel=1e-12)
    assert qz == pytest.approx(-k * d * le * sa, rel=1e-12)


def _sloped(name: str, slope: float, **more):
    """The example ``name`` planar and inextensible, no current, on a seabed
    of ``slope`` [deg] (J125 in 150 m of water through x = 0 at z = 134 m,
    S67 at z = 60 m: the test_slope.py cases)."""
    import pipelay_fast as pf

    origin = {"j125_2d": 134.0, "s67": 60.0}[name]
    depth = {"environment.water_depth": 150.0} if name == "j125_2d" else {}
    return pf.load_case(name).with_changes({
        "environment.current.speed": 0.0, "checks": None, "pipe.extensible": False,
        "seabed.slope_deg": slope, "seabed.slope_origin": origin, **depth, **more})


@pytest.fixture(scope="module", params=[("j125_2d", -8.0), ("j125_2d", 8.0), ("s67", -8.0),
                                        ("s67", 8.0)], ids=lambda p: f"{p[0]}{p[1]:+g}")
def on_a_slope(request):
    """A case on a slope solved on the rigid seabed and on foundations of
    1e8 and 1e9 N/m per m."""
    import pipelay_fast as pf

    name, slope = request.param
    base = _sloped(name, slope)
    soft = {k: pf.solve(base.with_changes({"seabed.stiffness": k})).summary
            for k in (1e8, 1e9)}
    return base, soft, pf.solve(base).summary


def test_a_stiff_foundation_on_a_slope_gives_the_rigid_answer(on_a_slope):
    """k = 1e9 N/m per m on a slope of -8 or +8 deg: the tension at
    touchdown, the sagbend's peak moment and the peak stress of the rigid
    sloped seabed to 1e-3 (the rigid answer agrees with an independent
    elastica, tests/test_slope.py)."""
    _base, soft, rigid = on_a_slope
    stiff = soft[1e9]
    assert stiff["status"] == "ok"
    for key in ("bottom_tension", "sagbend_max_moment", "max_von_mises", "top_angle_deg"):
        assert stiff[key] == pytest.approx(rigid[key], rel=1e-3), key


def test_the_touchdown_offset_on_a_slope_scales_with_the_foundation_length(on_a_slope):
    """Touchdown on the foundation (where the axis rises out of it) lies
    beyond the rigid one's by a distance that scales like (4 EI / k)^(1/4):
    ten times stiffer, 10^(1/4) times closer (to 2 %), each within 1.5
    foundation lengths (along the plane) of the rigid touchdown."""
    base, soft, rigid = on_a_slope
    cos_a = math.cos(math.radians(base.seabed.slope_deg))
    offset = {k: (sm["tdp_z"] - rigid["tdp_z"]) / cos_a for k, sm in soft.items()}
    for k, off in offset.items():
        beta = (4.0 * base.pipe.bending_stiffness / k) ** 0.25
        assert 0.0 < off < 1.5 * beta, (k, off, beta)
    assert offset[1e8] / offset[1e9] == pytest.approx(10.0 ** 0.25, rel=2e-2)


@pytest.mark.parametrize("name", ["j125_2d", "s67"])
def test_3d_on_an_elastic_slope_without_lateral_load_is_the_plane_answer(name):
    """In 3D with no lateral load the elastic sloped seabed's answer is the
    planar one (the foundation's normal has no y part): tension at touchdown,
    touchdown, the sagbend's peak moment and stress to 1e-9, and no free
    span on the plane."""
    import pipelay_fast as pf

    base = _sloped(name, 6.0, **{"seabed.stiffness": 1e7})
    a = pf.solve(base.with_changes({"solver.dimension": "2d"})).summary
    b = pf.solve(base.with_changes({"solver.dimension": "3d"})).summary
    for key in ("bottom_tension", "tdp_z", "sagbend_max_moment", "max_von_mises"):
        assert b[key] == pytest.approx(a[key], rel=1e-9), key
    assert a["n_spans"] == b["n_spans"] == 0

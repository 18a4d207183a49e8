"""The element kernel: tangent and d/dle = finite differences of the residual; 2D = 3D."""

import numpy as np
import pytest

from pipelay_fast.kernels import layout as L
from pipelay_fast.kernels.assembly import element_force
from pipelay_fast.kernels.element_shapes import hermite_crossing


def make_props(drag=0.0, torque_free=True, extensible=True, bed_k=0.0):
    """The scene's ``props`` and an element's ``section`` row."""
    sec = np.zeros(L.N_SECTION)
    sec[L.S_EI] = 2.6e8
    sec[L.S_EA] = 5.8e9
    sec[L.S_W_DRY] = 9.0e3
    sec[L.S_W_CONT] = 1.5e3
    sec[L.S_W_BUOY] = 4.0e3
    sec[L.S_AREA_I] = np.pi * 0.58**2 / 4
    sec[L.S_AREA_E] = np.pi * 0.61**2 / 4
    sec[L.S_DRAG] = drag
    p = np.zeros(L.N_PROPS)
    p[L.EI_REF] = sec[L.S_EI]
    p[L.H_CONT] = 40.0
    p[L.DEPTH] = 67.0
    p[L.RHOW_G] = 1025 * 9.81
    p[L.RHOI_G] = 900 * 9.81
    p[L.CUR_SPEED] = 1.0
    p[L.CUR_EY] = np.sin(0.7)
    p[L.CUR_EZ] = np.cos(0.7)
    p[L.CUR_PROFILE] = L.PROFILE_POWER
    p[L.CUR_EXP] = 1 / 7
    p[L.SEABED_K] = bed_k
    p[L.EXTENSIBLE] = 1.0 if extensible else 0.0
    if not torque_free:
        p[L.MOM_X], p[L.MOM_Y], p[L.MOM_Z] = 30.0, -20.0, 10.0
    return p, sec


def random_state(nd, rng, x0=20.0, chord=1.7):
    """A bent, slightly stretched element state."""
    ndn = 2 * nd + 1
    ue = np.zeros(2 * ndn)
    t_a = rng.normal(size=nd)
    t_a /= np.linalg.norm(t_a)
    t_b = t_a + 0.3 * rng.normal(size=nd)
    t_b /= np.linalg.norm(t_b)
    ue[0:nd] = rng.normal(size=nd) + np.r_[x0, np.zeros(nd - 1)]
    ue[nd:2 * nd] = t_a * 1.001
    ue[ndn:ndn + nd] = ue[0:nd] + chord * (t_a + t_b) / 2
    ue[ndn + nd:ndn + 2 * nd] = t_b * 0.999
    ue[2 * nd] = 3e5
    ue[ndn + 2 * nd] = 2.5e5
    return ue


def fd_tangent(nd, le, ue, props, sec, table, torque):
    ne = ue.size
    fe = np.zeros(ne)
    ke = np.zeros((ne, ne))
    kfd = np.zeros((ne, ne))
    for j in range(ne):
        h = 1e-6 * max(1.0, abs(ue[j])) if j % (2 * nd + 1) != 2 * nd else 1e-2
        up = ue.copy()
        up[j] += h
        element_force(nd, le, up, props, sec, table, torque, fe, ke, False)
        fp = fe.copy()
        up[j] -= 2 * h
        element_force(nd, le, up, props, sec, table, torque, fe, ke, False)
        kfd[:, j] = (fp - fe) / (2 * h)
    element_force(nd, le, ue, props, sec, table, torque, fe, ke, True)
    return ke, kfd


@pytest.mark.parametrize("nd", [2, 3])
@pytest.mark.parametrize(
    "kw",
    [
        {},
        {"extensible": False},
        {"drag": 0.5 * 1025 * 1.0 * 0.71},
        {"torque_free": False},
        {"bed_k": 1e5},
    ],
)
def test_tangent_matches_central_difference(nd, kw):
    rng = np.random.default_rng(3)
    props, sec = make_props(**kw)
    x0 = -0.05 if kw.get("bed_k") else 20.0
    ue = random_state(nd, rng, x0=x0)
    torque = 0.0 if kw.get("torque_free", True) else 4.0e4
    ke, kfd = fd_tangent(nd, 1.7, ue, props, sec, np.zeros((0, 2)), torque)
    scale = np.abs(kfd).max(axis=1, keepdims=True) + 1e-30
    assert np.max(np.abs(ke - kfd) / scale) < 2e-6


DLE_CASES = [
    {},
    {"extensible": False},
    {"drag": 0.5 * 1025 * 1.0 * 0.71},
    {"drag": 0.5 * 1025 * 1.0 * 0.71, "extensible": False},
    {"torque_free": False},
    {"torque_free": False, "drag": 0.5 * 1025 * 1.0 * 0.71},
    {"bed_k": 1e5},
]


def centred_state(nd, rng, le, x_mid):
    """A random state of an element of length ``le`` whose nodes are centred at
    height ``x_mid``."""
    ue = random_state(nd, rng, chord=le)
    ndn = 2 * nd + 1
    shift = x_mid - 0.5 * (ue[0] + ue[ndn])
    ue[0] += shift
    ue[ndn] += shift
    return ue


def crossings(nd, le, ue, props):
    """Where the element crosses the water surface and the contents level (-1: nowhere)."""
    ndn = 2 * nd + 1
    return [hermite_crossing(ue[0], ue[nd], ue[ndn], ue[ndn + nd], le, props[level])
            for level in (L.DEPTH, L.H_CONT)]


@pytest.mark.parametrize("nd", [2, 3])
@pytest.mark.parametrize("kw", DLE_CASES, ids=lambda kw: "-".join(kw) or "plain")
@pytest.mark.parametrize("le", [0.5, 4.0, 20.0])
def test_length_derivative_matches_central_difference(nd, kw, le):
    props, sec = make_props(**kw)
    table = np.zeros((0, 2))
    torque = 0.0 if kw.get("torque_free", True) else 4.0e4
    rng = np.random.default_rng(7)
    ndn = 2 * nd + 1
    # rows grouped by kind (position, tangent, lambda): each has its own unit
    kinds = [np.r_[0:nd, ndn:ndn + nd], np.r_[nd:2 * nd, ndn + nd:ndn + 2 * nd],
             np.array([2 * nd, ndn + 2 * nd])]
    for _ in range(4):
        # centred at x = 20 m, or at the seabed so that part of it penetrates
        ue = centred_state(nd, rng, le, 0.0 if kw.get("bed_k") else 20.0)
        assert crossings(nd, le, ue, props) == [-1.0, -1.0]
        if kw.get("bed_k"):
            assert min(ue[0], ue[ndn]) < 0.0 < max(ue[0], ue[ndn])
        fe = np.zeros(ue.size)
        ke = np.zeros((ue.size, ue.size))
        dfe = np.full(ue.size, np.nan)
        element_force(nd, le, ue, props, sec, table, torque, fe, ke, False, dfe)
        h = 1e-5 * le
        fp = np.zeros(ue.size)
        element_force(nd, le + h, ue, props, sec, table, torque, fp, ke, False)
        element_force(nd, le - h, ue, props, sec, table, torque, fe, ke, False)
        dfd = (fp - fe) / (2 * h)
        for rows in kinds:
            scale = np.abs(dfd[rows]).max()
            assert scale > 0.0
            assert np.max(np.abs(dfe[rows] - dfd[rows])) < 1e-8 * scale


@pytest.mark.parametrize("nd", [2, 3])
def test_length_derivative_leaves_residual_and_tangent_unchanged(nd):
    props, sec = make_props(drag=300.0, torque_free=False)
    rng = np.random.default_rng(9)
    ue = centred_state(nd, rng, 1.7, props[L.DEPTH])
    assert crossings(nd, 1.7, ue, props)[0] > 0.0  # integrated in two parts
    ne = ue.size
    out = []
    for dfe in (None, np.zeros(ne)):
        fe = np.zeros(ne)
        ke = np.zeros((ne, ne))
        element_force(nd, 1.7, ue, props, sec, np.zeros((0, 2)), 4.0e4, fe, ke, True, dfe)
        out.append((fe, ke))
    assert np.array_equal(out[0][0], out[1][0])
    assert np.array_equal(out[0][1], out[1][1])


def test_planar_state_gives_same_forces_in_2d_and_3d():
    rng = np.random.default_rng(5)
    props, sec = make_props(drag=300.0)
    props[L.CUR_EY], props[L.CUR_EZ] = 0.0, 1.0  # current along z: planar
    ue2 = random_state(2, rng)
    ue3 = np.zeros(14)
    for node in range(2):
        a2, a3 = 5 * node, 7 * node
        ue3[a3 + 0], ue3[a3 + 2] = ue2[a2 + 0], ue2[a2 + 1]
        ue3[a3 + 3], ue3[a3 + 5] = ue2[a2 + 2], ue2[a2 + 3]
        ue3[a3 + 6] = ue2[a2 + 4]
    f2, k2 = np.zeros(10), np.zeros((10, 10))
    f3, k3 = np.zeros(14), np.zeros((14, 14))
    element_force(2, 1.3, ue2, props, sec, np.zeros((0, 2)), 0.0, f2, k2, True)
    element_force(3, 1.3, ue3, props, sec, np.zeros((0, 2)), 0.0, f3, k3, True)
    keep = [0, 2, 3, 5, 6, 7, 9, 10, 12, 13]
    np.testing.assert_allclose(f3[keep], f2, rtol=1e-13, atol=1e-9)
    np.testing.assert_allclose(k3[np.ix_(keep, keep)], k2, rtol=1e-13, atol=1e-9)
    assert np.all(f3[[1, 4, 8, 11]] == 0.0)


@pytest.mark.parametrize("nd", [2, 3])
@pytest.mark.parametrize("drag", [0.0, 300.0])
@pytest.mark.parametrize(("le", "x_mid", "cut"), [
    (1.7, 67.0, (True, False)),  # the water surface
    (4.0, 40.0, (False, True)),  # the contents level
    (40.0, 53.5, (True, True)),  # both
])
def test_tangent_and_length_derivative_of_an_element_cut_by_a_level(nd, drag, le, x_mid, cut):
    """Where the element crosses the water surface or the contents level the
    load jumps (weight, and the drag, which stops at the surface) and the cut
    moves with the nodes' heights and with le: the tangent and d/dle carry
    that movement, so both match central differences (without it the tangent
    was off by 1.7e-6 to 1.2e-5 of its row's largest entry, d/dle by 1e-6)."""
    props, sec = make_props(drag=drag)
    rng = np.random.default_rng(11)
    table = np.zeros((0, 2))
    ndn = 2 * nd + 1
    ue = centred_state(nd, rng, le, x_mid)
    # nearly along x, so the element spans le in height and crosses the levels
    for node in range(2):
        ue[node * ndn + nd:node * ndn + 2 * nd] = np.r_[1.0, 0.05 * np.ones(nd - 1)]
    ue[ndn:ndn + nd] = ue[0:nd] + le * np.r_[1.0, np.zeros(nd - 1)]
    shift = x_mid - 0.5 * (ue[0] + ue[ndn])
    ue[0] += shift
    ue[ndn] += shift
    assert [c > 0.0 for c in crossings(nd, le, ue, props)] == list(cut)
    ke, kfd = fd_tangent(nd, le, ue, props, sec, table, 0.0)
    scale = np.abs(kfd).max(axis=1, keepdims=True) + 1e-30
    assert np.max(np.abs(ke - kfd) / scale) < 1e-8
    ne = ue.size
    fe, fp = np.zeros(ne), np.zeros(ne)
    dfe = np.zeros(ne)
    element_force(nd, le, ue, props, sec, table, 0.0, fe, np.zeros((ne, ne)), False, dfe)
    h = 1e-6 * le
    element_force(nd, le + h, ue, props, sec, table, 0.0, fp, np.zeros((ne, ne)), False)
    element_force(nd, le - h, ue, props, sec, table, 0.0, fe, np.zeros((ne, ne)), False)
    dfd = (fp - fe) / (2 * h)
    assert np.max(np.abs(dfe - dfd)) < 1e-8 * np.abs(dfd).max()


def reference_residual(nd, le, ue, props, sec, torque=0.0):
    """The element's residual G by NumPy, written apart from the kernels from
    the weak form in :mod:`pipelay_fast.kernels.element`'s docstring: cubic
    Hermite r, linear lam, 4-point Gauss-Legendre on each piece between the
    level crossings (found by brentq), the drag from its vector definition
    q = C |r'| |Vn| Vn, the moments from the cross products in 3D (the 2D
    state embedded at y = 0)."""
    from scipy.optimize import brentq

    ndn = 2 * nd + 1
    nodal = np.stack([ue[0:nd], ue[nd:2 * nd], ue[ndn:ndn + nd], ue[ndn + nd:ndn + 2 * nd]])
    lam_a, lam_b = ue[2 * nd], ue[ndn + 2 * nd]
    slots = [0, 1, 2] if nd == 3 else [0, 2]  # the components in 3D

    def shapes(xi):
        h = np.array([1 - 3 * xi**2 + 2 * xi**3, le * (xi - 2 * xi**2 + xi**3),
                      3 * xi**2 - 2 * xi**3, le * (-xi**2 + xi**3)])
        dh = np.array([(-6 * xi + 6 * xi**2) / le, 1 - 4 * xi + 3 * xi**2,
                       (6 * xi - 6 * xi**2) / le, -2 * xi + 3 * xi**2])
        ddh = np.array([(-6 + 12 * xi) / le**2, (-4 + 6 * xi) / le, (6 - 12 * xi) / le**2,
                        (-2 + 6 * xi) / le])
        return h, dh, ddh

    def height(xi):
        return shapes(xi)[0] @ nodal[:, 0]

    levels = [lv for lv in (props[L.DEPTH], props[L.H_CONT])
              if (height(0.0) - lv) * (height(1.0) - lv) < 0.0]
    cuts = sorted([0.0, 1.0, *(brentq(lambda xi, lv=lv: height(xi) - lv, 0.0, 1.0, xtol=1e-15)
                               for lv in levels)])
    gx, gw = np.polynomial.legendre.leggauss(4)
    m3 = np.array([props[L.MOM_X], props[L.MOM_Y], props[L.MOM_Z]])
    current = np.zeros(3)
    current[1], current[2] = props[L.CUR_EY], props[L.CUR_EZ]
    if nd == 2:
        current[1] = 0.0  # a planar case's current is along z
    fe = np.zeros(2 * ndn)
    for c0, c1 in zip(cuts[:-1], cuts[1:], strict=True):
        for g, wg in zip(gx, gw, strict=True):
            xi = c0 + (c1 - c0) * (g + 1) / 2
            w = wg / 2 * (c1 - c0) * le
            h, dh, ddh = shapes(xi)
            r, rp, rpp = h @ nodal, dh @ nodal, ddh @ nodal
            lam = (1 - xi) * lam_a + xi * lam_b
            x = r[0]
            q3 = np.zeros(3)
            q3[0] = -(sec[L.S_W_DRY] + sec[L.S_W_CONT] * (x < props[L.H_CONT])
                      - sec[L.S_W_BUOY] * (x < props[L.DEPTH]))
            if props[L.SEABED_K] > 0 and x <= 0:
                q3[0] -= props[L.SEABED_K] * x
            rp3, rpp3 = np.zeros(3), np.zeros(3)
            rp3[slots], rpp3[slots] = rp, rpp
            if sec[L.S_DRAG] > 0 and 0 <= x <= props[L.DEPTH]:
                v = props[L.CUR_SPEED] * (x / props[L.DEPTH]) ** props[L.CUR_EXP] * current
                t = rp3 / np.linalg.norm(rp3)
                vn = v - (v @ t) * t
                q3 += sec[L.S_DRAG] * np.linalg.norm(rp3) * np.linalg.norm(vn) * vn
            e = 0.0
            if props[L.EXTENSIBLE]:
                tw_te = (props[L.RHOI_G] * (props[L.H_CONT] - x) * sec[L.S_AREA_I]
                         * (x < props[L.H_CONT])
                         - props[L.RHOW_G] * (props[L.DEPTH] - x) * sec[L.S_AREA_E]
                         * (x < props[L.DEPTH]))
                eps = (lam + sec[L.S_EI] * rpp @ rpp + tw_te) / sec[L.S_EA]
                e = eps + eps**2 / 2
            c3 = torque * np.cross(rp3, rpp3) + np.cross(rp3, m3)
            for k in range(4):
                rows = [k // 2 * ndn + (k % 2) * nd + i for i in range(nd)]
                fe[rows] += w * (sec[L.S_EI] * rpp * ddh[k] + (lam * rp + c3[slots]) * dh[k]
                                 - q3[slots] * h[k])
            cval = (rp @ rp - 1) / 2 - e
            fe[2 * nd] += w * (1 - xi) * cval
            fe[ndn + 2 * nd] += w * xi * cval
    return fe


@pytest.mark.parametrize("nd", [2, 3])
@pytest.mark.parametrize("kw", DLE_CASES, ids=lambda kw: "-".join(kw) or "plain")
@pytest.mark.parametrize("x_mid", [20.0, 40.0, 67.0])
def test_residual_matches_a_numpy_quadrature_of_the_weak_form(nd, kw, x_mid):
    """Each kernel the solves run (the planar one in 2D) against
    :func:`reference_residual`, on elements inside a level and cut by the
    contents level (40 m) or the water surface (67 m)."""
    props, sec = make_props(**kw)
    if nd == 2:
        props[L.CUR_EY], props[L.CUR_EZ] = 0.0, -1.0
    torque = 4.0e4 if nd == 3 and not kw.get("torque_free", True) else 0.0
    rng = np.random.default_rng(13)
    ndn = 2 * nd + 1
    kinds = [np.r_[0:nd, ndn:ndn + nd], np.r_[nd:2 * nd, ndn + nd:ndn + 2 * nd],
             np.array([2 * nd, ndn + 2 * nd])]
    for le in (0.8, 4.0):
        ue = centred_state(nd, rng, le, 0.0 if kw.get("bed_k") else x_mid)
        ue[nd], ue[ndn + nd] = 0.8, 0.7  # steep: crossing the level at x_mid
        crossed = max(crossings(nd, le, ue, props)) > 0.0
        assert crossed == (x_mid != 20.0 and not kw.get("bed_k"))
        fe = np.zeros(ue.size)
        element_force(nd, le, ue, props, sec, np.zeros((0, 2)), torque, fe,
                      np.zeros((ue.size, ue.size)), False)
        ref = reference_residual(nd, le, ue, props, sec, torque)
        for rows in kinds:
            scale = np.abs(ref[rows]).max()
            assert np.max(np.abs(fe[rows] - ref[rows])) <= 1e-11 * scale


def test_power_law_current_and_its_derivative_are_one_smooth_profile():
    """current_speed for the power law V0 (x/d)^p: the profile itself above
    POWER_FLOOR d; below, a quadratic that vanishes at the seabed and meets the
    power law with its value and slope; its derivative is that of the values
    (central differences) on both sides of the floor."""
    from pipelay_fast.kernels.loads import POWER_FLOOR, current_speed

    props, _sec = make_props()
    table = np.zeros((1, 2))
    d, v0, p = props[L.DEPTH], props[L.CUR_SPEED], props[L.CUR_EXP]
    xs = POWER_FLOOR * d
    for x in (0.3 * d, 1e-4 * d, 2.0 * xs):
        v, dv = current_speed(props, table, x)
        assert v == pytest.approx(v0 * (x / d) ** p, rel=1e-14)
        assert dv == pytest.approx(p * v0 * (x / d) ** p / x, rel=1e-14)
    assert current_speed(props, table, 0.0)[0] == 0.0
    below, above = current_speed(props, table, xs * (1 - 1e-12)), current_speed(props, table, xs)
    assert below[0] == pytest.approx(above[0], rel=1e-9)
    assert below[1] == pytest.approx(above[1], rel=1e-9)
    for x in (0.3 * xs, 0.7 * xs, 1.5 * xs, 10.0 * xs):
        h = 1e-4 * xs
        up, down = current_speed(props, table, x + h)[0], current_speed(props, table, x - h)[0]
        fd = (up - down) / (2 * h)
        assert current_speed(props, table, x)[1] == pytest.approx(fd, rel=1e-6)


_PYTHON_ELEMENT = """
import sys
import numpy as np
sys.path.insert(0, {tests!r})
from test_element import make_props, random_state
from pipelay_fast.kernels.assembly import element_force
nd = {nd}
props, sec = make_props(drag=1.2, torque_free=False)
ue = random_state(nd, np.random.default_rng(7))
fe = np.zeros(ue.size)
ke = np.zeros((ue.size, ue.size))
element_force(nd, 1.7, ue, props, sec, np.zeros((0, 2)), 5.0, fe, ke, True)
print(repr(fe.tolist()))
"""


@pytest.mark.parametrize("nd", [2, 3])
def test_the_element_runs_as_python_under_numba_disable_jit(nd):
    """NUMBA_DISABLE_JIT=1 (docs/developers.md: a kernel stepped through in a
    debugger) runs the Python functions: the same element forces as the
    compiled kernel, to round-off."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    code = _PYTHON_ELEMENT.format(tests=str(Path(__file__).parent), nd=nd)
    env = {**os.environ, "NUMBA_DISABLE_JIT": "1"}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         check=True).stdout
    python_fe = np.array(eval(out))  # a list of floats printed by repr
    props, sec = make_props(drag=1.2, torque_free=False)
    ue = random_state(nd, np.random.default_rng(7))
    fe = np.zeros(ue.size)
    ke = np.zeros((ue.size, ue.size))
    element_force(nd, 1.7, ue, props, sec, np.zeros((0, 2)), 5.0, fe, ke, True)
    assert np.allclose(python_fe, fe, rtol=1e-12, atol=1e-9 * np.abs(fe).max())

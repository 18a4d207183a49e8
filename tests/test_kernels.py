"""Kernels tested directly: banded LU, the laid pipe through the Newton kernel,
Newton's quadratic rate."""

from __future__ import annotations

import copy

import numpy as np
import pytest

import pipelay_fast as pf
from pipelay_fast.engine.continuation import run_newton
from pipelay_fast.engine.model import build_props, section_array, sections_of
from pipelay_fast.engine.state import EndConditions, make_problem
from pipelay_fast.kernels import layout as L
from pipelay_fast.kernels.banded import (
    band_factor,
    band_matvec,
    band_solve_many,
    dense_to_band,
)
from pipelay_fast.kernels.contact import (
    friction_forces,
    friction_step,
    friction_track,
    node_arcs,
)
from pipelay_fast.kernels.layout import I_RES
from pipelay_fast.kernels.types import load_factors
from pipelay_fast.output.results import foundation_force
from tests.helpers import EXAMPLES, friction_system


@pytest.mark.parametrize("n,kl,ku", [(4, 1, 1), (7, 2, 3), (60, 9, 9), (200, 13, 13)])
def test_band_lu_solves_like_dense(n, kl, ku):
    rng = np.random.default_rng(n)
    a = np.zeros((n, n))
    for i in range(n):
        for j in range(max(0, i - kl), min(n, i + ku + 1)):
            a[i, j] = rng.normal()
    # zero every third diagonal entry: the saddle structure that needs pivoting
    a[np.arange(0, n, 3), np.arange(0, n, 3)] = 0.0
    a += np.diag(np.where(np.arange(n) % 3 == 0, 0.0, 0.1))
    x = rng.normal(size=n)
    ab = dense_to_band(a, kl, ku)
    b = np.zeros(n)
    band_matvec(ab, kl, ku, x, b)
    np.testing.assert_allclose(b, a @ x, rtol=1e-12, atol=1e-12)
    piv = np.zeros(n, dtype=np.int64)
    assert band_factor(ab, kl, ku, piv) == 0
    many = np.stack([b, 2.0 * b + 1.0, -b], axis=1)
    one = b[:, None].copy()
    band_solve_many(ab, kl, ku, piv, one, 1)
    np.testing.assert_allclose(one[:, 0], np.linalg.solve(a, a @ x), rtol=1e-8, atol=1e-8)
    # several right-hand sides at once: each as it is solved alone
    band_solve_many(ab, kl, ku, piv, many, 3)
    np.testing.assert_array_equal(many[:, 0], one[:, 0])
    np.testing.assert_allclose(many, np.linalg.solve(a, np.stack(
        [a @ x, 2.0 * (a @ x) + 1.0, -(a @ x)], axis=1)), rtol=1e-8, atol=1e-8)
    # border-like columns, zero above a row of their own (the forward
    # substitution skips them there), in no order, one all zero
    cols = np.zeros((n, 4))
    for c, start in enumerate((n - 1, 0, n // 2, n)):
        cols[start:start + 3, c] = rng.normal(size=cols[start:start + 3, c].shape)
    want = np.linalg.solve(a, cols)
    band_solve_many(ab, kl, ku, piv, cols, 4)
    np.testing.assert_allclose(cols, want, rtol=1e-8, atol=1e-8)


def test_band_lu_reports_singular_matrix():
    a = np.array([[1.0, 2.0], [2.0, 4.0]])
    ab = dense_to_band(a, 1, 1)
    assert band_factor(ab, 1, 1, np.zeros(2, dtype=np.int64)) != 0


def laid_pipe(case, nd, n_el=40, length=50.0, tension=2e5, lift=0.3):
    """A straight pipe started `lift` m above the seabed, pinned at its lower
    end and pulled along z at the other; every other node is a seabed contact,
    whose prescribed increment brings it onto the seabed in the first step."""
    ndn = 2 * nd + 1
    s = np.linspace(0.0, length, n_el + 1)
    u = np.zeros(s.size * ndn)
    u[0::ndn] = lift * s / length
    u[nd - 1::ndn] = s
    u[2 * nd - 1::ndn] = 1.0
    u[2 * nd::ndn] = tension
    fix = np.zeros_like(u, dtype=np.int8)
    fix[0] = fix[nd - 1] = 1  # lower end pinned
    if nd == 3:
        fix[1] = 1
    f_node = np.zeros_like(u)
    f_node[(s.size - 1) * ndn + nd - 1] = tension
    on_bed = np.ones(s.size, dtype=np.int8)  # every node on the seabed, the held end aside
    on_bed[0] = 0
    props, table = build_props(case)
    ends = EndConditions(fix, np.zeros_like(u), f_node, -1, s.size - 1, 0.0)
    return make_problem(nd=nd, s=s, props=props, table=table,
                        section=section_array(s, sections_of(case)), u=u, ends=ends,
                        fref=tension, href=1.0, bed_active=on_bed)


@pytest.mark.parametrize("nd", [2, 3])
def test_pipe_laid_on_seabed_under_its_weight(j125, nd):
    pb = laid_pipe(j125, nd)
    status, react, info = run_newton(pb, np.zeros_like(pb.u), 1e-10, 60)
    assert status == L.OK
    ndn = pb.ndn
    w = float(j125.effective_weight(0.0))
    h = np.diff(pb.s)[0]
    assert pb.contacts.bed_active[1:].all()  # every node but the pinned end is a contact
    r = react[0::ndn]
    np.testing.assert_allclose(r[1:-1], w * h, rtol=1e-6)
    np.testing.assert_allclose(r[[0, -1]], 0.5 * w * h, rtol=1e-6)
    assert r.sum() == pytest.approx(w * pb.s[-1], rel=1e-9)
    np.testing.assert_allclose(pb.u[0::ndn], 0.0, atol=1e-12)
    # bending moment EI x'' from the Hermite fields: zero on a flat pipe
    ei = j125.pipe.bending_stiffness
    xp = pb.u[nd::ndn]
    assert np.abs(ei * np.diff(xp) / h).max() < 1e-6 * w * h * h


@pytest.mark.parametrize("nd", [2, 3])
def test_a_residual_at_its_round_off_floor_is_converged(j125, nd):
    """Far from the origin (z + 10 km) on 0.125 m elements the residual cannot
    reach 1e-15: float64 holds the state to eps |r| only, and the residual's
    floor is ~1e-5 of the reference force. Newton stops there (every free row
    within a small multiple of its floor) with the closed-form answer: each
    contact carries the weight of its share of the pipe."""
    pb = laid_pipe(j125, nd, n_el=400)
    pb.u[nd - 1::pb.ndn] += 1e4
    pb.ends.fix_val[nd - 1] = pb.u[nd - 1]
    status, react, info = run_newton(pb, np.zeros_like(pb.u), 1e-15, 60)
    assert status == L.OK
    assert info[I_RES] > 1e-7  # converged on the floor, not on the tolerance
    assert info[1] <= 6
    w = float(j125.effective_weight(0.0))
    h = np.diff(pb.s)[0]
    r = react[0::pb.ndn]
    np.testing.assert_allclose(r[1:-1], w * h, rtol=1e-9)
    assert r.sum() == pytest.approx(w * pb.s[-1], rel=1e-12)


def test_newton_converges_quadratically(j125):
    """One Newton step from a state perturbed by eps leaves a residual ~ eps^2.

    The J125 state is lifted by eps |sin| bumps (so no contact changes) and one
    iteration is taken; the log-log slope of the residual after the step
    against the residual before it is the convergence order (here it comes out
    near 3: the bump direction makes the quadratic term small).
    """
    case = j125.with_changes({"environment.water_depth": 135.0})  # top under water:
    state = pf.solve(case).state  # no weight jump, so the tangent is exact
    ndn = state.ndn
    free = np.ones(state.nn, dtype=bool)
    free[state.contacts.bed_active.astype(bool)] = False
    free[[0, -1]] = False
    bump = np.abs(np.sin(np.linspace(0.0, 3.0 * np.pi, state.nn))) * free
    before, after = [], []
    for eps in (0.01, 0.005, 0.0025, 0.00125):
        pb = copy.deepcopy(state)
        pb.u[0::ndn] += eps * bump
        _, _, info = run_newton(pb, np.zeros_like(pb.u), 1e-14, 1)
        before.append(info[I_RES])
        _, _, info = run_newton(pb, np.zeros_like(pb.u), 1e-14, 1)
        after.append(info[I_RES])
    before, after = np.array(before), np.array(after)
    assert min(after) > 1e-8  # above the round-off floor, so the rates are meaningful
    # halving eps halves the residual before the step (linear) ...
    np.testing.assert_allclose(before[:-1] / before[1:], 2.0, rtol=0.05)
    # ... and the residual after it by 4 or more per halving over the range:
    # order >= 2 - 0.2 (over the whole range: the quadratic and cubic terms,
    # of opposite signs here, make single halvings range from 1.7 to 3.4)
    order = np.log(after[0] / after[-1]) / np.log(before[0] / before[-1])
    assert order >= 1.8, after


def lateral_drag(pb, q0):
    """Total y drag [N] of a current q0 = 1/2 rho C_D D_h V^2 along +y on the
    solved pipe: the component of the current normal to the deformed pipe,
    Gauss-Legendre on each Hermite element (written here, not taken from the
    kernels)."""
    xg, wg = np.polynomial.legendre.leggauss(6)
    xi, wq = 0.5 * (xg + 1.0), 0.5 * wg
    ndn, total = pb.ndn, 0.0
    for e in range(pb.nn - 1):
        le = pb.s[e + 1] - pb.s[e]
        a, b = pb.u[e * ndn:e * ndn + 3], pb.u[(e + 1) * ndn:(e + 1) * ndn + 3]
        pa, pbb = pb.u[e * ndn + 3:e * ndn + 6], pb.u[(e + 1) * ndn + 3:(e + 1) * ndn + 6]
        for t_, w_ in zip(xi, wq, strict=True):
            d = np.array([(-6 * t_ + 6 * t_**2) / le, 1 - 4 * t_ + 3 * t_**2,
                          (6 * t_ - 6 * t_**2) / le, -2 * t_ + 3 * t_**2])
            rp = d[0] * a + d[1] * pa + d[2] * b + d[3] * pbb
            t = rp / np.linalg.norm(rp)
            vn = np.array([0.0, 1.0, 0.0]) - t[1] * t
            total += w_ * le * q0 * np.linalg.norm(vn) * vn[1] * np.linalg.norm(rp)
    return total


@pytest.mark.parametrize("ratio", [0.5, 2.0])
def test_lateral_friction_on_laid_pipe(j125, ratio):
    """Uniform lateral drag q on a laid pipe pinned laterally at both ends.

    q < mu w: every contact's friction spring stays elastic; away from the ends
    each carries q h, so the pipe stands off by d_slip q / (mu w) exactly.
    q > mu w: every contact slides carrying mu W, and the pipe deflects as a
    tensioned beam under q - mu w.
    """
    mu, tension, length = 0.5, 2.0e7, 400.0  # taut: slopes ~6e-3, drag ~ constant
    d_slip = 1e-4
    w = float(j125.effective_weight(0.0))
    q_target = ratio * mu * w
    c_drag = 0.5 * 1025.0 * 1.0 * 0.71  # 1/2 rho C_D D_h of the J125 pipe
    case = j125.with_changes({"environment.current.speed": float(np.sqrt(q_target / c_drag)),
                              "environment.current.heading": 90.0,
                              "environment.current.profile": "uniform",
                              "seabed.lateral_friction": mu, "seabed.friction_slip": d_slip,
                              "pipe.extensible": False})
    pb = laid_pipe(case, 3, n_el=200, length=length, tension=tension)
    ndn = pb.ndn
    pb.ends.fix_mask[(pb.nn - 1) * ndn + 1] = 1  # far end held laterally too
    pb.settings.factors[L.F_CURRENT] = 0.0  # gravity first ...
    status, react, _ = run_newton(pb, np.zeros_like(pb.u), 1e-10, 60)
    assert status == L.OK
    pb.contacts.fric[:, L.FR_W] = np.where(pb.contacts.bed_active != 0, react[0::ndn], 0.0)
    pb.settings.factors[L.F_FRICTION] = 1.0  # ... then the current, against friction
    for factor in (0.25, 0.5, 0.75, 1.0):
        pb.settings.factors[L.F_CURRENT] = factor
        status, react, _ = run_newton(pb, np.zeros_like(pb.u), 1e-10, 80)
        assert status == L.OK
    y = pb.u[1::ndn]
    h = length / 200
    inner = np.arange(1, pb.nn - 1)
    q = c_drag * case.environment.current.speed**2
    assert q == pytest.approx(q_target, rel=1e-12)
    held = react[1::ndn][[0, -1]].sum()  # lateral reactions of the two pinned ends
    friction = react[1::ndn][inner].sum()  # friction forces are reported as reactions
    drag = lateral_drag(pb, q)
    # lateral equilibrium to 1e-8
    assert drag + friction + held == pytest.approx(0.0, abs=1e-8 * q * length)
    if ratio < 1.0:
        assert (pb.contacts.fric[inner, L.FR_DIR] == 0.0).all()
        far = inner[30:-30]  # 60 m from the pinned ends and their boundary layers
        np.testing.assert_allclose(-react[1::ndn][far], q * h, rtol=1e-6)
        np.testing.assert_allclose(y[far], d_slip * q / (mu * w), rtol=1e-6)
        return
    assert (pb.contacts.fric[inner, L.FR_DIR] == -1.0).all()  # friction along -y, against the drag
    np.testing.assert_allclose(pb.contacts.fric[inner, L.FR_W], w * h, rtol=1e-6)
    np.testing.assert_allclose(-react[1::ndn][inner], mu * pb.contacts.fric[inner, L.FR_W],
                               rtol=1e-9)
    assert drag == pytest.approx(q * length, rel=1e-2)  # less where the pipe turns
    # deflection: tensioned beam, pinned ends, load p = q - mu w
    p, ei = q - mu * w, j125.pipe.bending_stiffness
    lam = np.sqrt(ei / tension)
    s = pb.s
    exact = (p * s * (length - s) / (2 * tension)
             + p * lam**2 / tension * (np.cosh((s - length / 2) / lam)
                                       / np.cosh(length / (2 * lam)) - 1.0))
    np.testing.assert_allclose(y, exact, rtol=2e-3, atol=1e-4 * exact.max())


@pytest.mark.parametrize("nd", [2, 3])
def test_curve_node_is_the_exact_tangent_of_the_curve_coordinates(nd):
    """curve_node against a NumPy reference: a smooth banded residual g(u) on
    four nodes, node 1 expressed on the parabola x = a z^2 + b z + c through
    u = Phi(v) (x = f(z) + c, x' = f'(z) z' + c'). The kernel's residual must be
    J^T g and its tangent the central-difference derivative of v -> J(v)^T g(Phi(v))."""
    from pipelay_fast.kernels.assembly import curve_node

    ndn = 2 * nd + 1
    nn = 4
    n = nn * ndn
    kl = ku = 2 * ndn - 1
    rng = np.random.default_rng(nd)
    mat = np.zeros((n, n))
    for i in range(n):
        for j in range(max(0, i - kl), min(n, i + kl + 1)):
            if abs(i // ndn - j // ndn) <= 1:
                mat[i, j] = rng.normal()
    mat = mat + mat.T
    shift = rng.normal(size=n)
    a, b, c = -0.0013, 0.6, 3.0
    node, p, q = 1, ndn, ndn + nd - 1

    def g_of(u):  # nonlinear, with a banded Jacobian
        return mat @ u + 0.3 * np.sin(mat @ u) + shift

    def phi(v):
        u = v.copy()
        z, zp = v[q], v[q + nd]
        u[p] = (a * z + b) * z + c + v[p]
        u[p + nd] = (2 * a * z + b) * zp + v[p + nd]
        return u

    def reduced(v):
        u = phi(v)
        g = g_of(u)
        fp = 2 * a * u[q] + b
        out = g.copy()
        out[q] += fp * g[p] + 2 * a * u[q + nd] * g[p + nd]
        out[q + nd] += fp * g[p + nd]
        return out

    v0 = rng.normal(size=n)
    v0[q], v0[q + nd] = 280.0, 0.9
    u0 = phi(v0)
    g = g_of(u0)
    jac = mat + 0.3 * np.cos(mat @ u0)[:, None] * mat
    ab = dense_to_band(jac, kl, ku)
    curve_node(nd, ab, kl, ku, g, node, 2 * a * u0[q] + b, 2 * a, u0[q + nd], True)
    np.testing.assert_allclose(g, reduced(v0), rtol=1e-13, atol=1e-12)
    h = 1e-6
    fd = np.zeros((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = h
        fd[:, j] = (reduced(v0 + e) - reduced(v0 - e)) / (2 * h)
    kv = kl + ku
    dense = np.zeros((n, n))
    for j in range(n):
        for i in range(max(0, j - ku), min(n - 1, j + kl) + 1):
            dense[i, j] = ab[kv + i - j, j]
    np.testing.assert_allclose(dense, fd, rtol=1e-6, atol=1e-6 * np.abs(fd).max())


def test_friction_normal_force_on_an_elastic_seabed(j125):
    """On an elastic seabed the kernel's normal force W for friction is the
    foundation's force lumped at each node, k (-x) over half of each element
    beside it: the NumPy reference of the profile (results.foundation_force),
    on a graded mesh with nodes above and below the surface; nodes above it
    carry none and keep their anchors where they are."""
    case = j125.with_changes({"seabed.stiffness": 3e5})
    props, _table = build_props(case)
    nd, ndn = 2, 5
    s = np.cumsum(np.r_[0.0, np.linspace(0.5, 3.0, 11)])
    x = np.linspace(-2e-2, 1e-2, s.size)
    u = np.zeros(s.size * ndn)
    u[0::ndn] = x
    u[nd - 1::ndn] = s
    fric = np.full((s.size, L.N_FRIC), 7.0)
    friction_track(nd, u, np.zeros_like(u), props, np.zeros((0, 3)),
                   np.zeros(s.size, dtype=np.int8), fric, s)
    np.testing.assert_allclose(fric[:, L.FR_W], foundation_force(s, x, 3e5), rtol=1e-14)
    above = x >= 0.0
    assert above.any() and (~above).any()
    np.testing.assert_array_equal(fric[above, L.FR_Z], s[above])


@pytest.mark.parametrize("nd", [2, 3])
def test_carrying_a_node_along_the_pipe_is_its_hermite_interpolation(nd):
    """``_pipe_at`` (the state a node the stinger's boundaries move along the
    pipe takes, at the point ``_element_at`` finds) against the NumPy Hermite
    interpolation of a state (``problem.interpolate_state``) on a solved S67,
    at points inside elements, on nodes and in the graded elements; its
    derivative along the pipe at a node, on each side, against a one-sided
    difference of it."""
    from pipelay_fast.engine.state import interpolate_state
    from pipelay_fast.kernels.constraints import _element_at, _pipe_at

    case = pf.load_case("pipelay_fast/examples/s67.toml").with_changes(
        {"solver.dimension": f"{nd}d", "environment.current.speed": 0.0})
    pb = pf.solve(case).state
    s, u, ndn = pb.s, pb.u, 2 * nd + 1
    rng = np.random.default_rng(nd)
    targets = np.concatenate([rng.uniform(s[1], s[-2], 40), s[5:8], s[pb.lo_node] + [-0.3, 0.3]])
    expected = interpolate_state(s, u, nd, targets).reshape(-1, ndn)
    out, scratch, sh = np.zeros(ndn), np.zeros(ndn), np.zeros((3, 4))

    def along(node, t, value):
        e, xi = _element_at(s, node, t)  # searched from a neighbouring node
        _pipe_at(nd, u, s, e, xi, sh, value, scratch)

    for t, want in zip(targets, expected, strict=True):
        along(min(int(np.searchsorted(s, t)) + 2, s.size - 1), t, out)
        np.testing.assert_allclose(out, want, rtol=1e-12, atol=1e-10)
    rate, left, right = np.zeros(ndn), np.zeros(ndn), np.zeros(ndn)
    for node in (pb.lo_node, pb.lo_node - 3, 20):
        for up, sign in ((True, 1.0), (False, -1.0)):
            h = 1e-4 * (s[node + 1] - s[node - 1])
            e, xi = (node, 0.0) if up else (node - 1, 1.0)
            _pipe_at(nd, u, s, e, xi, sh, out, rate)
            np.testing.assert_allclose(out, u[node * ndn:(node + 1) * ndn], rtol=1e-12,
                                       atol=1e-12)
            along(node, s[node] + sign * h, right)
            along(node, s[node] + sign * 2.0 * h, left)
            # one-sided second-order difference: (4 f(h) - f(2h) - 3 f(0)) / 2h
            fd = sign * (4.0 * right - left - 3.0 * u[node * ndn:(node + 1) * ndn]) / (2.0 * h)
            np.testing.assert_allclose(rate, fd, rtol=1e-5, atol=1e-7)


def test_friction_tangent_is_the_derivative_of_its_forces():
    """The seabed friction's rows (lateral and axial, mu = 0.5 and 0.3) of the
    tangent are the central difference of the residual: the springs'
    stiffness and, through the normal force W = G_x (the contact's reaction at
    the present state, not the last iteration's), the x row of the elements'
    tangent times mu clip(d / d_slip). Checked on the solved J125 3D answer
    under a lateral current, its springs set to stick and slide."""
    # a linear current profile, whose drag's tangent is smooth at the seabed
    # (the power law's, exact too, is steep in its lowest POWER_FLOOR of the
    # depth, beyond a central difference's step there)
    case = pf.load_case(EXAMPLES / "j125_3d.toml").with_changes(
        {"seabed.axial_friction": 0.3, "environment.current.profile": "linear"})
    pb = pf.solve(case).state
    pb.settings.factors[:] = load_factors(1.0, True)  # the answer's load: full current, friction on
    nd, ndn = pb.nd, pb.ndn
    s, residual, dense, friction_only = friction_system(pb)

    on_bed = np.flatnonzero(pb.contacts.bed_active)[-8:]  # up to touchdown
    assert np.all(np.abs(pb.u[on_bed * ndn]) < 1e-9)  # on the seabed
    # springs sticking and sliding, each off its kink (the answer's slipping
    # springs sit on it, d_slip from their anchors)
    slip = pb.props[L.FRICTION_SLIP]
    stretch = np.resize([0.5, 1.5, -0.4, -1.3], on_bed.size) * slip
    pb.contacts.fric[on_bed, L.FR_Y] = pb.u[on_bed * ndn + 1] - stretch
    pb.contacts.fric[on_bed, L.FR_Z] = pb.u[on_bed * ndn + nd - 1] + stretch[::-1]
    pb.contacts.fric[on_bed, L.FR_S] = pb.s[on_bed]
    rows = np.concatenate([on_bed * ndn + 1, on_bed * ndn + nd - 1])
    # W is the contact's reaction at the present state: the x row of the
    # elements' residual, here 0.75 to 32 kN
    g_el = residual(pb.u, False, False)[0]
    w = g_el[on_bed * ndn]
    assert np.all(w > 0.0)
    force = g_el[rows] - residual(pb.u, False)[0][rows]  # friction on the pipe
    clip = np.clip(np.concatenate([stretch, -stretch[::-1]]) / slip, -1.0, 1.0)
    mu = np.repeat([pb.props[L.MU_Y], pb.props[L.MU_Z]], on_bed.size)
    np.testing.assert_allclose(force, -mu * clip * np.tile(w, 2), rtol=1e-10)  # 2e-12
    # the friction's share of residual and tangent
    k = dense(residual(pb.u, True)[1]) - dense(residual(pb.u, True, False)[1])
    cols = np.arange(max(0, on_bed[0] - 1) * ndn, min(pb.nn, on_bed[-1] + 2) * ndn)
    for j in cols:
        h = 1e-7 * max(1.0, abs(pb.u[j])) if j % ndn != 2 * nd else 1e-3
        up, dn = pb.u.copy(), pb.u.copy()
        if j % ndn == 0:
            # x on the seabed, where the drag begins: from above, and by 1 nm
            # (x rows' stiffness, 1e10 N/m, would move a reaction of 751 N
            # past zero within 0.1 um)
            up[j] += 1e-9
            fd = (friction_only(up)[rows] - friction_only(dn)[rows]) / 1e-9
        else:
            up[j] += h
            dn[j] -= h
            fd = (friction_only(up)[rows] - friction_only(dn)[rows]) / (2 * h)
        scale = np.abs(k[rows]).max(axis=1) + 1.0
        np.testing.assert_allclose(k[rows, j] / scale, fd / scale, atol=2e-5, err_msg=str(j))


def test_a_step_takes_no_sliding_spring_through_its_stick_zone():
    """friction_step against a NumPy reference: on the solved J125 3D answer
    (lateral friction 0.5, axial 0.3) with its laid springs stretched to
    +-1.5 and +-0.4 d_slip (sliding and sticking), a step that drives some of
    them far the other way is cut where the first sliding one reaches its
    anchor's far side (-d_slip from a spring stretched by +d_slip, and so on);
    after the cut step no sliding spring lies beyond that side, and the one
    that set the cut lies on it, marked: carried back by the next step, it
    stops at its anchor."""
    case = pf.load_case(EXAMPLES / "j125_3d.toml").with_changes({"seabed.axial_friction": 0.3})
    pb = pf.solve(case).state
    pb.settings.factors[:] = load_factors(1.0, True)
    nd, ndn = pb.nd, pb.ndn
    slip = pb.props[L.FRICTION_SLIP]
    s = np.zeros(pb.nn)
    node_arcs(pb.s_el, s)
    on_bed = np.flatnonzero(pb.contacts.bed_active)
    stretch = np.resize([1.5, -0.4, -1.5, 0.4, 2.0], on_bed.size) * slip
    rows = {1: L.FR_Y, nd - 1: L.FR_Z}
    for slot, col in rows.items():
        pb.contacts.fric[on_bed, col] = pb.u[on_bed * ndn + slot] - stretch
    pb.contacts.fric[on_bed, L.FR_S] = s[on_bed]
    rng = np.random.default_rng(4)
    du = np.zeros_like(pb.u)
    for slot in rows:
        du[on_bed * ndn + slot] = -stretch * rng.uniform(0.5, 40.0, on_bed.size)

    def reference(alpha):
        cut = alpha
        for slot, col in rows.items():
            for node in on_bed:
                rel = pb.u[node * ndn + slot] - pb.contacts.fric[node, col]
                if abs(rel) < slip:
                    continue
                edge = -np.sign(rel) * slip
                new = rel + alpha * du[node * ndn + slot]
                if np.sign(new - edge) != np.sign(rel - edge):
                    cut = min(cut, (edge - rel) / du[node * ndn + slot])
        return cut

    stop = np.zeros(pb.nn)
    bed, fric = pb.contacts.bed_active, pb.contacts.fric
    alpha = friction_step(nd, pb.u, du, s, pb.model(), bed, fric, stop, 1.0)
    assert alpha == pytest.approx(reference(1.0), rel=1e-12)
    assert 0.0 < alpha < 1.0
    gaps = []
    for slot, col in rows.items():
        rel = pb.u[on_bed * ndn + slot] - pb.contacts.fric[on_bed, col]
        new = rel + alpha * du[on_bed * ndn + slot]
        sliding = np.abs(rel) >= slip
        beyond = np.sign(new) != np.sign(rel)
        assert np.all(np.abs(new[sliding & beyond]) <= slip * (1.0 + 1e-9))
        gaps.append(np.min(np.abs(np.abs(new[sliding]) - slip)))
    assert min(gaps) < 1e-12
    # the spring that set the cut, and it alone, is marked for the next step
    flags = stop.copy()
    assert np.count_nonzero(flags) == 1
    node = int(np.flatnonzero(flags)[0])
    slot = 1 if flags[node] == 1.0 else nd - 1
    dof = node * ndn + slot
    edge = pb.u[dof] + alpha * du[dof] - pb.contacts.fric[node, rows[slot]]
    assert abs(edge) == pytest.approx(slip, rel=1e-9)
    # next iteration: it lies a hair beyond that edge (as the tracking of its
    # anchor leaves it) and a step carries it back, three times its stretch
    # the other way: it stops at its anchor (1.002 / 3 of the step), not at
    # the other edge (2.002 / 3), where it would again have no stiffness
    pb.u[dof] = pb.contacts.fric[node, rows[slot]] + 1.002 * edge
    back = np.zeros_like(pb.u)
    back[dof] = -3.0 * edge
    model = pb.model()
    alpha = friction_step(nd, pb.u, back, s, model, bed, fric, stop, 1.0)
    assert alpha == pytest.approx(1.002 / 3.0, rel=1e-12)
    assert not stop.any()  # stopped inside its stick zone: no mark
    alpha = friction_step(nd, pb.u, back, s, model, bed, fric, stop, 1.0)
    assert alpha == pytest.approx(2.002 / 3.0, rel=1e-12)  # unmarked: the far edge
    # friction off (gravity's path): no cut
    pb.settings.factors[:] = load_factors(1.0, False)
    assert friction_step(nd, pb.u, du, s, pb.model(), bed, fric, stop, 1.0) == 1.0


def test_an_anchor_interpolated_towards_a_free_neighbour_moves_with_it():
    """Touchdown's node, moved along the pipe past its anchor point, takes its
    anchor between its own and its free neighbour's, and a free node's anchor
    is kept on the node itself (``friction_track``): the sticking spring's
    force then depends on the neighbour's lateral and axial unknowns with
    weight t, and the tangent carries that (checked against a central
    difference of the residual with the neighbour's anchor tracked). Without
    it a random J-lay's current steps converged linearly, 0.70 a step (43
    iterations; 5 with it)."""
    from pipelay_fast.kernels.types import Model

    nd, ndn, nn = 3, 7, 3
    props = np.zeros(L.N_PROPS)
    props[L.MU_Y], props[L.MU_Z], props[L.FRICTION_SLIP] = 0.6, 0.3, 0.05
    model = Model(props, np.zeros((1, 2)), load_factors(1.0, True), np.zeros((nn - 1, L.N_SECTION)))
    s = np.array([0.0, 4.0, 8.0])
    bed = np.array([1, 1, 0], dtype=np.int8)
    u0 = np.zeros(nn * ndn)
    u0[1::ndn] = [0.010, 0.020, 0.031]  # y
    u0[2::ndn] = [0.0, 4.0, 8.0]  # z
    fric = np.zeros((nn, L.N_FRIC))
    fric[:, L.FR_S] = [0.0, 3.0, 8.0]  # node 1's material point lies past its anchor point
    fric[:2, L.FR_Y] = [0.0, 0.005]
    fric[:2, L.FR_Z] = [0.0, 3.0]
    weight = 1.0e4  # the nodes' normal force: the x rows of the residual

    def residual(u, tangent):
        f = fric.copy()
        f[2, L.FR_Y], f[2, L.FR_Z] = u[2 * ndn + 1], u[2 * ndn + 2]  # tracked: on the node
        g = np.zeros(u.size)
        g[0::ndn][:2] = weight
        kl = 2 * ndn - 1
        ab = np.zeros((3 * kl + 1, u.size)) if tangent else np.zeros((1, 1))
        friction_forces(nd, u, g, ab, 2 * kl if tangent else 0, model, bed, f,
                        np.zeros(u.size), s, False)
        return g, ab, kl

    _, ab, kl = residual(u0, True)
    t = (4.0 - 3.0) / (8.0 - 3.0)
    for slot, mu in ((1, 0.6), (2, 0.3)):
        dof, odof = ndn + slot, 2 * ndn + slot
        # the spring sticks: |u - anchor| < d_slip
        anchor = fric[1, [L.FR_Y, L.FR_Z][slot - 1]] * (1 - t) + u0[odof] * t
        assert abs(u0[dof] - anchor) < 0.05
        h = 1e-6
        up, dn = u0.copy(), u0.copy()
        up[odof] += h
        dn[odof] -= h
        fd = (residual(up, False)[0][dof] - residual(dn, False)[0][dof]) / (2 * h)
        assert fd == pytest.approx(-mu * weight / 0.05 * t, rel=1e-6)
        assert ab[2 * kl + dof - odof, odof] == pytest.approx(fd, rel=1e-6)


def _interpolate_state_reference(s_old, u_old, nd, s_new):
    """``problem.interpolate_state`` as NumPy computed it before the kernel
    (:func:`.kernels.geometry.hermite_state`)."""
    ndn = 2 * nd + 1
    idx = np.clip(np.searchsorted(s_old, s_new, side="right") - 1, 0, s_old.size - 2)
    le = s_old[idx + 1] - s_old[idx]
    xi = np.clip((s_new - s_old[idx]) / le, 0.0, 1.0)
    n1 = 1 - 3 * xi**2 + 2 * xi**3
    n2 = le * (xi - 2 * xi**2 + xi**3)
    n3 = 3 * xi**2 - 2 * xi**3
    n4 = le * (-(xi**2) + xi**3)
    d1 = (-6 * xi + 6 * xi**2) / le
    d2 = 1 - 4 * xi + 3 * xi**2
    d3 = (6 * xi - 6 * xi**2) / le
    d4 = -2 * xi + 3 * xi**2
    u = np.zeros(s_new.size * ndn)
    for i in range(nd):
        ra, rb = u_old[i::ndn][idx], u_old[i::ndn][idx + 1]
        pa, pbv = u_old[nd + i::ndn][idx], u_old[nd + i::ndn][idx + 1]
        u[i::ndn] = n1 * ra + n2 * pa + n3 * rb + n4 * pbv
        u[nd + i::ndn] = d1 * ra + d2 * pa + d3 * rb + d4 * pbv
    la, lb = u_old[2 * nd::ndn][idx], u_old[2 * nd::ndn][idx + 1]
    u[2 * nd::ndn] = (1 - xi) * la + xi * lb
    return u


@pytest.mark.parametrize("nd", [2, 3])
def test_the_state_interpolation_kernel_is_its_numpy_reference(nd):
    """interpolate_state (hermite_state) against the NumPy reference, bit for
    bit, on random meshes and states, new nodes inside, on and beyond the
    old mesh's ends; and a cubic centreline interpolated exactly."""
    from pipelay_fast.engine.state import interpolate_state

    rng = np.random.default_rng(nd)
    ndn = 2 * nd + 1
    for _ in range(100):
        n = int(rng.integers(2, 120))
        s_old = np.concatenate([[0.0], np.cumsum(rng.uniform(0.01, 6.0, n - 1))])
        u_old = rng.normal(size=n * ndn)
        inside = rng.uniform(-1.0, s_old[-1] + 1.0, int(rng.integers(1, 150)))
        s_new = np.sort(np.concatenate([inside, s_old[rng.integers(0, n, 3)]]))
        np.testing.assert_array_equal(interpolate_state(s_old, u_old, nd, s_new),
                                      _interpolate_state_reference(s_old, u_old, nd, s_new))
    s_old = np.array([0.0, 1.5, 4.0, 4.5, 9.0])
    cubic = [np.array([0.3, -1.0, 0.2, 0.05]), np.array([1.0, 0.5, -0.1, 0.01]),
             np.array([-2.0, 0.0, 0.3, -0.02])][:nd]
    def state(s):
        u = np.zeros((s.size, ndn))
        for i, c in enumerate(cubic):
            u[:, i] = np.polyval(c[::-1], s)
            u[:, nd + i] = np.polyval(np.polyder(c[::-1]), s)
        u[:, 2 * nd] = 2.0 * s - 1.0
        return u.reshape(-1)
    s_new = np.linspace(0.0, 9.0, 37)
    np.testing.assert_allclose(interpolate_state(s_old, state(s_old), nd, s_new), state(s_new),
                               rtol=1e-12, atol=1e-12)


def _nodal_fields_reference(nd, s, u, clamped):
    """r, r', the curvature vector (3D) and the unit tangent as NumPy computed
    them before :func:`.kernels.geometry.centreline_fields`."""
    ndn = 2 * nd + 1
    nn = s.size
    r = np.stack([u[i::ndn] for i in range(nd)], axis=1)
    rp = np.stack([u[nd + i::ndn] for i in range(nd)], axis=1)
    le = np.diff(s)[:, None]
    chord = r[1:] - r[:-1]
    start = -4.0 / le * rp[:-1] + 6.0 / le**2 * chord - 2.0 / le * rp[1:]
    end = 2.0 / le * rp[:-1] - 6.0 / le**2 * chord + 4.0 / le * rp[1:]
    rpp = np.zeros((nn, nd))
    rpp[:-1] += start
    rpp[1:] += end
    rpp[1:-1] *= 0.5
    edge = np.flatnonzero(clamped[1:] & ~clamped[:-1]) + 1
    if nd == 3:
        rpp[edge, 1] = end[edge - 1, 1]
    zero = np.zeros(nn)
    rp3 = rp if nd == 3 else np.stack([rp[:, 0], zero, rp[:, 1]], axis=1)
    rpp3 = rpp if nd == 3 else np.stack([rpp[:, 0], zero, rpp[:, 1]], axis=1)
    a = np.linalg.norm(rp3, axis=1)
    return r, rp, np.cross(rp3, rpp3) / a[:, None] ** 3, rp3 / a[:, None]


@pytest.mark.parametrize("nd", [2, 3])
def test_the_centreline_fields_kernel_against_numpy_and_a_circle(nd):
    """results.nodal_fields (centreline_fields) against the NumPy reference
    on random states, with clamped nodes (3D: the free side's y'' there), to
    round-off; and on a circle of radius R sampled exactly on a graded mesh,
    the curvature vector's error falls as h^2 towards (0, -1/R, 0) (the
    circle turning from +x towards +z)."""
    from pipelay_fast.output.results import nodal_fields

    rng = np.random.default_rng(10 + nd)
    ndn = 2 * nd + 1
    for _ in range(40):
        n = int(rng.integers(3, 80))
        s = np.concatenate([[0.0], np.cumsum(rng.uniform(0.05, 5.0, n - 1))])
        u = rng.normal(size=n * ndn)
        u[nd::ndn] += 2.0  # (r' away from zero)
        clamped = rng.random(n) < 0.2
        got = nodal_fields(nd, s, u, clamped)
        want = _nodal_fields_reference(nd, s, u, clamped)
        for g, w in zip(got, want, strict=True):
            np.testing.assert_allclose(g, w, rtol=1e-13, atol=1e-13 * np.abs(w).max())
    radius = 50.0
    errors = []
    for n in (11, 21, 41):
        s = np.linspace(0.0, 40.0, n) ** 1.2
        theta = s / radius
        nodal = np.zeros((n, ndn))
        nodal[:, 0], nodal[:, nd - 1] = radius * np.sin(theta), radius * (1.0 - np.cos(theta))
        nodal[:, nd], nodal[:, 2 * nd - 1] = np.cos(theta), np.sin(theta)
        _r, _rp, kvec, t3 = nodal_fields(nd, s, nodal.reshape(-1))
        np.testing.assert_allclose(t3[:, 0], np.cos(theta), atol=1e-14)
        errors.append(np.abs(kvec - [0.0, -1.0 / radius, 0.0]).max())
    rates = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert (rates > 1.8).all(), (errors, rates)

"""The homotopy's offset (:func:`.continuation._residual`): the residual G
of the first guess with its constrained rows removed, from the Newton
kernel's own evaluation (:func:`.newton._free_residual`), but those of the
stinger's curve, which keep G.

Checked against a NumPy reference built here from the geometry: at each
node, the columns of a matrix M are the physical displacements (global
frame) of the node's unknowns as the kernel holds them, and the offset g
must do no work along a removed one and the work of the plain residual G
(the element chain with the seabed's friction, nothing constrained) along
every other: M^T g = mask(M^T G). Removed: the held ends (in their
frames), the seabed's contacts (x and x' on the flat seabed, and x' at the
lower end), the lateral hold in 3D (y and y' over the stinger's span), and
each bearing rigid point's normal, (cos phi, -sin phi) in (x, z) with
phi = atan2(x', z') the pipe's tangent (and y on a V roller). The stinger's
contacts are in curve coordinates (x = f(z) + c, x' = f'(z) z' + c': the
unknown c moves the node along x at fixed z, its z slides it along the
curve, (f', 1) in (x, z) and f'' z' in x'), f from the stinger's
coefficients: the offset keeps G there, and the kernel's way back from
these coordinates (:func:`.system._from_nodal_frames`) is checked on its
own with c and c' removed: the part removed is then the curve's reaction,
which does no work along the curve's tangent.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import pipelay_fast as pf
from pipelay_fast.engine.continuation import _residual, homotopy
from pipelay_fast.engine.problem import build_problem
from pipelay_fast.kernels import layout as L
from pipelay_fast.kernels.contact import friction_forces
from pipelay_fast.kernels.layout import B_PT
from pipelay_fast.kernels.system import _from_nodal_frames, system_2d, system_3d
from pipelay_fast.kernels.tuning import LATERAL_HYSTERESIS
from tests.helpers import EXAMPLES
from tests.test_points import beam_on_points


def plain_residual(pb):
    """G at ``pb.u`` (global frame): the elements, the nodal loads, the
    bottom tension and the friction springs; no row constrained."""
    g = np.zeros_like(pb.u)
    no_band = np.zeros((2, 2)).T
    system = system_2d if pb.nd == 2 else system_3d
    system(pb.s_el, pb.u, pb.model(), np.full(pb.nn - 1, pb.props[L.TORQUE]), no_band, g,
           pb.kernel_ends(np.zeros_like(pb.u)), False, np.zeros((pb.bnodes.size, pb.nn)),
           np.full(pb.bnodes.size, -1, dtype=np.int64), np.zeros((pb.bnodes.size, 1)))
    friction_forces(pb.nd, pb.u, g, no_band, 0, pb.model(), pb.contacts.active[L.ROW_BED],
                    pb.contacts.fric, np.zeros_like(pb.u), pb.s, False)
    return g


def _turn(m, p, q, phi):
    """Columns p and q of M for a pair (x, z) turned by ``phi`` (the
    kernel's frame: normal x cos phi - z sin phi, tangent x sin phi + z cos phi)."""
    c, s = math.cos(phi), math.sin(phi)
    m[p, p], m[q, p] = c, -s
    m[p, q], m[q, q] = s, c


def stinger_slope(case):
    """f'(z) and f'' of the stinger x = a z^2 + b z + c through its ends."""
    st = case.lay.stinger
    (x_l, z_l), (x_u, z_u) = st.lower, st.upper
    b = ((x_u - x_l) - st.a * (z_u**2 - z_l**2)) / (z_u - z_l)
    return (lambda z: 2.0 * st.a * z + b), 2.0 * st.a, (z_l, z_u)


def node_maps(pb, case=None, hold_curve=False):
    """Per node (M, the columns removed), the module docstring's rules,
    from the problem's data before any kernel has set its frames
    (``hold_curve``: the curve's c and c' removed too)."""
    nd, ndn, u = pb.nd, pb.ndn, pb.u
    c = pb.contacts
    fix = pb.ends.fix_mask.reshape(pb.nn, ndn) != 0
    bed = c.active[L.ROW_BED] != 0
    curve = c.active[L.ROW_CURVE] != 0 if c.kind[L.ROW_CURVE] == L.SUP_CURVE else bed & False
    top = pb.ends.top_node
    stinger = case is not None and getattr(case.lay, "stinger", None) is not None
    if stinger:
        fp, fpp, (z_l, z_u) = stinger_slope(case)
    maps = []
    for k in range(pb.nn):
        base = k * ndn
        m = np.eye(ndn)
        held = fix[k].copy()
        for blk, phi in ((0, c.phi_r[k]), (1, c.phi_rp[k])):
            if phi != 0.0:
                _turn(m, blk * nd, blk * nd + nd - 1, phi)
        if bed[k]:
            held[0] = held[nd] = True
        if k == 0 and c.kind[L.ROW_BED] == L.SUP_SEABED:
            held[nd] = True
        if curve[k] and k != top:
            z = u[base + nd - 1]
            m[0, nd - 1] = fp(z)
            m[nd, nd - 1] = fpp * u[base + 2 * nd - 1]
            m[nd, 2 * nd - 1] = fp(z)
            held[0] = held[0] or hold_curve
            held[nd] = held[nd] or (hold_curve and k > 0 and curve[k - 1])
        if nd == 3 and stinger and k != top and not fix[k, 0]:
            h = pb.s_el[min(k, pb.nn - 2)] if k == 0 else min(pb.s_el[k - 1],
                                                               pb.s_el[min(k, pb.nn - 2)])
            if z_l - LATERAL_HYSTERESIS * h <= u[base + nd - 1] <= z_u:
                held[1] = held[nd + 1] = True
        maps.append((m, held))
    for b in range(B_PT, pb.bnodes.size):
        k = int(pb.bnodes[b])
        point = c.geom[b]
        if k >= 0 and point[L.PT_BEAR] != 0.0:
            m, held = maps[k]
            _turn(m, 0, nd - 1, math.atan2(u[k * ndn + nd], u[k * ndn + 2 * nd - 1]))
            held[0] = True
            held[1] = held[1] or (nd == 3 and point[L.PT_HOLD] != 0.0)
    return maps


def check(pb, case=None):
    """M^T g = mask(M^T G) at every node; returns, per node, the largest
    |M^T G| on its constrained columns [N, N m] (what the offset leaves out)."""
    maps = node_maps(pb, case)
    g_plain = plain_residual(pb)
    g, _te = _residual(pb)
    tol = 1e-9 * np.abs(g_plain).max()
    removed = np.zeros(pb.nn)
    for k, (m, held) in enumerate(maps):
        rows = slice(k * pb.ndn, (k + 1) * pb.ndn)
        want = m.T @ g_plain[rows]
        removed[k] = np.abs(want[held]).max(initial=0.0)
        want[held] = 0.0
        np.testing.assert_allclose(m.T @ g[rows], want, rtol=0.0, atol=tol, err_msg=f"node {k}")
    return removed


@pytest.mark.parametrize("name", ["s67.toml", "s67_3d.toml", "j125_3d.toml"])
def test_the_offset_has_no_component_along_a_constraint(name):
    """The first guess of an S-lay (seabed, the stinger's curve, in 3D the
    lateral hold) and of a J-lay: every removed direction removed, every
    other one the plain residual's."""
    case = pf.load_case(EXAMPLES / name)
    pb = build_problem(case)
    assert check(pb, case).max() > 1.0  # (the guess is out of balance on its constraints)


@pytest.mark.parametrize("name", ["s67.toml", "s67_3d.toml"])
def test_the_curve_coordinates_back_to_the_global_frame(name):
    """M^T G with the curve's c and c' zeroed, back through the kernel's
    inverse of its curve coordinates: M^T of it is that, at every node."""
    case = pf.load_case(EXAMPLES / name)
    pb = build_problem(case)
    maps = node_maps(pb, case, hold_curve=True)
    _residual(pb)  # (the kernel's frames and lateral hold at the guess)
    g_plain = plain_residual(pb)
    h = np.empty_like(g_plain)
    for k, (m, held) in enumerate(maps):
        rows = slice(k * pb.ndn, (k + 1) * pb.ndn)
        h[rows] = np.where(held, 0.0, m.T @ g_plain[rows])
    g = h.copy()
    _from_nodal_frames(pb.nd, g, pb.u, pb.kernel_supports())
    curve = np.flatnonzero(pb.contacts.active[L.ROW_CURVE])
    assert curve.size > 10 and np.median(np.abs(g_plain[curve * pb.ndn])) > 1.0
    tol = 1e-9 * np.abs(g_plain).max()
    for k, (m, _held) in enumerate(maps):
        rows = slice(k * pb.ndn, (k + 1) * pb.ndn)
        np.testing.assert_allclose(m.T @ g[rows], h[rows], rtol=0.0, atol=tol,
                                   err_msg=f"node {k}")


@pytest.mark.parametrize("nd", [2, 3])
def test_a_bearing_points_normal_is_removed(nd):
    """A beam on three rigid points, its tangent turned at the points' nodes
    (so that their normals are not the axes), the last a V roller in 3D:
    the offset does no work along each normal (nor along y on the roller)."""
    pb = beam_on_points(nd=nd)
    ndn = 2 * nd + 1
    pb.contacts.geom[B_PT + 2, L.PT_HOLD] = 1.0
    for j, b in enumerate(range(B_PT, pb.bnodes.size)):
        k = int(pb.bnodes[b])
        pb.u[k * ndn + nd] = 0.2 + 0.1 * j  # x': tangent at atan2(x', 1)
        if nd == 3:
            pb.u[k * ndn + 1] = 1e-3  # y: an out-of-balance lateral force at the roller
    nodes = pb.bnodes[B_PT:]
    assert (check(pb)[nodes] > 1.0).all()


def top_tension(pb, g):
    """The top's effective tension [N]: the top reaction G (global frame)
    along the pipe's tangent there."""
    base = pb.ends.top_node * pb.ndn
    t = pb.u[base + pb.nd:base + 2 * pb.nd]
    return float(g[base:base + pb.nd] @ t / np.linalg.norm(t))


@pytest.mark.parametrize("name", ["s67.toml", "j125_3d.toml"])
def test_at_load_factor_0_the_guess_solves_the_top_tension_row(name):
    """The guess built for 580 kN, its target then doubled: at load factor
    0 the homotopy's top target is the guess's own top tension (the plain
    residual's top reaction along the tangent), so that its top row holds
    as its free rows do (:func:`check`); it runs linearly to the case's
    target, which it is, to the bit, at 1."""
    case = pf.load_case(EXAMPLES / name)
    pb = build_problem(case)
    target = 2.0 * pb.ends.top_target
    pb.ends.top_target = target
    te0 = top_tension(pb, plain_residual(pb))
    assert abs(te0 - target) > 0.4 * target  # (the guess is far from the target)
    load = homotopy(pb)
    offset, _ = load(0.0, False)
    np.testing.assert_allclose(pb.kernel_ends(offset).top_target, te0, rtol=1e-9)
    check(pb, case)  # (the offset: minus the free rows' residual)
    load(0.25, False)
    np.testing.assert_allclose(pb.kernel_ends(offset).top_target, te0 + 0.25 * (target - te0),
                               rtol=1e-12)
    load(1.0, False)
    assert pb.kernel_ends(offset).top_target == target

"""Rigid point contacts, rows of the supports' table (``SUP_POINT``, layout ``PT_*``).

Each point holds the pipe from below: a node follows the material point
over it (a boundary unknown of Newton) and the complementarity
min(R, c g) = 0 chooses whether it bears. The stinger's tip is the first
point of an S-lay; here a straight beam rests on three points, and the
answers are checked against the continuous beam of small-deflection theory:
Clapeyron's three-moment equations for the reactions, and the double
integral of M/EI for a clearance.

The beam is the half (z >= 0) of a symmetric beam, since the engine's lower
end (node 0) keeps its slope at zero as a laid pipe's: that is the symmetry
plane's condition (slope zero, shear free). The full beam rests on supports
at +-5, +-15 and +-25 m, with 3 m overhangs. EI is large enough that the
deflections are at most 1e-4 of the spans (44 um on three points, 1.2 mm
spanning 20 m), so small-deflection theory holds to about 1e-8.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid

from pipelay_fast.engine.continuation import run_newton
from pipelay_fast.engine.state import EndConditions, make_problem
from pipelay_fast.kernels import layout as L
from pipelay_fast.kernels.layout import B_PT
from pipelay_fast.kernels.types import load_factors

Q = 1000.0  # weight per length [N/m]
EI = 1e9  # [N m2]
POINTS = (5.0, 15.0, 25.0)  # z of the half model's points [m]
END = 28.0  # the free end [m]
X0 = 1.0  # height of the points [m]


def beam_on_points(drop=(0.0, 0.0, 0.0), h=0.5, nd=2):
    """The half beam, straight at the points' height, on nodes ``h`` [m]
    apart; point j lowered by ``drop[j]`` [m]; every point starts bearing.
    In 3D the symmetry plane's end also holds y and y' (nothing loads the
    pipe laterally; they take out its rigid motions)."""
    ndn = 2 * nd + 1
    s = np.linspace(0.0, END, int(round(END / h)) + 1)
    nn = s.size
    u = np.zeros(nn * ndn)
    u[0::ndn] = X0
    u[nd - 1::ndn] = s
    u[2 * nd - 1::ndn] = 1.0
    props = np.zeros(L.N_PROPS)
    props[L.EI_REF] = EI
    section = np.zeros((nn - 1, L.N_SECTION))
    section[:, L.S_EI], section[:, L.S_EA], section[:, L.S_W_DRY] = EI, 1e12, Q
    props[L.H_CONT] = -1.0  # no contents; the depth 0: in air
    props[L.EXTENSIBLE] = 1.0
    fix = np.zeros(nn * ndn, dtype=np.int8)
    fix[nd - 1] = 1  # z at the symmetry plane
    if nd == 3:
        fix[1] = fix[nd + 1] = 1
    pts = np.zeros((len(POINTS), L.N_PT))
    pts[:, L.PT_X] = X0 - np.asarray(drop)
    pts[:, L.PT_Z] = POINTS
    pts[:, L.PT_BEAR] = 1.0
    ends = EndConditions(fix, np.zeros(nn * ndn), np.zeros(nn * ndn), -1, nn - 1, 0.0)
    pb = make_problem(nd=nd, s=s, props=props, table=np.zeros((1, 2)), section=section, u=u,
                      ends=ends, fref=Q * 10.0, href=h, points=pts,
                      factors=load_factors(0.0, False))
    # no touchdown, no lift-off; a node on each point, its zone 4 m each side
    nodes = [-1, -1] + [int(np.argmin(np.abs(s - z))) for z in POINTS]
    pb.mesh.follow(nodes, [(0.0, 0.0)] * 2 + [(4.0, 4.0)] * len(POINTS))
    return pb


def three_moment(z, c):
    """Reactions [N] of a beam under Q on supports ``z`` (sorted) with
    overhangs ``c`` = (left, right) [m]: the support moments from
    Clapeyron's equations, M_{i-1} L_{i-1} + 2 M_i (L_{i-1} + L_i) +
    M_{i+1} L_i = -Q (L_{i-1}^3 + L_i^3) / 4 (sagging positive), the end
    supports' moments those of the overhangs; then each span's end shears."""
    z = np.asarray(z, dtype=float)
    n = z.size
    span = np.diff(z)
    m = np.zeros(n)
    m[0], m[-1] = -Q * c[0] ** 2 / 2.0, -Q * c[1] ** 2 / 2.0
    a = np.zeros((n - 2, n - 2))
    rhs = np.zeros(n - 2)
    for i in range(1, n - 1):
        a[i - 1, i - 1] = 2.0 * (span[i - 1] + span[i])
        rhs[i - 1] = -Q * (span[i - 1] ** 3 + span[i] ** 3) / 4.0
        for j, lj in ((i - 1, span[i - 1]), (i + 1, span[i])):
            if 0 < j < n - 1:
                a[i - 1, j - 1] = lj
            else:
                rhs[i - 1] -= m[j] * lj
    m[1:-1] = np.linalg.solve(a, rhs)
    r = np.zeros(n)
    r[0] += Q * c[0]
    r[-1] += Q * c[1]
    for i, li in enumerate(span):
        r[i] += Q * li / 2.0 + (m[i + 1] - m[i]) / li
        r[i + 1] += Q * li / 2.0 - (m[i + 1] - m[i]) / li
    return r


def sag_between(z, r, c_left, z_a, z_b, z_at):
    """Height [m] at ``z_at`` of the beam on supports ``z`` with reactions
    ``r``, relative to the chord between supports z_a and z_b: x'' = M/EI
    integrated twice (M from statics, sagging positive, free left end
    c_left before the first support)."""
    zz = np.linspace(z_a, z_b, 200001)
    m = -Q * (zz - (z[0] - c_left)) ** 2 / 2.0
    for zi, ri in zip(z, r, strict=True):
        m += ri * np.clip(zz - zi, 0.0, None)
    slope = cumulative_trapezoid(m / EI, zz, initial=0.0)
    x = cumulative_trapezoid(slope, zz, initial=0.0)
    x -= x[-1] * (zz - z_a) / (z_b - z_a)  # on both supports
    return float(np.interp(z_at, zz, x))


def solve(pb):
    status, _react, info = run_newton(pb, np.zeros_like(pb.u), 1e-11, 30)
    assert status == L.OK, L.STATUS_TEXT[status]
    return int(info[1])


def node_over(pb, j):
    """(x, z) [m] of the node over point j."""
    base = int(pb.bnodes[B_PT + j]) * pb.ndn
    return pb.u[base], pb.u[base + pb.nd - 1]


@pytest.mark.parametrize("nd", [2, 3])
def test_three_points_carry_the_continuous_beam(nd):
    pb = beam_on_points(nd=nd)
    n_it = solve(pb)
    full = np.concatenate([-np.array(POINTS[::-1]), POINTS])
    ref = three_moment(full, (END - POINTS[-1],) * 2)[len(POINTS):]
    np.testing.assert_allclose(pb.contacts.points[:, L.PT_R], ref, rtol=1e-9)  # measured 1e-10
    assert np.all(pb.contacts.points[:, L.PT_BEAR] == 1.0)
    # the weight (measured 2e-11: the reactions are Newton's last linearised ones)
    assert pb.contacts.points[:, L.PT_R].sum() == pytest.approx(Q * END, rel=1e-10)
    for j, zp in enumerate(POINTS):  # each node over its point, on it
        x, z = node_over(pb, j)
        assert z == pytest.approx(zp, abs=1e-9)
        assert x == pytest.approx(X0, abs=1e-9)
    assert n_it <= 4  # linear but for the boundaries: Newton's quadratic convergence


@pytest.mark.parametrize("h", [0.5, 0.35])
def test_a_point_below_the_beam_carries_nothing_and_reports_its_clearance(h):
    """The middle point 5 mm low: the beam spans from 5 to 25 m over it,
    sagging 1.2 mm there; the point's complementarity releases it (it started
    bearing) and the node over it gives the clearance. The mesh of 0.35 m
    puts no node on it at the start."""
    drop = 5e-3
    pb = beam_on_points(drop=(0.0, drop, 0.0), h=h)
    solve(pb)
    outer = (-POINTS[2], -POINTS[0], POINTS[0], POINTS[2])
    r = three_moment(outer, (END - POINTS[-1],) * 2)
    assert pb.contacts.points[1, L.PT_BEAR] == 0.0 and pb.contacts.points[1, L.PT_R] == 0.0
    np.testing.assert_allclose(pb.contacts.points[[0, 2], L.PT_R], r[2:],
                               rtol=1e-7)  # measured 2e-8
    sag = sag_between(outer, r, END - POINTS[-1], POINTS[0], POINTS[2], POINTS[1])
    assert 1e-3 < -sag < drop / 2.0  # the beam sags there, by less than the drop
    # the node over the point: on the pipe's normal through it (the pipe's
    # slope there, 2.2e-5, puts it 8e-8 m off the vertical), its clearance
    # along that normal the vertical one to the slope squared (measured 3e-8)
    k = int(pb.bnodes[B_PT + 1])
    x, z, xp, zp = pb.u[5 * k:5 * k + 4]
    t = np.array([xp, zp]) / np.hypot(xp, zp)
    d = np.array([x - pb.contacts.points[1, L.PT_X], z - POINTS[1]])
    assert abs(t @ d) < 1e-12
    assert abs(z - POINTS[1]) < 1e-6
    gap = t[1] * d[0] - t[0] * d[1]
    assert gap == pytest.approx(drop + sag, rel=1e-6)

"""Geometry of a centreline given by its nodal unknowns (cubic Hermite r,
r'): the state carried onto another mesh (:func:`hermite_state`), the nodal
fields the results read (:func:`centreline_fields`) and the clearance of a
point from the pipe (:func:`point_clearance`, for
:func:`pipelay_fast.design.tip_clearance`, which states the method).

Kernels because every solve calls them on arrays of some hundred nodes,
where NumPy would spend its time in the overhead of a few dozen small
operations."""

from __future__ import annotations

import math

from ._jit import jit
from .roots import bracketed_step


@jit(_nrt=False)
def _at(r, rp, s, e, xi, tip, gap, slope, curve):
    """The element ``e``'s cubic Hermite at ``xi`` in [0, 1]: gap = r - tip,
    slope = dr/dxi and curve = d2r/dxi2 (nodal slopes scaled by its length);
    returns |gap|^2."""
    le = s[e + 1] - s[e]
    g2 = 0.0
    for i in range(r.shape[1]):
        p0 = r[e, i]
        p1 = r[e + 1, i]
        m0 = le * rp[e, i]
        m1 = le * rp[e + 1, i]
        c2 = 3.0 * (p1 - p0) - 2.0 * m0 - m1
        c3 = 2.0 * (p0 - p1) + m0 + m1
        gap[i] = ((c3 * xi + c2) * xi + m0) * xi + p0 - tip[i]
        slope[i] = (3.0 * c3 * xi + 2.0 * c2) * xi + m0
        curve[i] = 6.0 * c3 * xi + 2.0 * c2
        g2 += gap[i] * gap[i]
    return g2


@jit(_nrt=False)
def _foot_rate(r, rp, s, e, xi, tip, gap, slope, curve):
    """(h, dh/dxi) at ``xi`` on element ``e``: h = (r - tip) . dr/dxi, zero
    at the foot of the normal from ``tip``."""
    _at(r, rp, s, e, xi, tip, gap, slope, curve)
    h = 0.0
    rate = 0.0
    for i in range(r.shape[1]):
        h += gap[i] * slope[i]
        rate += slope[i] * slope[i] + gap[i] * curve[i]
    return h, rate


@jit(_nrt=False)
def _foot(r, rp, s, e, tip, samples, gap, slope, curve):
    """xi in [0, 1] of the point of element ``e`` nearest ``tip``: the
    nearest of ``samples`` points, then the root of h = (r - tip) . dr/dxi
    between its neighbours (h < 0 below it and > 0 above it: the distance
    falls, then rises), by Newton guarded by bisection to round-off
    (:func:`.roots.bracketed_step`); where h does not change sign so, the
    nearest of the sample and its neighbours (an end of the element when
    the distance falls towards it)."""
    x = 0.0
    nearest = math.inf
    j_near = 0
    for j in range(samples):
        g2 = _at(r, rp, s, e, j / (samples - 1), tip, gap, slope, curve)
        if g2 < nearest:
            nearest = g2
            j_near = j
            x = j / (samples - 1)
    lo = max(j_near - 1, 0) / (samples - 1)
    hi = min(j_near + 1, samples - 1) / (samples - 1)
    h_lo, _rate = _foot_rate(r, rp, s, e, lo, tip, gap, slope, curve)
    h_hi, _rate = _foot_rate(r, rp, s, e, hi, tip, gap, slope, curve)
    if not h_lo < 0.0 < h_hi:
        for end in (lo, hi):
            g2 = _at(r, rp, s, e, end, tip, gap, slope, curve)
            if g2 < nearest:
                nearest = g2
                x = end
        return x
    last = math.inf
    while True:
        h, rate = _foot_rate(r, rp, s, e, x, tip, gap, slope, curve)
        if h == 0.0:
            return x
        x, lo, hi, last, done = bracketed_step(x, h, rate, lo, hi, -1.0, last)
        if done:
            return x


@jit(entry=True, _nrt=False)
def point_clearance(r, rp, s, tip, up, samples, gap, slope, curve):
    """Signed distance [m] from ``tip`` to the centreline (nodes ``r``,
    slopes ``rp``, arc lengths ``s``), sign by ``up``: the nearest of the
    feet of the normal (:func:`_foot`, each element sampled at ``samples``
    points) on the four elements around the node nearest the tip; ``gap``,
    ``slope``, ``curve`` are scratch of length nd."""
    nn = s.shape[0]
    nd = r.shape[1]
    near = 0
    best_d = math.inf
    for k in range(nn):
        d = 0.0
        for i in range(nd):
            d += (r[k, i] - tip[i]) ** 2
        if d < best_d:
            best_d = d
            near = k
    best = math.inf
    best_sign = 1.0
    for e in range(max(near - 2, 0), min(near + 2, nn - 1)):
        x = _foot(r, rp, s, e, tip, samples, gap, slope, curve)
        g2 = _at(r, rp, s, e, x, tip, gap, slope, curve)
        length = math.sqrt(g2)
        if length < best:
            best = length
            side = 0.0
            for i in range(nd):
                side += gap[i] * up[i]
            best_sign = math.copysign(1.0, side)
    return best_sign * best


@jit(entry=True, _nrt=False)
def hermite_state(idx, xi, xi2, xi3, le, u_old, nd, u):
    """The state at new nodes (:func:`pipelay_fast.problem.interpolate_state`
    gives each one's old element ``idx``, its place ``xi`` in it, ``xi2`` =
    xi**2 and ``xi3`` = xi**3 as NumPy computes them, and the element's
    length ``le`` [m]): r and r' the old element's cubic Hermite and its
    slope, lambda linear; into ``u`` (n_new * (2 nd + 1)). Each value as
    the NumPy expressions gave it, to the bit (the powers are NumPy's: its
    vectorised xi**3 is not libm's pow)."""
    ndn = 2 * nd + 1
    for j in range(idx.shape[0]):
        a = idx[j] * ndn
        b = a + ndn
        x1, x2, x3, h = xi[j], xi2[j], xi3[j], le[j]
        n1 = 1 - 3 * x2 + 2 * x3
        n2 = h * (x1 - 2 * x2 + x3)
        n3 = 3 * x2 - 2 * x3
        n4 = h * (-x2 + x3)
        d1 = (-6 * x1 + 6 * x2) / h
        d2 = 1 - 4 * x1 + 3 * x2
        d3 = (6 * x1 - 6 * x2) / h
        d4 = -2 * x1 + 3 * x2
        out = j * ndn
        for i in range(nd):
            ra, pa = u_old[a + i], u_old[a + nd + i]
            rb, pb = u_old[b + i], u_old[b + nd + i]
            u[out + i] = n1 * ra + n2 * pa + n3 * rb + n4 * pb
            u[out + nd + i] = d1 * ra + d2 * pa + d3 * rb + d4 * pb
        u[out + 2 * nd] = (1 - x1) * u_old[a + 2 * nd] + x1 * u_old[b + 2 * nd]


@jit(_nrt=False)
def _end_curvature(s, r, rp, e, i, start):
    """Component ``i`` of element ``e``'s Hermite r'' [1/m] at its start
    (xi = 0) or end (xi = 1)."""
    le = s[e + 1] - s[e]
    chord = r[e + 1, i] - r[e, i]
    if start:
        return -4.0 / le * rp[e, i] + 6.0 / (le * le) * chord - 2.0 / le * rp[e + 1, i]
    return 2.0 / le * rp[e, i] - 6.0 / (le * le) * chord + 4.0 / le * rp[e + 1, i]


@jit(entry=True, _nrt=False)
def centreline_fields(nd, s, u, clamped, r, rp, rpp, kvec, t3):
    """r, r' and r'' at the nodes [m, -, 1/m] into ``r``, ``rp``, ``rpp``
    (nn, nd); in (x, y, z), the plane's y = 0 embedded, the curvature vector
    (r' x r'')/|r'|^3 [1/m] and the unit tangent into ``kvec``, ``t3`` (nn, 3).

    r'' is each element's Hermite r'' at its ends, averaged over the two
    elements of a node, but at a node in ``clamped`` (nn,) bool whose element
    below is not (its lateral slope held there and the element below free,
    as at the stinger's tip under the lateral hold): the held side carries
    the lateral constraint's couple, so y'' there is the free side's; x''
    and z'' are averaged as elsewhere, so that 3D without a lateral load
    reports what 2D does."""
    ndn = 2 * nd + 1
    nn = s.shape[0]
    for k in range(nn):
        for i in range(nd):
            r[k, i] = u[k * ndn + i]
            rp[k, i] = u[k * ndn + nd + i]
            rpp[k, i] = 0.0
    for e in range(nn - 1):
        for i in range(nd):
            rpp[e, i] += _end_curvature(s, r, rp, e, i, True)
            rpp[e + 1, i] += _end_curvature(s, r, rp, e, i, False)
    for k in range(1, nn - 1):
        for i in range(nd):
            rpp[k, i] *= 0.5
    if nd == 3:
        for k in range(1, nn):
            if clamped[k] and not clamped[k - 1]:
                rpp[k, 1] = _end_curvature(s, r, rp, k - 1, 1, False)
    zi = nd - 1
    for k in range(nn):
        xp, zp = rp[k, 0], rp[k, zi]
        xpp, zpp = rpp[k, 0], rpp[k, zi]
        yp = rp[k, 1] if nd == 3 else 0.0
        ypp = rpp[k, 1] if nd == 3 else 0.0
        a = math.sqrt(xp * xp + yp * yp + zp * zp)
        a3 = a * a * a
        kvec[k, 0] = (yp * zpp - zp * ypp) / a3
        kvec[k, 1] = (zp * xpp - xp * zpp) / a3
        kvec[k, 2] = (xp * ypp - yp * xpp) / a3
        t3[k, 0] = xp / a
        t3[k, 1] = yp / a
        t3[k, 2] = zp / a

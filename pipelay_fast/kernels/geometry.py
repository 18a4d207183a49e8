"""Geometry of a solved centreline that the results read: the clearance of a
point from the pipe (:func:`pipelay_fast.design.tip_clearance`, which states
the method). A kernel because every S-lay summary asks for it: in NumPy its
few dozen calls on arrays of 4 x 33 values took 0.1 ms a solve."""

from __future__ import annotations

import math

from .._jit import jit


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
def point_clearance(r, rp, s, tip, up, samples, steps, gap, slope, curve):
    """Signed distance [m] from ``tip`` to the centreline (nodes ``r``,
    slopes ``rp``, arc lengths ``s``), sign by ``up``: on the four elements
    around the node nearest the tip, each sampled at ``samples`` points and
    refined by at most ``steps`` Newton steps on (r - tip) . dr/dxi = 0, xi
    kept in [0, 1]; ``gap``, ``slope``, ``curve`` are scratch of length nd."""
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
        x = 0.0
        nearest = math.inf
        for j in range(samples):
            xi = j / (samples - 1)
            g2 = _at(r, rp, s, e, xi, tip, gap, slope, curve)
            if g2 < nearest:
                nearest = g2
                x = xi
        for _ in range(steps):
            _at(r, rp, s, e, x, tip, gap, slope, curve)
            rate = 0.0
            dot = 0.0
            for i in range(nd):
                rate += slope[i] * slope[i] + gap[i] * curve[i]
                dot += gap[i] * slope[i]
            if not rate > 0.0:
                break
            new = min(max(x - dot / rate, 0.0), 1.0)
            done = abs(new - x) < 1e-13
            x = new
            if done:
                break
        g2 = _at(r, rp, s, e, x, tip, gap, slope, curve)
        length = math.sqrt(g2)
        if length < best:
            best = length
            side = 0.0
            for i in range(nd):
                side += gap[i] * up[i]
            best_sign = math.copysign(1.0, side)
    return best_sign * best

"""Newton guarded by bisection, run to round-off (kernels/roots.py), in its two
users: a level's crossing in a Hermite element (hermite_crossing), against
brentq on the cubic, and the foot of the normal from a point to the
centreline (point_clearance), against a dense sampling of the distance."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from pipelay_fast.kernels.element_shapes import hermite_crossing
from pipelay_fast.kernels.geometry import point_clearance

EPS = np.finfo(float).eps


def _cubic(xi, xa, pa, xb, pb, le, level):
    """The Hermite coordinate less ``level`` at xi, and its d/dxi (power basis)."""
    m0, m1 = le * pa, le * pb
    c2 = 3.0 * (xb - xa) - 2.0 * m0 - m1
    c3 = 2.0 * (xa - xb) + m0 + m1
    return (((c3 * xi + c2) * xi + m0) * xi + xa - level,
            (3.0 * c3 * xi + 2.0 * c2) * xi + m0)


def _from_cubic(f, df, le, xa):
    """The element (xa, pa, xb, pb, le, level) whose coordinate less its
    level is the cubic ``f`` of xi (slope ``df``), with xa at xi = 0."""
    level = xa - f(0.0)
    return xa, df(0.0) / le, f(1.0) + level, df(1.0) / le, le, level


def _elements(rng, count):
    """Random elements (xa, pa, xb, pb, le, level) that cross their level:
    shorter than their radius of curvature with the level anywhere between
    the ends or near one; a near-horizontal inflection before the crossing
    (slope a millionth of the chord's there: Newton from the chord runs into
    it); near-tangent, the level all but touched at a second place."""
    out = []
    while len(out) < count:
        le = rng.uniform(0.2, 20.0)
        kind = len(out) % 5
        xa = rng.uniform(-300.0, 300.0)
        c = rng.uniform(0.1, 0.6)
        d = rng.choice([-1.0, 1.0]) * rng.uniform(0.1, 2.0)
        e = c + rng.uniform(0.3, 0.9) * (1.0 - c)
        if kind == 3:  # d (xi - c)^3 + b (xi - c), b = 1e-6 d, crossing at e
            def f(xi, c=c, d=d, e=e):
                return d * ((xi - c) ** 3 - (e - c) ** 3 + 1e-6 * (xi - e))

            def df(xi, c=c, d=d):
                return d * (3.0 * (xi - c) ** 2 + 1e-6)
        elif kind == 4:  # d (xi - c)^2 (xi - e) + 1e-6 d (c - e): touches near c
            def f(xi, c=c, d=d, e=e):
                return d * ((xi - c) ** 2 * (xi - e) + 1e-6 * (c - e))

            def df(xi, c=c, d=d, e=e):
                return d * (2.0 * (xi - c) * (xi - e) + (xi - c) ** 2)
        if kind >= 3:
            out.append(_from_cubic(f, df, le, xa))
            continue
        th = rng.uniform(-1.5, 1.5)
        kap = rng.normal() * 0.3 / le
        pa, pb = math.sin(th), math.sin(th + kap * le)
        xb = xa + le * 0.5 * (pa + pb)
        share = {0: rng.uniform(0.0, 1.0), 1: rng.uniform(0.0, 1e-9),
                 2: 1.0 - rng.uniform(0.0, 1e-9)}[kind]
        level = xa + share * (xb - xa)
        if (xa - level) * (xb - level) < 0.0:
            out.append((xa, pa, xb, pb, le, level))
    return out


def test_crossing_is_the_root_brentq_finds():
    """The crossing agrees with brentq (to its finest tolerance) within the
    root's round-off: the cubic's rounding error, a few EPS times the sum of
    its terms' sizes, over its slope there."""
    rng = np.random.default_rng(41)
    for element in _elements(rng, 4000):
        xa, pa, xb, pb, le, level = element
        root = brentq(lambda xi, *el: _cubic(xi, *el)[0], 0.0, 1.0, args=element,
                      xtol=1e-300, rtol=4.0 * EPS)
        xi = hermite_crossing(xa, pa, xb, pb, le, level)
        size = abs(xa) + abs(xb) + le * (abs(pa) + abs(pb)) + abs(level)
        slope = abs(_cubic(root, xa, pa, xb, pb, le, level)[1])
        assert 0.0 <= xi <= 1.0
        assert abs(xi - root) <= 64.0 * EPS * size / slope + 8.0 * EPS


def test_crossing_from_a_chord_on_a_stationary_point():
    """(xi - 1/4)^3 - 3/32: its chord from xi = 0 to 1 is 1/4, where the slope
    is 0 (Newton's step infinite, bisection takes over); the root is
    1/4 + (3/32)^(1/3)."""
    c, k = 0.25, -0.09375
    xa, xb = (0.0 - c) ** 3 + k, (1.0 - c) ** 3 + k
    assert xa / (xa - xb) == c
    xi = hermite_crossing(xa, 3.0 * c * c, xb, 3.0 * (1.0 - c) ** 2, 1.0, 0.0)
    assert xi == pytest.approx(c + (-k) ** (1.0 / 3.0), abs=16 * EPS)


def test_crossing_misses_a_level_it_does_not_cross():
    assert hermite_crossing(1.0, 0.1, 2.0, 0.1, 3.0, 0.5) == -1.0
    assert hermite_crossing(1.0, 0.1, 2.0, 0.1, 3.0, 2.0) == -1.0  # at an end: no crossing


def _line(rng, nd, nn):
    """A random smooth centreline of ``nn`` nodes: nodes ``r`` on a curve of
    radius >= 20 m, slopes ``rp`` and arc lengths ``s`` [m]."""
    s = np.concatenate([[0.0], np.cumsum(rng.uniform(0.5, 3.0, nn - 1))])
    kap = rng.uniform(-0.05, 0.05)
    tilt = rng.uniform(-0.02, 0.02)
    th = rng.uniform(0, 2 * math.pi) + kap * s
    r = np.zeros((nn, nd))
    rp = np.zeros((nn, nd))
    r[:, 0] = np.sin(th) / kap if kap else s
    r[:, -1] = (1.0 - np.cos(th)) / kap if kap else 0.0
    r[:, 0] -= r[0, 0]
    r[:, -1] -= r[0, -1]
    rp[:, 0], rp[:, -1] = np.cos(th), np.sin(th)
    if nd == 3:  # rising slowly out of the plane
        r[:, 1] = tilt * s
        rp[:, 1] = tilt
    return r + rng.uniform(-500.0, 500.0, nd), rp, s


def _dense_distance(r, rp, s, tip, elements, n=200001):
    """The least distance from ``tip`` to the elements' cubic Hermites,
    sampled at ``n`` points each (the distance is stationary at its minimum,
    so the samples' spacing enters squared), and the nearest point."""
    xi = np.linspace(0.0, 1.0, n)[:, None]
    best, where = math.inf, None
    for e in elements:
        le = s[e + 1] - s[e]
        n1, n2 = 1 - 3 * xi**2 + 2 * xi**3, le * (xi - 2 * xi**2 + xi**3)
        n3, n4 = 3 * xi**2 - 2 * xi**3, le * (-xi**2 + xi**3)
        pts = n1 * r[e] + n2 * rp[e] + n3 * r[e + 1] + n4 * rp[e + 1]
        d = np.linalg.norm(pts - tip, axis=1)
        k = int(np.argmin(d))
        if d[k] < best:
            best, where = float(d[k]), pts[k]
    return best, where


@pytest.mark.parametrize("nd", [2, 3])
@pytest.mark.parametrize("place", ["inside", "near_node", "before_start", "past_end", "on"])
def test_clearance_is_the_least_distance(nd, place):
    """point_clearance against a dense sampling of the distance over the
    same elements (the four around the node nearest the tip), its sign from
    the side of ``up``: the tip beside an element, beside a node (two
    elements' ends), beyond either end of the line (the foot at an end
    node) and on the line."""
    rng = np.random.default_rng({"inside": 1, "near_node": 2, "before_start": 3,
                                 "past_end": 4, "on": 5}[place] + 10 * nd)
    scratch = (np.empty(nd), np.empty(nd), np.empty(nd))
    for _ in range(25):
        nn = 9
        r, rp, s = _line(rng, nd, nn)
        k = int(rng.integers(2, nn - 3))
        normal = np.zeros(nd)
        normal[0], normal[-1] = -rp[k, -1], rp[k, 0]
        if place == "inside":
            base = 0.5 * (r[k] + r[k + 1])
            tip = base + rng.uniform(-2.0, 2.0) * normal
        elif place == "near_node":
            tip = r[k] + rng.uniform(-2.0, 2.0) * normal
        elif place == "before_start":
            tip = r[0] - rng.uniform(0.1, 1.0) * rp[0] + rng.uniform(-0.1, 0.1) * normal
        elif place == "past_end":
            tip = r[-1] + rng.uniform(0.1, 1.0) * rp[-1] + rng.uniform(-0.1, 0.1) * normal
        else:
            tip = r[k].copy()
        near = int(np.argmin(np.linalg.norm(r - tip, axis=1)))
        elements = range(max(near - 2, 0), min(near + 2, nn - 1))
        expected, foot = _dense_distance(r, rp, s, tip, elements)
        up = normal
        got = point_clearance(r, rp, s, tip, up, 33, *scratch)
        assert abs(got) == pytest.approx(expected, abs=1e-9)
        if expected > 1e-6:
            assert math.copysign(1.0, got) == math.copysign(1.0, float((foot - tip) @ up))

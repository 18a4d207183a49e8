"""The supports' table (``Supports.kind``, ``geom``, ``active``; layout
``SUP_*``) and the kernels that read a support's geometry by its kind
(:mod:`pipelay_fast.kernels.supports`), against NumPy references: the flat
seabed is x = 0, the curve x = a z^2 + b z + c, a point's gap is along the
normal of the pipe's frame."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pipelay_fast.engine.supports import support_table
from pipelay_fast.kernels import layout as L
from pipelay_fast.kernels.supports import (
    holds_laterally,
    in_curve_coords,
    support_angle,
    support_gap,
    support_height,
    support_span,
    tangency,
)

CURVE = np.array([-0.0012, 0.45, 12.0, 265.0, 400.0])  # a, b, c, zL, zU
POINTS = np.array([[55.0, 265.0, 0.0, 0.0, 1.0], [60.0, 280.0, 1.0, 2.5e3, 0.0]])
Z = np.array([-30.0, 0.0, 265.0, 300.7, 400.0])
X = np.array([-0.2, 0.0, 1e-3, 57.3, 80.0])


def table():
    kind, geom, active = support_table(6, CURVE, POINTS)
    return kind, geom, active


def test_the_table_rows_are_the_boundaries_supports():
    kind, geom, active = table()
    assert kind.dtype == np.int64 and geom.shape == (L.ROW_PT + 2, L.N_GEOM)
    assert active.shape == (L.ROW_PT + 2, 6) and active.dtype == np.int8 and not active.any()
    assert (L.ROW_BED, L.ROW_CURVE, L.ROW_PT) == (L.B_TD, L.B_LO, L.B_PT)
    assert kind.tolist() == [L.SUP_SEABED, L.SUP_CURVE, L.SUP_POINT, L.SUP_POINT]
    assert geom[L.ROW_BED, L.SB_LEVEL] == 0.0
    np.testing.assert_array_equal(geom[L.ROW_CURVE], CURVE)
    np.testing.assert_array_equal(geom[L.ROW_PT:], POINTS)
    none, _g, _a = support_table(4)  # J-lay: no curve, no points
    assert none.tolist() == [L.SUP_SEABED, L.SUP_NONE]


@pytest.mark.parametrize("z", Z)
def test_heights_and_angles_by_kind(z):
    kind, geom, _active = table()
    a, b, c = CURVE[:3]
    assert support_height(kind[L.ROW_BED], geom[L.ROW_BED], z) == (0.0, 0.0, 0.0)
    f, fp, fpp = support_height(kind[L.ROW_CURVE], geom[L.ROW_CURVE], z)
    assert (f, fp, fpp) == pytest.approx((a * z * z + b * z + c, 2 * a * z + b, 2 * a),
                                         rel=1e-14, abs=1e-12)
    assert support_angle(kind[L.ROW_BED], geom[L.ROW_BED], z) == 0.0
    assert support_angle(kind[L.ROW_CURVE], geom[L.ROW_CURVE], z) == pytest.approx(
        math.atan(2 * a * z + b), rel=1e-14)
    assert support_height(kind[L.ROW_PT], geom[L.ROW_PT], z)[0] == POINTS[0, L.PT_X]


@pytest.mark.parametrize(("x", "z"), list(zip(X, Z, strict=True)))
def test_gaps_by_kind(x, z):
    kind, geom, _active = table()
    a, b, c = CURVE[:3]
    assert support_gap(kind[L.ROW_BED], geom[L.ROW_BED], x, z, 0.3) == x  # the seabed is x = 0
    assert support_gap(kind[L.ROW_CURVE], geom[L.ROW_CURVE], x, z, 0.0) == pytest.approx(
        x - (a * z * z + b * z + c), rel=1e-13, abs=1e-10)
    for j, phi in ((0, 0.0), (1, 0.4)):
        normal = np.array([math.cos(phi), -math.sin(phi)])  # (x, z) of the frame's normal
        ref = normal @ (np.array([x, z]) - POINTS[j, [L.PT_X, L.PT_Z]])
        got = support_gap(kind[L.ROW_PT + j], geom[L.ROW_PT + j], x, z, phi)
        assert got == pytest.approx(ref, rel=1e-13, abs=1e-11)


def test_spans_and_holds_by_kind():
    kind, geom, _active = table()
    assert support_span(kind[L.ROW_BED], geom[L.ROW_BED]) == (-math.inf, math.inf)
    assert support_span(kind[L.ROW_CURVE], geom[L.ROW_CURVE]) == (265.0, 400.0)
    assert support_span(kind[L.ROW_PT + 1], geom[L.ROW_PT + 1]) == (280.0, 280.0)
    assert [bool(in_curve_coords(k)) for k in kind] == [False, True, False, False]
    assert [bool(holds_laterally(k)) for k in kind] == [False, True, False, False]
    assert not in_curve_coords(L.SUP_NONE) and not holds_laterally(L.SUP_NONE)


@pytest.mark.parametrize("nd", [2, 3])
def test_tangency_by_kind(nd):
    """x' - f'(z) z' at a node and its derivative d/du (central differences)."""
    kind, geom, _active = table()
    ndn = 2 * nd + 1
    rng = np.random.default_rng(7)
    u = rng.normal(size=3 * ndn)
    node = 1
    base = node * ndn
    u[base + nd - 1] = 310.0  # z on the curve's range
    a, b = CURVE[:2]
    for k, ref in ((L.ROW_BED, lambda v: v[base + nd]),
                   (L.ROW_CURVE, lambda v: v[base + nd]
                    - (2 * a * v[base + nd - 1] + b) * v[base + 2 * nd - 1])):
        row = np.zeros(u.size)
        value = tangency(nd, u, kind[k], geom[k], node, row)
        assert value == pytest.approx(ref(u), rel=1e-14)
        assert tangency(nd, u, kind[k], geom[k], node, np.zeros(0)) == value
        fd = np.zeros(u.size)
        for i in range(u.size):
            e = np.zeros(u.size)
            e[i] = 1e-6
            fd[i] = (ref(u + e) - ref(u - e)) / 2e-6
        np.testing.assert_allclose(row, fd, atol=1e-8)

"""The rod element's building blocks: Gauss-Legendre quadrature, the cubic
Hermite shape functions, the pieces an element is integrated in, and the
layout of the element kernels' scratch vector ``ws``.

Four Gauss points integrate every polynomial term of the weak form exactly
(:mod:`.element`: the highest is lam (r'.dr'), degree 5). An element that
crosses the water surface or the contents level is integrated piecewise, 4
points on each side of the crossing (:func:`level_cuts`), so that the jump
of the effective weight there is integrated exactly.
"""

from __future__ import annotations

import math

import numpy as np

from . import layout as L
from ._jit import jit, phase
from .roots import bracketed_step

_G = np.sqrt(3.0 / 7.0 - 2.0 / 7.0 * np.sqrt(6.0 / 5.0))
_H = np.sqrt(3.0 / 7.0 + 2.0 / 7.0 * np.sqrt(6.0 / 5.0))
_WG = (18.0 + np.sqrt(30.0)) / 36.0
_WH = (18.0 - np.sqrt(30.0)) / 36.0
GAUSS_XI = np.array([0.5 - 0.5 * _H, 0.5 - 0.5 * _G, 0.5 + 0.5 * _G, 0.5 + 0.5 * _H])
GAUSS_W = np.array([0.5 * _WH, 0.5 * _WG, 0.5 * _WG, 0.5 * _WH])


@jit(_nrt=False)
def hermite(xi, le, n, dn, ddn):
    """Cubic Hermite shape functions on [0, le] at xi = s/le, with d/ds and d2/ds2.

    Order: r_a, r'_a, r_b, r'_b.
    """
    xi2 = xi * xi
    xi3 = xi2 * xi
    n[0] = 1.0 - 3.0 * xi2 + 2.0 * xi3
    n[1] = le * (xi - 2.0 * xi2 + xi3)
    n[2] = 3.0 * xi2 - 2.0 * xi3
    n[3] = le * (-xi2 + xi3)
    dn[0] = (-6.0 * xi + 6.0 * xi2) / le
    dn[1] = 1.0 - 4.0 * xi + 3.0 * xi2
    dn[2] = (6.0 * xi - 6.0 * xi2) / le
    dn[3] = -2.0 * xi + 3.0 * xi2
    ddn[0] = (-6.0 + 12.0 * xi) / (le * le)
    ddn[1] = (-4.0 + 6.0 * xi) / le
    ddn[2] = (6.0 - 12.0 * xi) / (le * le)
    ddn[3] = (-2.0 + 6.0 * xi) / le


@jit(_nrt=False)
def hermite_crossing(xa, pa, xb, pb, le, level):
    """xi in (0, 1) where a Hermite coordinate crosses ``level``, else -1.

    ``xa, xb`` are the nodal values of the coordinate, ``pa, pb`` their
    derivatives d/ds (the height x at the water surface, z at the stinger
    tip). Newton from the chord estimate, guarded by bisection in [0, 1] and
    run to round-off (:func:`.roots.bracketed_step`); the root is unique
    when the element is monotone in x, which holds for any element shorter
    than the local radius of curvature (otherwise it is one of them).
    """
    fa = xa - level
    fb = xb - level
    if fa * fb >= 0.0:
        return -1.0
    xi = fa / (fa - fb)
    lo, hi, last = 0.0, 1.0, math.inf
    sign_lo = math.copysign(1.0, fa)
    while True:
        xi2 = xi * xi
        xi3 = xi2 * xi
        f = ((1.0 - 3.0 * xi2 + 2.0 * xi3) * xa + le * (xi - 2.0 * xi2 + xi3) * pa
             + (3.0 * xi2 - 2.0 * xi3) * xb + le * (-xi2 + xi3) * pb - level)
        if f == 0.0:
            return xi
        df = ((-6.0 * xi + 6.0 * xi2) * xa + le * (1.0 - 4.0 * xi + 3.0 * xi2) * pa
              + (6.0 * xi - 6.0 * xi2) * xb + le * (-2.0 * xi + 3.0 * xi2) * pb)
        xi, lo, hi, last, done = bracketed_step(xi, f, df, lo, hi, sign_lo, last)
        if done:
            return xi


@jit(_nrt=False)
def level_cuts(props, le, xa, pa, xb, pb, cuts, cutlev):
    """The pieces an element is integrated in: split where its height x
    (nodal xa, xb and slopes pa, pb) crosses the water surface or the
    contents level. Writes the abscissae 0 = cuts[0] < ... < cuts[ncut] = 1
    and the level each inner cut crosses (``cutlev``); returns ncut."""
    cuts[0] = 0.0
    ncut = 1
    for lev in range(2):
        level = props[L.DEPTH] if lev == 0 else props[L.H_CONT]
        xi_c = hermite_crossing(xa, pa, xb, pb, le, level)
        if xi_c > 0.0:
            cuts[ncut] = xi_c
            cutlev[ncut] = level
            ncut += 1
    cuts[ncut] = 1.0
    if ncut == 3 and cuts[1] > cuts[2]:
        cuts[1], cuts[2] = cuts[2], cuts[1]
        cutlev[1], cutlev[2] = cutlev[2], cutlev[1]
    return ncut


@jit(_nrt=False)
def _cross3(a, b, out):
    """``out`` = a x b (3-vectors)."""
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@jit(_nrt=False)
def _cross_t(a, b):
    """a x b of two 3-tuples, as a tuple."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


# Layout of the scratch vector ``ws``: offsets of the per-Gauss-point values.
# The kernel views them through slices; _dle_gauss_point indexes ``ws`` directly
# (slices there would cost more than its arithmetic).
_N, _DN, _DDN = 0, 4, 8  # shape functions and their d/ds, d2/ds2
_R, _RP, _RPP = 12, 15, 18  # r, r', r''
_Q, _QD, _DQ_DX = 21, 24, 27  # load, drag, d(drag)/dx
_RP3, _RPP3, _M3, _C3, _E3 = 30, 33, 36, 39, 42  # 3-vectors of the torque terms
_CUTS, _DWORK = 45, 49  # crossing abscissae; drag_force's scratch (15)
_DRP, _DRPP, _DQ = 64, 67, 70  # d/dle of r', r'', q
_KA, _KX = 73, 89  # (4, 4) sums over the Gauss points: EI N''N'' + lam N'N', N dqx/dx N
_CUTLEV = 105  # the level each crossing abscissa crosses
WORK_SIZE = 109
_P = (0.0, 1.0, 0.0, 1.0)  # power of le in each shape function


@phase
def _point_views(nd, ws, wm):
    """The views of a Gauss point's values in the scratch ``ws``, ``wm``:
    (N, N', N'' (4,), r' (nd,), the drag (nd,), its d/dx (nd,), its d/dr'
    (nd, nd), :func:`.loads.drag_force`'s scratch (15,))."""
    return (ws[_N:_N + 4], ws[_DN:_DN + 4], ws[_DDN:_DDN + 4], ws[_RP:_RP + nd],
            ws[_QD:_QD + nd], ws[_DQ_DX:_DQ_DX + nd], wm[:nd, :nd], ws[_DWORK:_DWORK + 15])

"""The seabed profile's height as a kernel phase: the C1 cubic Hermite
interpolant of :mod:`pipelay_fast.input.profile`'s knots (z, x, dx/dz per
row), held at its end values beyond them."""

from __future__ import annotations

from ._jit import phase


@phase
def bed_height(knots, z):
    """(x [m], dx/dz [-]) of the profile with ``knots`` (n, 3) at z [m]; (0, 0)
    without knots (n = 0: the reference level)."""
    n = knots.shape[0]
    if n == 0:
        return 0.0, 0.0
    if z <= knots[0, 0]:
        return knots[0, 1], 0.0
    if z >= knots[n - 1, 0]:
        return knots[n - 1, 1], 0.0
    lo, hi = 0, n - 1  # knots[lo, 0] < z < knots[hi, 0]
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if knots[mid, 0] <= z:
            lo = mid
        else:
            hi = mid
    h = knots[hi, 0] - knots[lo, 0]
    t = (z - knots[lo, 0]) / h
    x0, x1 = knots[lo, 1], knots[hi, 1]
    m0, m1 = knots[lo, 2] * h, knots[hi, 2] * h
    t2 = t * t
    t3 = t2 * t
    x = ((2.0 * t3 - 3.0 * t2 + 1.0) * x0 + (t3 - 2.0 * t2 + t) * m0
         + (-2.0 * t3 + 3.0 * t2) * x1 + (t3 - t2) * m1)
    dx = ((6.0 * t2 - 6.0 * t) * (x0 - x1) + (3.0 * t2 - 4.0 * t + 1.0) * m0
          + (3.0 * t2 - 2.0 * t) * m1) / h
    return x, dx

"""The seabed profile (``seabed.profile``): water depth along the route as a
table ``[[z, depth], ...]`` [m], validated here and turned into the knots of
its interpolant.

The interpolant is the monotone piecewise-cubic Hermite one (PCHIP; Fritsch
and Butland's weighted harmonic mean of the neighbouring chord slopes at
interior knots, as scipy's ``PchipInterpolator``; zero where the chords
change sign): continuous with its first derivative (C1), it neither
overshoots a knot's value nor adds a hump or a dip the table does not have.
Its end slopes are zero, and beyond the table the depth is held at its end
values, so it stays C1 across the ends.
"""

from __future__ import annotations

import math

import numpy as np

from .validate import fail


def check_profile(value, key: str = "seabed.profile") -> tuple[tuple[float, float], ...]:
    """The profile ``value`` as a tuple of (z [m], depth [m]) rows; ValueError
    naming ``key`` and the offending row unless it has two rows at least,
    each two finite numbers, z strictly ascending and every depth positive."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__"):
        fail(key, value, "must be a table [[z, depth], ...] of two rows at least [m]")
    if len(value) < 2:
        fail(key, value, "needs two rows at least ([[z, depth], ...] [m])")
    rows = []
    for i, row in enumerate(value):
        where = f"{key}[{i}]"
        if isinstance(row, (str, bytes)) or not hasattr(row, "__len__") or len(row) != 2:
            fail(where, row, "must be a pair [z, depth] [m]")
        try:
            z, depth = float(row[0]), float(row[1])
        except (TypeError, ValueError):
            fail(where, row, "must be a pair of numbers [z, depth] [m]")
        if isinstance(row[0], bool) or isinstance(row[1], bool):
            fail(where, row, "must be a pair of numbers [z, depth] [m]")
        if not (math.isfinite(z) and math.isfinite(depth)):
            fail(where, row, "must be finite")
        if depth <= 0.0:
            fail(where, row, "has a depth that is not positive (the seabed must lie below "
                 "the water surface)")
        if rows and z <= rows[-1][0]:
            fail(where, row, f"has z = {z!r} m not above the previous row's "
                 f"{rows[-1][0]!r} m (z must ascend)")
        rows.append((z, depth))
    return tuple(rows)


def pchip_slopes(z, x) -> np.ndarray:
    """The knots' slopes dx/dz [-] of the C1 monotone cubic Hermite
    interpolant of ``x`` at the ascending ``z`` (the module docstring): the
    weighted harmonic mean of the chords' slopes at interior knots, zero
    where they change sign or vanish, and zero at both ends."""
    z = np.asarray(z, dtype=float)
    x = np.asarray(x, dtype=float)
    h = np.diff(z)
    delta = np.diff(x) / h
    m = np.zeros(z.size)
    for k in range(1, z.size - 1):
        d0, d1 = delta[k - 1], delta[k]
        if d0 * d1 <= 0.0:
            continue
        w1 = 2.0 * h[k] + h[k - 1]
        w2 = h[k] + 2.0 * h[k - 1]
        m[k] = (w1 + w2) / (w1 / d0 + w2 / d1)
    return m


def bed_knots(profile, water_depth: float) -> np.ndarray:
    """The seabed's knots (n, 3): z [m], the height x = water_depth - depth
    [m] above the reference level (where ``environment.water_depth`` is
    measured, x = 0) and the slope dx/dz [-] (:func:`pchip_slopes`), of a
    checked ``profile`` (:func:`check_profile`); (0, 3) without one."""
    if not profile:
        return np.zeros((0, 3))
    table = np.asarray(profile, dtype=float)
    z = table[:, 0]
    x = water_depth - table[:, 1]
    return np.ascontiguousarray(np.column_stack([z, x, pchip_slopes(z, x)]))


def bed_heights(knots, z) -> tuple[np.ndarray, np.ndarray]:
    """The seabed's height x [m] and slope dx/dz [-] at the points ``z`` [m]
    (any shape) of the profile with ``knots`` (:func:`bed_knots`): the
    array form of :func:`pipelay_fast.kernels.bed.bed_height` (zeros
    without knots)."""
    z = np.asarray(z, dtype=float)
    knots = np.asarray(knots, dtype=float)
    if knots.shape[0] == 0:
        return np.zeros(z.shape), np.zeros(z.shape)
    zk = knots[:, 0]
    lo = np.clip(np.searchsorted(zk, z, side="right") - 1, 0, zk.size - 2)
    h = zk[lo + 1] - zk[lo]
    t = np.clip((z - zk[lo]) / h, 0.0, 1.0)
    x0, x1 = knots[lo, 1], knots[lo + 1, 1]
    m0, m1 = knots[lo, 2] * h, knots[lo + 1, 2] * h
    t2, t3 = t * t, t * t * t
    x = ((2.0 * t3 - 3.0 * t2 + 1.0) * x0 + (t3 - 2.0 * t2 + t) * m0
         + (-2.0 * t3 + 3.0 * t2) * x1 + (t3 - t2) * m1)
    dx = ((6.0 * t2 - 6.0 * t) * (x0 - x1) + (3.0 * t2 - 4.0 * t + 1.0) * m0
          + (3.0 * t2 - 2.0 * t) * m1) / h
    outside = (z <= zk[0]) | (z >= zk[-1])
    return x, np.where(outside, 0.0, dx)

"""Closed forms of the stinger's parabola x = a z^2 + b z + c [m]: its arc
length and the inverse, and the parabola in a frame turned about the origin
(a trimmed vessel's stinger, :mod:`.trim`). NumPy, vectorised in z."""

from __future__ import annotations

import math

import numpy as np


def arc(a: float, b: float, z0: float, z1):
    """The parabola's arc length [m] from z0 to z1 [m] (negative when z1 <
    z0): with p = 2 a z + b, 4 a s = [p sqrt(1 + p^2) + asinh p] between the
    ends (a straight line when a = 0); vectorised in z1."""
    if a == 0.0:
        return math.sqrt(1.0 + b * b) * (z1 - z0)
    p0, p1 = 2.0 * a * z0 + b, 2.0 * a * z1 + b
    return ((p1 * np.sqrt(1.0 + p1 * p1) + np.arcsinh(p1))
            - (p0 * math.sqrt(1.0 + p0 * p0) + math.asinh(p0))) / (4.0 * a)


def at_arc(a: float, b: float, z0: float, s):
    """z [m] where the parabola's arc length from z0 [m] is ``s`` [m]
    (negative: towards lower z): the inverse of :func:`arc`, by Newton from
    the chord along the tangent at z0 (ds/dz = sqrt(1 + p^2) >= 1, so the
    iteration converges quadratically) until its step stops shrinking, at
    round-off; vectorised in s."""
    s = np.asarray(s, dtype=float)
    z = z0 + s / math.sqrt(1.0 + (2.0 * a * z0 + b) ** 2)
    last = math.inf
    while True:
        p = 2.0 * a * z + b
        dz = (arc(a, b, z0, z) - s) / np.sqrt(1.0 + p * p)
        z = z - dz
        step = float(np.max(np.abs(dz), initial=0.0))
        if not step < last:
            return z
        last = step


def root(qa: float, qb: float, qc):
    """The root u of qa u^2 + qb u + qc = 0 where 2 qa u + qb = -sqrt(disc)
    (as qa -> 0 with qb < 0, the one that tends to -qc / qb), in the form
    without cancellation for either sign of qb; vectorised in qc."""
    disc = np.sqrt(np.maximum(qb * qb - 4.0 * qa * qc, 0.0))
    return 2.0 * qc / (disc - qb) if qb < 0.0 else -(qb + disc) / (2.0 * qa)


def turned(a: float, b: float, c: float, turn: float, z):
    """(x [m], dx/dz [-], d2x/dz2 [1/m], u [m]) at z [m] of the parabola
    x'' = a u^2 + b u + c in the coordinates (x'', u) of a frame turned by
    ``turn`` [rad] about the origin: x = cos(t) x'' + sin(t) u, z = cos(t) u
    - sin(t) x'' (``turn`` > 0 turns it counter-clockwise seen with z to the
    right and x up). u is the :func:`root` of sin(t) x''(u) - cos(t) u + z = 0
    continuous with u = z at t = 0, where the turned curve's tangent is less
    than 90 deg from horizontal. The arithmetic of the kernel
    :func:`pipelay_fast.kernels.supports.turned_curve`, to the bit;
    vectorised in z."""
    cs, sn = math.cos(turn), math.sin(turn)
    u = root(sn * a, sn * b - cs, sn * c + np.asarray(z, dtype=float))
    p = 2.0 * a * u + b
    den = cs - sn * p
    return (cs * ((a * u + b) * u + c) + sn * u, (cs * p + sn) / den,
            2.0 * a / (den * den * den), u)


def rotate(point, turn: float, pivot) -> tuple[float, float]:
    """(x, z) [m] of ``point`` (x, z) [m] turned by ``turn`` [rad] about
    ``pivot`` (x, z) [m], counter-clockwise seen with z to the right and x
    up: x - xp = cos(t) (x' - xp) + sin(t) (z' - zp), z - zp = cos(t) (z' -
    zp) - sin(t) (x' - xp)."""
    cs, sn = math.cos(turn), math.sin(turn)
    dx, dz = point[0] - pivot[0], point[1] - pivot[1]
    return (pivot[0] + (cs * dx + sn * dz), pivot[1] + (cs * dz - sn * dx))

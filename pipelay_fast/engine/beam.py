"""The small-slope beam-column and the planar heavy elastica: a
bending-dominated J-lay's first guess (engine layer).

A pipe of bending stiffness EI under the constant horizontal tension ``h``
and the effective weight ``w`` per length leaves a flat seabed tangent to
it with no moment at touchdown (xi = 0, y = y' = y'' = 0) and reaches a
pinned top (y'' = 0) at height ``x_top`` a horizontal span L further. With
lam = sqrt(EI / h) and small slopes, EI y'''' - h y'' = -w gives

    y = (w/h) [xi^2/2 - lam^2 (cosh(xi/lam) - 1) + lam tanh(L/(2 lam)) (lam sinh(xi/lam) - xi)],

and the span L is the root of  y(L) = (w/h) [L^2/2 - lam L tanh(L/(2 lam))] = x_top,
which grows with L from 0. Its limits: the catenary (parabola) one flexural
length further out, (w/2h) (L - lam)^2, where lam << L; the weightless
beam's w L^4 / (24 EI) where lam >> L. The catenary guess
(:mod:`.catenary`) touches down a span near sqrt(2 h x_top / w) from the
top; a bending-dominated pipe (lam above (EI/w)^(1/3)) touches down
(24 EI x_top / w)^(1/4) from it, kilometres further for a near-rigid pipe.
Steep tops are beyond small slopes (the span 30 % long at 82 deg), and a
top held at an angle carries a moment that the catenary's tension omits:
:class:`ElasticaSpan` solves the large-deflection rod from the beam-column.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_bvp
from scipy.optimize import brentq

from ..input.case import Case
from . import tuning as T

# points along the span on which the shape is tabulated against arc length
_TABLE = 2001


def bending_dominated(ei: float, lam: float, w: float) -> bool:
    """Whether a lay of bending stiffness ``ei`` [N m^2], flexural length
    ``lam`` = sqrt(EI/h) [m] at touchdown and effective weight ``w`` [N/m]
    there is bending-dominated: ``lam`` at least the heavy elastica's
    (EI/w)^(1/3), so that the pipe's stiffness, not its tension, sets the
    span (a J-lay's guess is then :class:`BeamSpan`); else tension-dominated,
    with boundary layers of length ``lam`` at its contact boundaries
    (:func:`.problem.sized_mesh`)."""
    return lam >= (ei / w) ** (1.0 / 3.0)


class _Tabled:
    """A span tabulated against arc length ``_s`` [m] from touchdown: its
    height ``_x``, horizontal distance ``_z`` [m], angle ``_th`` [rad] and
    curvature ``_kappa`` [1/m], interpolated linearly."""

    def _shape(self, s):
        """(s, x, z, theta) at arc lengths ``s`` [m] from touchdown."""
        s = np.asarray(s, dtype=np.float64)
        return (s, np.interp(s, self._s, self._x), np.interp(s, self._s, self._z),
                np.interp(s, self._s, self._th))

    def curvature(self, s):
        """Curvature [1/m] at arc lengths ``s`` [m] from touchdown."""
        return np.interp(np.asarray(s, dtype=np.float64), self._s, self._kappa)


class BeamSpan(_Tabled):
    """The small-slope beam-column from touchdown (s = 0, x = z = 0) to a
    pinned top at height ``x_top`` [m], in the horizontal tension ``h`` [N]
    under the weight ``w1`` [N/m] (the seabed's; ``w2`` [N/m] above the
    surface at height ``depth`` [m] only sets the effective tension), of
    bending stiffness ``ei`` [N m^2]. Duck-types
    :class:`.catenary.Catenary` for :func:`.guess.shape`."""

    tan0 = 0.0

    def __init__(self, h: float, w1: float, w2: float, depth: float, x_top: float, ei: float):
        self.h, self.w1, self.w2, self.depth, self.x_top, self.ei = h, w1, w2, depth, x_top, ei
        self.lam = math.sqrt(ei / h)
        self.span = self._span()
        xi = np.linspace(0.0, self.span, _TABLE)
        y, dy, ddy = self._y(xi)
        ds = np.hypot(1.0, dy)
        self._s = np.concatenate([[0.0], np.cumsum(0.5 * (ds[1:] + ds[:-1]) * np.diff(xi))])
        self._z, self._x, self._th = xi, y, np.arctan(dy)
        self._kappa = ddy / ds**3
        self.length = float(self._s[-1])

    def _height(self, span: float) -> float:
        lam = self.lam
        return self.w1 / self.h * (0.5 * span * span - lam * span * math.tanh(0.5 * span / lam))

    def _span(self) -> float:
        """The root L of y(L) = x_top. As tanh <= 1, y(L) >= (w/h) (L^2/2 - lam L),
        which reaches x_top at L = lam + sqrt(lam^2 + 2 h x_top / w): the
        bracket's upper end (the root itself where tanh rounds to 1 there)."""
        lam = self.lam
        top = lam + math.sqrt(lam * lam + 2.0 * self.h * self.x_top / self.w1)
        if self._height(top) <= self.x_top:
            return top
        return brentq(lambda L: self._height(L) - self.x_top, 0.0, top)

    def _y(self, xi):
        """y, y', y'' at horizontal distances ``xi`` [m] from touchdown (in
        u = xi/lam and U = L/(2 lam): cosh u - tanh U sinh u = cosh(u - U) /
        cosh U, each exponent below 0 for 0 <= u <= 2U, so no overflow)."""
        lam, q = self.lam, self.w1 / self.h
        big = 0.5 * self.span / lam
        t = math.tanh(big)
        u = np.asarray(xi, dtype=np.float64) / lam
        a, b, n = np.exp(u - 2.0 * big), np.exp(-u), 1.0 + math.exp(-2.0 * big)
        ch, sh = (a + b) / n, (a - b) / n  # cosh(u - U) / cosh U, sinh(u - U) / cosh U
        y = q * (0.5 * xi * xi + lam * lam * (1.0 - ch) - lam * t * xi)
        dy = q * (xi - lam * (sh + t))
        ddy = q * (1.0 - ch)
        return y, dy, ddy

    @property
    def top_tension(self) -> float:
        """Effective tension at the pinned top [N]: h plus the weight of the
        height climbed (exact for a pinned top, where M = 0)."""
        below = min(self.x_top, self.depth)
        return self.h + self.w1 * below + self.w2 * max(self.x_top - self.depth, 0.0)

    def at(self, s):
        """Shape at arc lengths ``s`` [m] from touchdown: x, z [m], theta [rad],
        Te [N] (h plus the weight of the height climbed, less M^2 / (2 EI))."""
        s, x, z, th = self._shape(s)
        kappa = self.curvature(s)
        rise = self.w1 * np.minimum(x, self.depth) + self.w2 * np.maximum(x - self.depth, 0.0)
        return x, z, th, self.h + rise - 0.5 * self.ei * kappa * kappa


class ElasticaSpan(_Tabled):
    """The planar heavy elastica (inextensible) from touchdown on a flat
    seabed (s = 0, x = z = theta = 0, no moment) to a top at height
    ``x_top`` [m]: pinned (``angle`` None, no moment) or held at ``angle``
    [rad] above the horizontal; ``h`` [N] the horizontal tension, or None
    with ``top_tension`` [N] (the effective tension along the pipe at the
    top) given. Weights ``w1``, ``w2`` [N/m] below and above the surface at
    height ``depth`` [m]; bending stiffness ``ei`` [N m^2]. With V the
    vertical force the pipe above s exerts (V(0) = -R, R the touchdown's
    reaction), EI theta'' = h sin(theta) - V cos(theta), V' = w(x), the
    weight's step at the surface spread over ``step`` [m] (an element's
    length: a mesh does not resolve it more finely). Solved by collocation
    (scipy's solve_bvp to tuning.ELASTICA_TOL, on a first mesh of
    tuning.ELASTICA_NODES nodes, within scipy's cap on nodes) from
    ``start`` (a :class:`BeamSpan`, the small-slope shape); ``ok`` False
    when that fails.
    Duck-types :class:`.catenary.Catenary` for :func:`.guess.shape`."""

    tan0 = 0.0

    def __init__(self, start: BeamSpan, angle: float | None, h: float | None,
                 top_tension: float | None, step: float):
        self.w1, self.w2, self.depth, self.x_top, self.ei = (
            start.w1, start.w2, start.depth, start.x_top, start.ei)
        ell, f0 = self.x_top, start.w1 * self.x_top  # scales: length, force
        ei = self.ei / (f0 * ell * ell)
        ratio, depth, width = self.w2 / self.w1, self.depth / ell, step / ell
        free_h = h is None
        h_of = (lambda p: p[1]) if free_h else (lambda p, v=h / f0: v)
        tau = np.linspace(0.0, 1.0, T.ELASTICA_NODES)
        s0 = tau * start.length
        x0, z0, th0, _ = start.at(s0)
        k0 = start.curvature(s0) * ell
        v0 = start.h / f0 * np.tan(th0)
        y0 = np.vstack([x0 / ell, z0 / ell, th0, k0, v0])
        p0 = [start.length / ell] + ([start.h / f0] if free_h else [])

        def fun(_t, y, p):
            n = p[0]
            w = 1.0 + (ratio - 1.0) * 0.5 * (1.0 + np.tanh((y[0] - depth) / width))
            return n * np.vstack([np.sin(y[2]), np.cos(y[2]), y[3],
                                  (h_of(p) * np.sin(y[2]) - y[4] * np.cos(y[2])) / ei, w])

        def bc(ya, yb, p):
            top = [yb[0] - 1.0, yb[3] if angle is None else yb[2] - angle]
            if free_h:
                te = h_of(p) * math.cos(yb[2]) + yb[4] * math.sin(yb[2])
                top.append(te - top_tension / f0)
            return np.array([ya[0], ya[1], ya[2], ya[3], *top])

        sol = solve_bvp(fun, bc, tau, y0, p=p0, tol=T.ELASTICA_TOL)  # (scipy's node cap)
        self.ok = bool(sol.success)
        p = sol.p
        self.h = float(h_of(p) * f0)
        self.length = float(p[0] * ell)
        tab = np.linspace(0.0, 1.0, _TABLE)
        y = sol.sol(tab)
        self._s = tab * self.length
        self._x, self._z, self._th = y[0] * ell, y[1] * ell, y[2]
        self._kappa = y[3] / ell
        self._v = y[4] * f0

    @property
    def span(self) -> float:
        """Horizontal distance from touchdown to the top [m]."""
        return float(self._z[-1])

    @property
    def top_tension(self) -> float:
        """Effective tension along the pipe at the top [N]."""
        return float(self.at(self.length)[3])

    def at(self, s):
        """Shape at arc lengths ``s`` [m] from touchdown: x, z [m], theta [rad],
        Te [N] (the force along the pipe, h cos(theta) + V sin(theta))."""
        s, x, z, th = self._shape(s)
        v = np.interp(s, self._s, self._v)
        return x, z, th, self.h * np.cos(th) + v * np.sin(th)


def bending_guessed(case: Case, cat) -> bool:
    """Whether a J-lay's guess is the elastica's (:func:`bending_span`)
    rather than the catenary ``cat`` (:class:`.catenary.Catenary`): a flat
    seabed, no pipe length given, and the lay bending-dominated
    (:func:`bending_dominated`, the same test as the mesh's boundary layer,
    :func:`.problem.sized_mesh`)."""
    ei = case.pipe.bending_stiffness
    return (case.lay.pipe_length is None and case.seabed.profile is None
            and bending_dominated(ei, math.sqrt(ei / cat.h), cat.w1))


def bending_span(case: Case, cat, held: float | None = None):
    """A bending-dominated lay's free span (:func:`bending_guessed`): the
    planar heavy elastica (:class:`ElasticaSpan`) started from the
    small-slope beam-column (:class:`BeamSpan`) on the catenary ``cat``'s
    tension; when the elastica is not found, that beam-column (pinned top)
    or ``cat``. The top is the J-lay's, or, with ``held`` [rad], held at
    that angle (an S-lay's lift-off, tangent to the stinger). On the same
    height and tension a pinned top's effective tension is the catenary's
    (M = 0 there), so h is ``cat``'s unless a J-lay's top angle and its top
    tension are given."""
    lay = case.lay
    beam = BeamSpan(cat.h, cat.w1, cat.w2, cat.depth, cat.x_top, case.pipe.bending_stiffness)
    pinned = held is None and lay.top_angle in (None, "pinned")
    angle = held if held is not None or pinned else math.radians(lay.top_angle)
    free_h = held is None and not pinned and lay.bottom_tension is None
    span = ElasticaSpan(beam, angle, None if free_h else cat.h,
                        lay.top_tension if free_h else None, case.solver.element_length)
    if span.ok:
        return span
    return beam if pinned else cat

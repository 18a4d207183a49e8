"""Planar inextensible elastica of a J-lay pipe: reference BVP solution.

Independent of ``pipelay_fast``; scipy's ``solve_bvp`` with analytic Jacobians.

Coordinates and conventions
---------------------------
``x`` height above a flat rigid seabed [m], ``z`` horizontal towards the vessel
[m]; the plane (z, x) is oriented counter-clockwise (z first), so the scalar
cross product is ``a x b = a_z b_x - a_x b_z``. ``s`` is arc length from the
touchdown point (TDP, s = 0) to the hang-off point (s = L). ``theta`` is the
tangent angle from +z towards +x: ``t = (cos theta, sin theta)`` in (z, x).

``F(s) = (Fz, Fx)`` is the internal force exerted on the part [0, s] by the part
(s, L] (tension positive) and ``M(s)`` the internal moment, same convention.

Equilibrium of a slice ds under the effective weight ``-w(x) e_x``:

    force:   F' = w e_x                  ->  Fz = const = T_bottom,  Fx' = w(x)
    moment:  M' + t x F = 0              ->  M' = Fz sin(theta) - Fx cos(theta)
    bending: M = EI theta'

Sign check (the pitfall): for a cable M = 0 forces ``F || t``, i.e.
``Fx / Fz = tan(theta)``; the catenary's ``theta`` increases with s (sagbend is
concave up, positive curvature) so the elastica's sagbend moment is positive and
tends to ``EI * w cos^2(theta) / H`` as EI -> 0 (tested). A tip-loaded cantilever
(F = -P e_x) gives M = -P (L - s): hogging, as it must.

Effective tension ``Te = F . t = Fz cos(theta) + Fx sin(theta)``; shear
``V = F . n = -M'`` with ``n = (-sin, cos)``. From these, ``Te' = w x' - (M^2 / 2EI)'``,
so ``Te(L) = T_bottom + int_0^x_top w dx + (M(0)^2 - M(L)^2) / (2 EI)``: with a
pinned top the top tension equals the catenary formula exactly (a test uses it).

Seabed and TDP: the laid pipe is straight along z, moment-free, with
``F = (T_bottom, 0)`` (its weight is carried by the seabed). A concentrated seabed
reaction ``R`` acts at the TDP, so ``Fx`` jumps from 0 to ``Fx(0+) = -R``: the
seabed pushes up (R >= 0) exactly when ``Fx(0+) <= 0``. Since M(0) = 0 and
M' (0) = -Fx(0) = R, an upward reaction is what lets the sagbend moment grow from
zero. Boundary conditions: x = z = theta = M = 0 at s = 0, Fx(0) free (it is the
reaction); at the top x = x_top and M = 0 (pinned) or theta = top angle.

Solution method
---------------
The suspended pipe is split at the water surface (when the top is above it) into
two segments, each mapped onto tau in [0, 1] with its own unknown length as a
parameter (``s = s_start + L_k tau``); continuity of all five states and
``x = depth`` are imposed at the junction. The weight jump then sits exactly at a
segment end: collocation never straddles the discontinuity of ``Fx'`` (and of
``M''``), so the 4th-order accuracy of ``solve_bvp`` is kept without a local
mesh pile-up. The state is (x, z, theta, M, Fx); theta (not a slope) keeps it
regular up to and beyond a vertical tangent. Everything is scaled by the length
``x_top`` and the force ``w_sub x_top`` so all unknowns are O(1) for the
relative tolerance of ``solve_bvp``.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_bvp
from scipy.optimize import brentq

from .catenary import catenary_profile, natural_catenary_two_weights

_NS = 5  # states per segment: x, z, theta, M, Fx
_X, _Z, _TH, _M, _FX = range(_NS)


def rod_segment(y, o, L, EI, w, Fz, dy=None, dfdy=None, dfdp_k=None):
    """The planar rod's equations on one segment, shared by the references.

    States at offset ``o`` of ``y``: x, z, theta, M, Fx (slots ``_X .. _FX``);
    arc length scaled by the segment length L, horizontal force Fz constant.
    x' = L sin, z' = L cos, theta' = L M/EI, M' = L (Fz sin - Fx cos), Fx' = L w.
    Writes the rates into ``dy``, their derivatives with respect to those five
    states into ``dfdy`` and with respect to L into the column ``dfdp_k``.
    """
    th, M, Fx = y[o + _TH], y[o + _M], y[o + _FX]
    c, s = np.cos(th), np.sin(th)
    if dy is not None:
        dy[o + _X] = L * s
        dy[o + _Z] = L * c
        dy[o + _TH] = L * M / EI
        dy[o + _M] = L * (Fz * s - Fx * c)
        dy[o + _FX] = L * w
    if dfdy is not None:
        dfdy[o + _X, o + _TH] = L * c
        dfdy[o + _Z, o + _TH] = -L * s
        dfdy[o + _TH, o + _M] = L / EI
        dfdy[o + _M, o + _TH] = L * (Fz * c + Fx * s)
        dfdy[o + _M, o + _FX] = -L * c
    if dfdp_k is not None:
        dfdp_k[o + _X] = s
        dfdp_k[o + _Z] = c
        dfdp_k[o + _TH] = M / EI
        dfdp_k[o + _M] = Fz * s - Fx * c
        dfdp_k[o + _FX] = w
    return s


class _Scaled:
    """The problem in scaled units: length ell = x_top, force F0 = w_sub ell."""

    def __init__(self, EI, w_sub, w_dry, depth, x_top, T_bottom, T_top, top_angle_deg):
        self.ell = float(x_top)
        self.F0 = float(w_sub) * self.ell
        self.EI = float(EI) / (self.F0 * self.ell**2)
        self.two = x_top > depth
        self.w = np.array([1.0, w_dry / w_sub] if self.two else [1.0])
        self.nseg = len(self.w)
        self.depth = depth / self.ell
        self.Fz_known = None if T_bottom is None else T_bottom / self.F0
        self.T_top = None if T_top is None else T_top / self.F0
        self.angle = None if top_angle_deg is None else math.radians(top_angle_deg)

    def split(self, p):
        """(segment lengths, Fz) from the parameter vector."""
        lengths = p[: self.nseg]
        Fz = self.Fz_known if self.Fz_known is not None else p[self.nseg]
        return lengths, Fz

    def fun(self, tau, y, p):
        lengths, Fz = self.split(p)
        dy = np.empty_like(y)
        for k in range(self.nseg):
            rod_segment(y, _NS * k, lengths[k], self.EI, self.w[k], Fz, dy=dy)
        return dy

    def fun_jac(self, tau, y, p):
        lengths, Fz = self.split(p)
        n, m = y.shape
        dfdy = np.zeros((n, n, m))
        dfdp = np.zeros((n, len(p), m))
        for k in range(self.nseg):
            o, L = _NS * k, lengths[k]
            s = rod_segment(y, o, L, self.EI, self.w[k], Fz, dfdy=dfdy, dfdp_k=dfdp[:, k])
            if self.Fz_known is None:
                dfdp[o + _M, self.nseg] = L * s
        return dfdy, dfdp

    def bc(self, ya, yb, p):
        _, Fz = self.split(p)
        res = [ya[_X], ya[_Z], ya[_TH], ya[_M]]  # TDP on the seabed, tangent, M = 0
        if self.two:
            res += list(ya[_NS:] - yb[:_NS])  # continuity at the surface
            res.append(yb[_X] - self.depth)  # the junction is the surface
        top = yb[_NS * (self.nseg - 1) :]
        res.append(top[_X] - 1.0)
        res.append(top[_M] if self.angle is None else top[_TH] - self.angle)
        if self.T_top is not None:
            th = top[_TH]
            res.append(Fz * math.cos(th) + top[_FX] * math.sin(th) - self.T_top)
        return np.array(res)


def _initial_mesh(lam_over_L, n_uniform=60):
    """tau mesh: uniform plus geometric clustering at both ends down to a step
    of about a fifth of the flexural length (boundary layers at TDP and top)."""
    h = min(max(lam_over_L / 5.0, 1e-7), 1.0 / n_uniform)
    pts = [np.linspace(0.0, 1.0, n_uniform + 1)]
    if h < 1.0 / n_uniform:
        g = np.geomspace(h, 1.0 / n_uniform, 25)
        pts += [g, 1.0 - g]
    return np.unique(np.concatenate(pts))


def _catenary_guess(sc, tau, H, EI, w_sub, w_dry, depth, x_top):
    """Initial state from the two-weight natural catenary with horizontal force H,
    with the moment EI * curvature damped to zero over the flexural length at the
    TDP (M(0) = 0) and at a pinned top."""
    cat = natural_catenary_two_weights(w_sub, w_dry, depth, x_top, T_bottom=H)
    if sc.two:
        lengths = [cat["surface_length"], cat["suspended_length"] - cat["surface_length"]]
    else:
        lengths = [cat["suspended_length"]]
    L = cat["suspended_length"]
    lam = math.sqrt(EI / H)
    y = np.empty((_NS * sc.nseg, tau.size))
    start = 0.0
    for k, Lk in enumerate(lengths):
        s = start + Lk * tau
        prof = catenary_profile(w_sub, w_dry, depth, H, s)
        damp = -np.expm1(-s / lam)
        if sc.angle is None:
            damp = damp * -np.expm1(-(L - s) / lam)
        o = _NS * k
        y[o + _X] = prof["x"] / sc.ell
        y[o + _Z] = prof["z"] / sc.ell
        y[o + _TH] = prof["theta"]
        y[o + _M] = EI * prof["curvature"] * damp / (sc.F0 * sc.ell)
        y[o + _FX] = prof["Fx"] / sc.F0
        start += Lk
    if sc.two:  # the guess must put the junction exactly on the surface
        y[_X, -1] = sc.depth
    p = [Lk / sc.ell for Lk in lengths]
    if sc.Fz_known is None:
        p.append(H / sc.F0)
    return y, np.array(p)


def jlay_elastica(
    EI,
    w_sub,
    w_dry,
    depth,
    x_top,
    z_top,
    T_bottom=None,
    T_top=None,
    top_angle_deg=None,
    *,
    tol=1e-8,
    max_nodes=200_000,
):
    """Large-deflection inextensible planar elastica of a J-lay pipe.

    Parameters
    ----------
    EI : float
        Bending stiffness [N m^2].
    w_sub, w_dry : float
        Effective weight per length below / above the water surface [N/m].
    depth : float
        Water depth [m] (surface at x = depth).
    x_top, z_top : float
        Hang-off point [m].
    T_bottom, T_top : float
        Bottom (laid pipe, horizontal) effective tension [N], or top effective
        tension [N] (the bottom tension then becomes an unknown); exactly one.
    top_angle_deg : float or None
        Prescribed top angle [deg from horizontal]; None: pinned top (M = 0).
    tol : float
        ``solve_bvp`` relative collocation tolerance (boundary conditions too).

    Returns
    -------
    dict with tdp_z [m], suspended_length [m], top_angle_deg [deg],
    top_tension [N], bottom_tension [N], max_moment [N m] (max |M| over the span),
    sagbend_moment [N m] (largest |M| at an interior stationary point),
    top_moment [N m], seabed_reaction [N] (concentrated TDP reaction, upward
    positive = -Fx(0)), top_vertical_force [N] (Fx(L)), surface_length [m]
    (arc length TDP -> surface, None if the top is under water), arrays s, x, z,
    theta_deg, moment, Fx, tension on the solver's final mesh, ``profile`` (a
    function of arc length s [m] returning the same arrays) and the solve_bvp
    result ``bvp``.
    """
    if (T_top is None) == (T_bottom is None):
        raise ValueError("give exactly one of T_top and T_bottom")
    sc = _Scaled(EI, w_sub, w_dry, depth, x_top, T_bottom, T_top, top_angle_deg)
    if T_bottom is not None:
        H0 = float(T_bottom)
    else:
        H0 = natural_catenary_two_weights(w_sub, w_dry, depth, x_top, T_top=T_top)["H"]
    cat_L = natural_catenary_two_weights(w_sub, w_dry, depth, x_top, T_bottom=H0)
    lam_over_L = math.sqrt(EI / H0) / cat_L["suspended_length"]
    for n_uniform in (60, 600):  # retry once from a finer initial mesh
        tau = _initial_mesh(lam_over_L, n_uniform)
        y0, p0 = _catenary_guess(sc, tau, H0, EI, w_sub, w_dry, depth, x_top)
        sol = solve_bvp(
            sc.fun,
            sc.bc,
            tau,
            y0,
            p=p0,
            fun_jac=sc.fun_jac,
            tol=tol,
            bc_tol=tol,
            max_nodes=max_nodes,
        )
        if sol.status == 0:
            break
    else:
        raise RuntimeError(
            f"jlay_elastica did not converge (EI={EI}, T_bottom={T_bottom}, T_top={T_top}, "
            f"top_angle_deg={top_angle_deg}): {sol.message}"
        )
    return _collect(sc, sol, z_top)


def _collect(sc, sol, z_top):
    lengths, Fz = sc.split(sol.p)
    ell, F0 = sc.ell, sc.F0
    starts = np.concatenate([[0.0], np.cumsum(lengths)])
    L = starts[-1]

    def state_at(s_scaled):
        s_scaled = np.atleast_1d(np.asarray(s_scaled, dtype=float))
        k = np.clip(np.searchsorted(starts, s_scaled, side="right") - 1, 0, sc.nseg - 1)
        out = np.empty((_NS, s_scaled.size))
        for seg in range(sc.nseg):
            sel = k == seg
            if np.any(sel):
                t = (s_scaled[sel] - starts[seg]) / lengths[seg]
                out[:, sel] = sol.sol(t)[_NS * seg : _NS * (seg + 1)]
        return out

    def shear_derivative(s_scaled):  # dM/ds in scaled units
        y = state_at(s_scaled)
        return Fz * np.sin(y[_TH]) - y[_FX] * np.cos(y[_TH])

    z_rel_top = state_at(L)[_Z, 0]
    z_tdp = z_top / ell - z_rel_top

    def profile(s):
        """Arrays at arc lengths s [m] from the TDP."""
        s_scaled = np.asarray(s, dtype=float) / ell
        y = state_at(s_scaled)
        th = y[_TH]
        return {
            "s": s_scaled * ell,
            "x": y[_X] * ell,
            "z": (z_tdp + y[_Z]) * ell,
            "theta_deg": np.degrees(th),
            "moment": y[_M] * F0 * ell,
            "Fx": y[_FX] * F0,
            "tension": (Fz * np.cos(th) + y[_FX] * np.sin(th)) * F0,
        }

    s_nodes = np.unique(np.concatenate([starts[k] + lengths[k] * sol.x for k in range(sc.nseg)]))
    out = profile(s_nodes * ell)

    # Moment peaks: stationary points of M (zero shear), located by brentq on the
    # equilibrium expression M' = Fz sin(theta) - Fx cos(theta) of the interpolant.
    dM = shear_derivative(s_nodes)
    peaks = []
    for i in np.nonzero(np.sign(dM[:-1]) * np.sign(dM[1:]) < 0)[0]:
        root = brentq(lambda t: shear_derivative(t)[0], s_nodes[i], s_nodes[i + 1], xtol=1e-14)
        peaks.append(abs(state_at(root)[_M, 0]))
    m_scale = F0 * ell
    sagbend = max(peaks) * m_scale if peaks else 0.0
    top_state = state_at(L)[:, 0]
    th_top = top_state[_TH]
    return {
        "tdp_z": float(z_tdp * ell),
        "suspended_length": float(L * ell),
        "surface_length": float(lengths[0] * ell) if sc.two else None,
        "top_angle_deg": math.degrees(th_top),
        "top_tension": float((Fz * math.cos(th_top) + top_state[_FX] * math.sin(th_top)) * F0),
        "bottom_tension": float(Fz * F0),
        "max_moment": float(max(sagbend, np.max(np.abs(out["moment"])))),
        "sagbend_moment": float(sagbend),
        "top_moment": float(top_state[_M] * m_scale),
        "seabed_reaction": float(-state_at(0.0)[_FX, 0] * F0),
        "top_vertical_force": float(top_state[_FX] * F0),
        **out,
        "profile": profile,
        "bvp": sol,
    }

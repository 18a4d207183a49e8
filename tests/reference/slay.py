"""Planar inextensible elastica of an S-lay pipe on a rigid stinger: reference.

Independent of ``pipelay_fast``; scipy's ``solve_bvp`` with analytic Jacobians,
same conventions as :mod:`.elastica` (read its docstring first).

Conventions
-----------
``x`` height above a flat rigid seabed, ``z`` horizontal towards the vessel, the
(z, x) plane counter-clockwise: ``a x b = a_z b_x - a_x b_z``. ``s`` is arc length
from the touchdown point (TDP, s = 0) to the top. ``theta`` is the tangent angle
from +z towards +x, ``t = (cos, sin)``, ``n = (-sin, cos)`` in (z, x) (``n`` points
up, away from a stinger lying under the pipe). ``F = (Fz, Fx)`` is the internal
force on [0, s] from (s, L], ``M = EI theta'`` the moment (sagging positive),
``Te = F.t`` the effective tension, ``V = F.n`` the shear.

Stinger: ``x_s(z) = a z^2 + b z + c`` on ``z_L <= z <= z_U``, through both end
points; slope ``u = 2 a z + b``, ``theta_s = atan(u)``, curvature
``kappa_s = 2a / (1 + u^2)^(3/2)`` (a < 0: hogging, the overbend).

Equilibrium of the rod (classical form; Garrett's rod gives the same equations
with ``lambda = Te - EI kappa^2``)
-----------------------------------------------------------------------------
With the external load per length ``q = -w e_x + p n`` (weight, and a stinger
reaction ``p >= 0`` normal to the stinger, which in contact is also the pipe's
normal) a slice gives

    F' = w e_x - p n,        M' + t x F = 0  ->  V = F.n = -M',   M = EI kappa.

Split ``F = Te t + V n`` and use ``t' = kappa n``, ``n' = -kappa t``:

    tangential:  Te' - kappa V = w sin(theta)
                 ->  Te' = w x' - (M^2 / (2 EI))'              (p has no share)
    normal:      kappa Te + V' = w cos(theta) - p
                 ->  p = w cos(theta) - kappa Te + EI kappa''

So along the conforming region (``M = EI kappa_s``, position and angle those of
the stinger) the tension is known in closed form from the top:

    Te(z) = T_top - [W(x_U) - W(x_s(z))] + (M_U^2 - M(z)^2) / (2 EI),
    W(x)  = int_0^x w dx,   V(z) = -EI dkappa_s/ds = 12 EI a^2 u / (1 + u^2)^3,

and ``F = Te t + V n`` there. In the free span there is no distributed horizontal
load: ``Fz`` is constant, ``Fx' = w``, ``M' = Fz sin - Fx cos`` (as in J-lay).

Contact conditions: why a concentrated reaction where the pipe leaves the curve
-------------------------------------------------------------------------------
Where the pipe leaves a smooth rigid support (a lift-off point) the unilateral
(obstacle) problem gives position, angle *and moment* continuous; the shear may
jump, the jump being a concentrated reaction ``R >= 0`` (normal, pushing up):
``F(s-) = F(s+) + R n`` (below = above + R n). This is the rigid-seabed TDP
again (``R = -Fx(0+)``) and the textbook heavy strip lifted by P at one end
(lift-off reaction = P). Requiring the shear to be continuous as well (R = 0) is
one condition too many: with T_top given, the conforming part is fixed by the
lift-off point z_lo alone, so the free span is an initial-value problem in z_lo;
its three TDP conditions (x = 0, theta = 0, M = 0) need three unknowns
(z_lo, span length, R). R is therefore an output, and the check is ``R >= 0``.
The sign is the non-penetration condition: just below a lift-off point at arc
distance h the moment differs from the stinger's by ``R h`` and the normal gap
is ``R h^3 / (6 EI) + O(h^4)`` -- a negative R would put the pipe into the
stinger (tested).

Regime 1 ("liftoff"), the pipe leaves the stinger at z_lo in (z_L, z_U]:
  unknowns: span length(s), z_lo, R_lo;  TDP: x = theta = M = 0 (z_tdp free);
  at z_lo: x, z, theta, M of the stinger, F = F_conforming + R_lo n.
Regime 2 ("tip"), the pipe conforms down to z_c, hovers over the stinger and
bears on the tip point (x_L, z_L):
  unknowns: lengths, z_c, R_c (lift-off reaction at z_c), R_tip;
  at z_c: as regime 1;  at the tip: x = x_L, z = z_L, (x, z, theta, M)
  continuous, ``F(tip-) = F(tip+) + R_tip n`` (frictionless point contact on a
  corner: the force is normal to the pipe);  TDP as above.
  Checked afterwards: R_tip >= 0, R_c >= 0, gap between pipe and stinger >= 0 on
  [z_L, z_c]. As the hovering stretch shrinks to h -> 0 the free pipe there
  lacks the distributed support p, so the gap is ~ c s^3 - p s^4/(24 EI) with
  c ~ p h / (24 EI): R_c ~ p h / 4 -> 0 and R_tip -> R_lo; the regimes join
  continuously where regime 1's z_lo reaches z_L (tested).
  Count: 5 unknowns (z_c, R_c, R_tip and the two span lengths) for 5 conditions
  (tip x and z; TDP x, theta, M); without R_c it would again be one too many.
  Close to the switch R_c ~ p h / 4 and R_c + R_tip ~ R_lo + p h (h the hovering
  arc length): the approach is O(h) = O(sqrt(a - a_switch)). Within ~1e-6
  (relative) of a_switch (h < 0.1 m) the tip regime is too ill-conditioned for
  tol = 1e-8 and a RuntimeError is raised.
Regime choice: regime 1 is tried first; it is accepted when z_L <= z_lo <= z_U,
R_lo >= 0 and the free span clears the stinger on [z_L, z_lo]; otherwise the tip
regime is solved. Either way the distributed reaction p must be >= 0 along the
conforming region, or an error is raised. ``T_bottom`` may be given instead of
``T_top`` (T_top then becomes an unknown, Fz(TDP) = T_bottom the extra
condition). Since Te' = w x' - (M^2/2EI)' holds across the point reactions too
(they are normal to the pipe), ``T_b = T_top - W(x_U) + M_U^2 / (2 EI)``
exactly: with T_top given, the bottom tension, hence the sagbend, hardly
depends on ``a``.

Limit EI -> 0 (tested): the lift-off tends to the point where a natural
catenary carrying the conforming tension leaves the stinger tangentially,
``Te (1 - cos theta) = W(x)``, shifted up the stinger by sqrt(EI / Te); R_lo
vanishes like sqrt(EI).

Numerics: the free span is split into segments at the tip and at the water
surface (weight jump), each mapped on tau in [0, 1] with its length a parameter,
states (x, z, theta, M, Fx, Fz) per segment (Fz' = 0; it jumps at the tip), so
no discontinuity lies inside a collocation interval. Scaled by the length
``ell = x_L`` and the force ``w_sub ell``.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_bvp
from scipy.optimize import brentq

from .catenary import catenary_profile, natural_catenary_two_weights
from .elastica import rod_segment

_NS = 6  # states per segment
_X, _Z, _TH, _M, _FX, _FZ = range(_NS)


class Stinger:
    """Quadratic stinger x = a z^2 + b z + c through (x_L, z_L), (x_U, z_U) [m]."""

    def __init__(self, a, lower, upper):
        (self.xL, self.zL), (self.xU, self.zU) = map(float, lower), map(float, upper)
        if not self.zU > self.zL:
            raise ValueError("the stinger's upper end must be at larger z than its lower end")
        self.a = float(a)
        self.b = (self.xU - self.xL) / (self.zU - self.zL) - self.a * (self.zU + self.zL)
        self.c = self.xL - self.a * self.zL**2 - self.b * self.zL

    def x(self, z):
        return (self.a * z + self.b) * z + self.c

    def slope(self, z):
        return 2.0 * self.a * z + self.b

    def theta(self, z):
        return np.arctan(self.slope(z))

    def kappa(self, z):
        """Curvature d theta / ds [1/m]."""
        return 2.0 * self.a / (1.0 + self.slope(z) ** 2) ** 1.5

    def dkappa_ds(self, z):
        u = self.slope(z)
        return -12.0 * self.a**2 * u / (1.0 + u * u) ** 3

    def arc(self, z):
        """Arc length from z = 0 (an antiderivative of sqrt(1 + u^2)) [m]."""
        u = self.slope(z)
        if self.a == 0.0:
            return z * np.sqrt(1.0 + u * u)
        return (u * np.sqrt(1.0 + u * u) + np.arcsinh(u)) / (4.0 * self.a)

    def z_at_height(self, x):
        """The z in [z_L, z_U] where the stinger is at height x, or None."""
        f = lambda z: self.x(z) - x  # noqa: E731
        zz = np.linspace(self.zL, self.zU, 401)
        v = f(zz)
        i = np.nonzero(np.sign(v[:-1]) * np.sign(v[1:]) <= 0)[0]
        if i.size == 0:
            return None
        return brentq(f, zz[i[0]], zz[i[0] + 1], xtol=1e-13)

    def max_abs_kappa(self, z0, z1):
        """max |kappa| over [z0, z1] (largest where |u| is smallest)."""
        cand = [z0, z1]
        if self.a != 0.0:
            zv = -self.b / (2.0 * self.a)
            if z0 < zv < z1:
                cand.append(zv)
        return max(abs(float(self.kappa(z))) for z in cand)


class _Model:
    """Unscaled physics shared by the BVP, the guess and the post-processing."""

    def __init__(self, EI, w_sub, w_dry, depth, stinger):
        self.EI, self.w_sub, self.w_dry, self.depth = map(float, (EI, w_sub, w_dry, depth))
        self.st = stinger

    def W(self, x):
        """int_0^x w dx [N]."""
        return self.w_sub * np.minimum(x, self.depth) + self.w_dry * np.maximum(x - self.depth, 0.0)

    def w(self, x):
        return np.where(x < self.depth, self.w_sub, self.w_dry)

    def conforming(self, z, T_top):
        """Conforming-region state at z: dict of x, theta, M, Te, V, Fz, Fx [SI]."""
        st, EI = self.st, self.EI
        x = st.x(z)
        th = st.theta(z)
        M = EI * st.kappa(z)
        M_U = EI * st.kappa(st.zU)
        Te = T_top - (self.W(st.xU) - self.W(x)) + (M_U**2 - M**2) / (2.0 * EI)
        V = -EI * st.dkappa_ds(z)
        c, s = np.cos(th), np.sin(th)
        return {"x": x, "theta": th, "M": M, "Te": Te, "V": V, "Fz": Te * c - V * s,
                "Fx": Te * s + V * c}

    def stinger_reaction(self, z, T_top):
        """Distributed reaction p [N/m] = w cos(theta) - kappa Te + EI kappa''."""
        st = self.st
        cf = self.conforming(z, T_top)
        u = st.slope(z)
        # kappa'' = d/ds (dkappa/ds) = cos(theta) d/dz(-12 a^2 u (1+u^2)^-3)
        d2 = -12.0 * st.a**2 * 2.0 * st.a * (1.0 - 5.0 * u * u) / (1.0 + u * u) ** 4
        d2 = d2 / np.sqrt(1.0 + u * u)
        return self.w(cf["x"]) * np.cos(cf["theta"]) - st.kappa(z) * cf["Te"] + self.EI * d2


class _Layout:
    """Segments of the free span from the TDP up, and the junctions between them."""

    def __init__(self, regime, x_end, model):
        d, xL = model.depth, model.st.xL
        wet, dry = model.w_sub, model.w_dry
        self.regime = regime
        if regime == "liftoff":
            if x_end > d:
                self.w, self.junctions = [wet, dry], ["surface"]
            else:
                self.w, self.junctions = [wet], []
        else:
            if d < xL:
                self.w, self.junctions = [wet, dry, dry], ["surface", "tip"]
            elif d < x_end:
                self.w, self.junctions = [wet, wet, dry], ["tip", "surface"]
            else:
                self.w, self.junctions = [wet, wet if xL < d else dry], ["tip"]
        self.nseg = len(self.w)
        self.tip_seg = self.junctions.index("tip") if "tip" in self.junctions else None

    def consistent(self, x_end, model):
        return _Layout(self.regime, x_end, model).junctions == self.junctions


class _Scaled:
    def __init__(self, model, layout, T_top, T_bottom):
        self.m, self.lay = model, layout
        self.ell = model.st.xL
        self.F0 = model.w_sub * self.ell
        self.EI = model.EI / (self.F0 * self.ell**2)
        self.w = np.array(layout.w) / model.w_sub
        self.depth = model.depth / self.ell
        self.T_top = None if T_top is None else T_top / self.F0
        self.T_bottom = None if T_bottom is None else T_bottom / self.F0
        n = layout.nseg
        self.i_zc, self.i_Rc = n, n + 1
        self.i_Rtip = n + 2 if layout.regime == "tip" else None
        self.i_Ttop = (n + 2 + (layout.regime == "tip")) if T_top is None else None

    # Parameters: segment lengths / ell; z_c scaled from the stinger's lower end.
    # (Not logarithms: near the switch the hovering length h solves ~ c h^2 = a -
    # a_switch, for which plain Newton is Heron's method, convergent from any
    # h > 0, whereas in log h an underestimate overshoots wildly.)
    def z_real(self, zs):
        return self.m.st.zL + self.ell * zs

    def lengths(self, p):
        return np.asarray(p[: self.lay.nseg])

    def zc_scaled(self, p):
        return p[self.i_zc]

    def z_c(self, p):
        return self.z_real(self.zc_scaled(p))

    def T_top_of(self, p):
        return self.T_top if self.i_Ttop is None else p[self.i_Ttop]

    def fun(self, tau, y, p):
        dy = np.zeros_like(y)
        for k in range(self.lay.nseg):
            o = _NS * k
            rod_segment(y, o, p[k], self.EI, self.w[k], y[o + _FZ], dy=dy)
        return dy

    def fun_jac(self, tau, y, p):
        n, m = y.shape
        dfdy = np.zeros((n, n, m))
        dfdp = np.zeros((n, len(p), m))
        for k in range(self.lay.nseg):
            o, L = _NS * k, p[k]
            s = rod_segment(y, o, L, self.EI, self.w[k], y[o + _FZ], dfdy=dfdy,
                            dfdp_k=dfdp[:, k])
            dfdy[o + _M, o + _FZ] = L * s  # Fz is a state here
        return dfdy, dfdp

    def conforming_scaled(self, zs, T_top_s):
        cf = self.m.conforming(self.z_real(zs), T_top_s * self.F0)
        ell, F0 = self.ell, self.F0
        return (cf["x"] / ell, cf["theta"], cf["M"] / (F0 * ell), cf["Fz"] / F0, cf["Fx"] / F0)

    def bc(self, ya, yb, p):
        lay = self.lay
        res = [ya[_X], ya[_TH], ya[_M]]
        if self.T_bottom is not None:
            res.append(ya[_FZ] - self.T_bottom)
        for j, kind in enumerate(lay.junctions):
            lo, hi = yb[_NS * j : _NS * (j + 1)], ya[_NS * (j + 1) : _NS * (j + 2)]
            if kind == "surface":
                res += list(hi - lo)
                res.append(lo[_X] - self.depth)
            else:  # tip: F(below) = F(above) + R n, n = (-sin, cos)
                R, th = p[self.i_Rtip], lo[_TH]
                res += list(hi[:4] - lo[:4])
                res += [lo[_X] - self.m.st.xL / self.ell, lo[_Z]]
                res += [lo[_FZ] - (hi[_FZ] - R * math.sin(th)),
                        lo[_FX] - (hi[_FX] + R * math.cos(th))]
        top = yb[_NS * (lay.nseg - 1) :]
        zc, Rc = self.zc_scaled(p), p[self.i_Rc]
        x, th, M, Fz, Fx = self.conforming_scaled(zc, self.T_top_of(p))
        res += [
            top[_X] - x,
            top[_Z] - zc,
            top[_TH] - th,
            top[_M] - M,
            top[_FZ] - (Fz - Rc * math.sin(th)),
            top[_FX] - (Fx + Rc * math.cos(th)),
        ]
        return np.array(res)


# ------------------------------------------------------------------ initial guess
def _cable_liftoff(model, T_top):
    """z where a natural catenary leaves the (extended) stinger tangentially with
    the conforming tension: Te (1 - cos theta) = W(x) (H = Te cos theta and
    Te = H + W(x) for any two-weight catenary). None if there is none."""
    st = model.st

    def f(z):
        cf = model.conforming(z, T_top)
        return cf["Te"] * (1.0 - math.cos(cf["theta"])) - model.W(cf["x"])

    zz = np.linspace(st.zU, st.zL - (st.zU - st.zL), 401)
    zz = zz[st.x(zz) > 0.05 * st.xL]
    v = np.array([f(z) for z in zz])
    i = np.nonzero(np.sign(v[:-1]) * np.sign(v[1:]) <= 0)[0]
    if i.size == 0:
        return None
    return brentq(f, zz[i[0] + 1], zz[i[0]], xtol=1e-10)


def _catenary_path(model, x_end, T_end):
    """Natural catenary from the TDP to height x_end with tension T_end there
    (H = T_end - W(x_end)); returns (length, state-of-s function), the moment
    EI * curvature damped to zero at the TDP over the flexural length."""
    H = max(T_end - float(model.W(x_end)), 0.05 * T_end)
    cat = natural_catenary_two_weights(model.w_sub, model.w_dry, model.depth, x_end, T_bottom=H)
    lam = math.sqrt(model.EI / H)

    def state(s):
        prof = catenary_profile(model.w_sub, model.w_dry, model.depth, H, s)
        damp = -np.expm1(-s / lam)
        return np.vstack([prof["x"], prof["z"], prof["theta"], model.EI * prof["curvature"] * damp,
                          prof["Fx"], np.full_like(s, H)])

    return cat["suspended_length"], state


def _guess(model, layout, T_top, z_c, R_c, R_tip, tau, lower=None):
    """Initial y, p (unscaled state path split into the layout's segments).
    Tip regime: ``lower = (length, state(s))`` is the span below the tip (from a
    regime-1 solution), else a catenary through the tip."""
    st = model.st
    if layout.regime == "liftoff":
        x_end = float(st.x(z_c))
        T_end = float(model.conforming(z_c, T_top)["Te"])
        L_cat, cat = _catenary_path(model, x_end, T_end)
        z_shift = z_c - cat(np.array([L_cat]))[_Z, 0]

        def path(s):
            y = cat(s)
            y[_Z] += z_shift
            return y

        L_total = L_cat
        tip_s = None
    else:
        if lower is None:
            T_tip = float(model.conforming(st.zL, T_top)["Te"])
            L_cat, cat = _catenary_path(model, st.xL, T_tip)
            z_shift = st.zL - cat(np.array([L_cat]))[_Z, 0]
        else:
            L_cat, cat = lower
            z_shift = 0.0
        zz = np.linspace(st.zL, z_c, 201)
        arc = st.arc(zz) - st.arc(st.zL)
        L_st = arc[-1]

        def path(s):
            s = np.atleast_1d(s)
            y = np.empty((_NS, s.size))
            low = s <= L_cat
            if np.any(low):
                y[:, low] = cat(s[low])
                y[_Z, low] += z_shift
            if np.any(~low):
                z = np.interp(s[~low] - L_cat, arc, zz)
                cf = model.conforming(z, T_top)
                y[:, ~low] = np.vstack([cf["x"], z, cf["theta"], cf["M"], cf["Fx"], cf["Fz"]])
            return y

        L_total = L_cat + L_st
        tip_s = L_cat
    # junction arc positions
    breaks = [0.0]
    s_dense = np.linspace(0.0, L_total, 4001)
    x_dense = path(s_dense)[_X]
    for kind in layout.junctions:
        if kind == "tip":
            breaks.append(tip_s)
        else:  # surface: first crossing after the previous junction
            lo = breaks[-1]
            hi = tip_s if (tip_s is not None and lo < tip_s) else L_total
            sel = (s_dense > lo) & (s_dense < hi) & (x_dense >= model.depth)
            breaks.append(s_dense[sel][0] if np.any(sel) else 0.5 * (lo + hi))
    breaks.append(L_total)
    breaks = np.array(breaks)
    sc = _Scaled(model, layout, T_top, None)  # only for the scales
    ell, F0 = sc.ell, sc.F0
    scale = np.array([ell, ell, 1.0, F0 * ell, F0, F0])[:, None]
    shift = np.array([0.0, st.zL, 0.0, 0.0, 0.0, 0.0])[:, None]
    ys = []
    for k in range(layout.nseg):
        s = breaks[k] + (breaks[k + 1] - breaks[k]) * tau
        ys.append((path(s) - shift) / scale)
    y = np.vstack(ys)
    p = list(np.diff(breaks) / ell) + [(z_c - st.zL) / ell, R_c / F0]
    if layout.regime == "tip":
        p.append(R_tip / F0)
    return y, np.array(p)


def _tau_mesh(n=80):
    t = np.linspace(0.0, 1.0, n + 1)
    g = np.geomspace(1e-4, 1.0 / n, 12)
    return np.unique(np.concatenate([t, g, 1.0 - g]))


# ------------------------------------------------------------------ solving
class _ToleranceError(RuntimeError):
    """Converged loosely from the guess, failed at the tolerance asked."""


def _solve_regime(model, regime, T_top, T_bottom, tol, z_c0, R_c0=0.0, R_tip0=0.0, lower=None,
                  max_nodes=1_000):
    """solve_bvp for one regime from a guess of the top end z_c0; returns (sc, sol)
    or raises RuntimeError. With T_bottom given, T_top is estimated for the guess
    as T_bottom + W(x) at the top end (cable)."""
    st = model.st
    T_guess = T_top if T_top is not None else T_bottom + float(model.W(st.xU))
    layout = _Layout(regime, float(st.x(z_c0)), model)
    last = None
    for _attempt in range(3):
        tau = _tau_mesh()
        y0, p0 = _guess(model, layout, T_guess, z_c0, R_c0, R_tip0, tau, lower)
        sc = _Scaled(model, layout, T_top, T_bottom)
        if sc.i_Ttop is not None:
            p0 = np.append(p0, T_guess / sc.F0)
        try:
            with np.errstate(all="ignore"):
                # coarse first (a bad guess fails fast), then to the tolerance asked
                tol0 = max(tol, 1e-6)
                sol = solve_bvp(sc.fun, sc.bc, tau, y0, p=p0, fun_jac=sc.fun_jac, tol=tol0,
                                bc_tol=tol0, max_nodes=max_nodes)
                if sol.status == 0 and tol < tol0:
                    fine = solve_bvp(sc.fun, sc.bc, sol.x, sol.y, p=sol.p, fun_jac=sc.fun_jac,
                                     tol=tol, bc_tol=tol, max_nodes=20_000)
                    if fine.status != 0:  # converged coarse: not a matter of the guess
                        raise _ToleranceError(
                            f"S-lay {regime} BVP (a={st.a}) converged to {tol0:g} but not to "
                            f"tol={tol:g}: {fine.message}")
                    sol = fine
        except _ToleranceError:
            raise
        except (OverflowError, FloatingPointError, ValueError, np.linalg.LinAlgError) as e:
            raise RuntimeError(f"S-lay {regime} BVP failed (a={st.a}): {e!r}") from None
        last = sol
        if sol.status != 0:
            break
        if np.any(sol.p[: layout.nseg] <= 0.0):
            raise RuntimeError(f"S-lay {regime} BVP (a={st.a}): a segment length came out <= 0")
        z_c = sc.z_c(sol.p)
        x_c = float(st.x(z_c))
        if layout.consistent(x_c, model):
            return sc, sol
        # the top end crossed the water surface: redo with the right segments
        layout = _Layout(regime, x_c, model)
        z_c0 = z_c
        R_c0 = sol.p[sc.i_Rc] * sc.F0
        if regime == "tip":
            R_tip0 = sol.p[sc.i_Rtip] * sc.F0
        if sc.i_Ttop is not None:
            T_guess = sol.p[sc.i_Ttop] * sc.F0
    msg = last.message if last is not None else "no attempt"
    raise RuntimeError(f"S-lay {regime} BVP failed (a={st.a}): {msg}")


def _collect(sc, sol):
    m, st, lay = sc.m, sc.m.st, sc.lay
    ell, F0, EI = sc.ell, sc.F0, m.EI
    p = sol.p
    n = lay.nseg
    lengths = sc.lengths(p) * ell
    starts = np.concatenate([[0.0], np.cumsum(lengths)])
    L_free = starts[-1]
    z_c = sc.z_c(p)
    R_c = p[sc.i_Rc] * F0
    R_tip = p[sc.i_Rtip] * F0 if sc.i_Rtip is not None else 0.0
    T_top = sc.T_top_of(p) * F0
    scale = np.array([ell, ell, 1.0, F0 * ell, F0, F0])[:, None]
    shift = np.array([0.0, st.zL, 0.0, 0.0, 0.0, 0.0])[:, None]

    def seg_state(k, tau):
        return sol.sol(np.atleast_1d(tau))[_NS * k : _NS * (k + 1)] * scale + shift

    # free span: dense profile per segment (segment ends included)
    t_fine = np.unique(np.concatenate([sol.x, np.linspace(0.0, 1.0, 401)]))
    free = [seg_state(k, t_fine) for k in range(n)]
    free_s = [starts[k] + lengths[k] * t_fine for k in range(n)]

    # moment extremes of the free span: stationary points (zero shear) + ends
    stationary = []
    for k in range(n):
        Y = free[k]
        dM = Y[_FZ] * np.sin(Y[_TH]) - Y[_FX] * np.cos(Y[_TH])
        for i in np.nonzero(np.sign(dM[:-1]) * np.sign(dM[1:]) < 0)[0]:
            def g(t, k=k):
                y = seg_state(k, t)[:, 0]
                return y[_FZ] * math.sin(y[_TH]) - y[_FX] * math.cos(y[_TH])
            t0 = brentq(g, t_fine[i], t_fine[i + 1], xtol=1e-14)
            stationary.append(float(seg_state(k, t0)[_M, 0]))
    ends = [float(Y[_M, 0]) for Y in free] + [float(Y[_M, -1]) for Y in free]
    M_all_free = np.concatenate([Y[_M] for Y in free] + [np.array(stationary + ends)])

    # conforming region, graded towards z_c, the surface crossing as a node
    zz = z_c + (st.zU - z_c) * 0.5 * (1.0 - np.cos(np.linspace(0.0, math.pi, 1201)))
    z_surf = st.z_at_height(m.depth)
    if z_surf is not None and z_c < z_surf < st.zU:
        zz = np.unique(np.concatenate([zz, [z_surf]]))
    cf = m.conforming(zz, T_top)
    s_conf = L_free + st.arc(zz) - st.arc(z_c)
    hog_conf = EI * st.max_abs_kappa(z_c, st.zU)
    p_min = float(np.min(m.stinger_reaction(zz, T_top)))

    # tension in the free span
    def tension(Y):
        return Y[_FZ] * np.cos(Y[_TH]) + Y[_FX] * np.sin(Y[_TH])

    s_all = np.concatenate(free_s + [s_conf[1:]])
    x_all = np.concatenate([Y[_X] for Y in free] + [cf["x"][1:]])
    z_all = np.concatenate([Y[_Z] for Y in free] + [zz[1:]])
    th_all = np.concatenate([Y[_TH] for Y in free] + [cf["theta"][1:]])
    M_all = np.concatenate([Y[_M] for Y in free] + [cf["M"][1:]])
    T_all = np.concatenate([tension(Y) for Y in free] + [cf["Te"][1:]])
    # drop the duplicated junction nodes between free segments
    keep = np.concatenate([[True], np.diff(s_all) > 0])
    s_all, x_all, z_all, th_all, M_all, T_all = (
        v[keep] for v in (s_all, x_all, z_all, th_all, M_all, T_all)
    )

    # gap between the free span and the stinger over [z_L, z_c] (vertical
    # distance times cos(theta_s): the normal gap to first order)
    Zf = np.concatenate([Y[_Z] for Y in free])
    Xf = np.concatenate([Y[_X] for Y in free])
    on = (Zf >= st.zL) & (Zf <= z_c)
    gap = (Xf[on] - st.x(Zf[on])) * np.cos(st.theta(Zf[on]))
    min_gap = float(gap.min()) if gap.size else 0.0

    tdp = free[0][:, 0]
    top_cf = m.conforming(st.zU, T_top)
    if lay.regime == "tip":
        k = lay.tip_seg
        tip_state = free[k][:, -1]
        angle_lo = tip_state[_TH]
        z_lo = st.zL
    else:
        angle_lo = free[-1][_TH, -1]
        z_lo = z_c
    hog = max(hog_conf, float(np.max(-M_all_free, initial=0.0)))
    sag = float(max(0.0, np.max(M_all_free)))
    return {
        "regime": lay.regime,
        "liftoff_z": float(z_lo),
        "conform_end_z": float(z_c),
        "liftoff_angle_deg": math.degrees(angle_lo),
        "tdp_z": float(tdp[_Z]),
        "overbend_max_moment": float(hog),
        "sagbend_max_moment": sag,
        "top_tension": float(T_top),
        "bottom_tension": float(tdp[_FZ]),
        "tip_reaction": float(R_tip),
        "liftoff_reaction": float(R_c),
        "seabed_reaction": float(-tdp[_FX]),
        "top_force": (float(top_cf["Fz"]), float(top_cf["Fx"])),
        "top_moment": float(top_cf["M"]),
        "free_length": float(L_free),
        "free_segments": [
            (float(starts[k]), float(starts[k + 1]), float(lay.w[k])) for k in range(n)
        ],
        "min_gap": min_gap,
        "min_stinger_reaction": p_min,
        "s": s_all,
        "x": x_all,
        "z": z_all,
        "theta_deg": np.degrees(th_all),
        "moment": M_all,
        "tension": T_all,
        "stinger": st,
        "stinger_reaction": lambda z: m.stinger_reaction(np.asarray(z, dtype=float), T_top),
        "free_state": lambda s_: _free_state(s_, starts, lengths, seg_state),
        "bvp": sol,
    }


def _free_state(s, starts, lengths, seg_state):
    """(x, z, theta, M, Fx, Fz) [SI] of the free span at arc lengths s (below a
    junction at equal s: the lower segment's end value)."""
    s = np.atleast_1d(np.asarray(s, dtype=float))
    out = np.empty((_NS, s.size))
    k = np.clip(np.searchsorted(starts, s, side="left") - 1, 0, len(lengths) - 1)
    for seg in range(len(lengths)):
        sel = k == seg
        if np.any(sel):
            out[:, sel] = seg_state(seg, (s[sel] - starts[seg]) / lengths[seg])
    return out


def _liftoff_solution(model, T_top, T_bottom, tol):
    T_guess = T_top if T_top is not None else T_bottom + float(model.W(model.st.xU))
    z0 = _cable_liftoff(model, T_guess)
    if z0 is None:
        z0 = model.st.zL
    sc, sol = _solve_regime(model, "liftoff", T_top, T_bottom, tol, z0)
    return _collect(sc, sol)


def _tip_solution(model, T_top, T_bottom, tol, r1=None):
    """Regime 2. Best guess (r1: the regime-1 solution, whose lift-off point lies
    beyond the tip by delta): its free span below the tip, tip reaction R_lo,
    hovering stretch h ~ sqrt(3.5 lam delta) (h vanishes at the switch like
    sqrt(a - a_switch), as does delta ~ h^2; the constant fits S67 within 20 %).
    Fallbacks: a catenary through the tip and a few hovering lengths."""
    st = model.st
    T_guess = T_top if T_top is not None else T_bottom + float(model.W(st.xU))
    lam = math.sqrt(model.EI / T_guess)
    attempts = []
    if r1 is not None and r1["liftoff_z"] < st.zL and r1["liftoff_reaction"] > 0.0:
        delta = st.zL - r1["liftoff_z"]
        # regime 1's profile up to the tip: free span, then the (extended) stinger
        fs, L1 = r1["free_state"], r1["free_length"]
        zz = np.linspace(r1["liftoff_z"], st.zL, 101)
        arc = st.arc(zz) - st.arc(zz[0])

        def lower_state(s, fs=fs, L1=L1, zz=zz, arc=arc):
            s = np.atleast_1d(s)
            y = np.empty((_NS, s.size))
            low = s <= L1
            y[:, low] = fs(s[low])
            if np.any(~low):
                z = np.interp(s[~low] - L1, arc, zz)
                cf = model.conforming(z, T_guess)
                y[:, ~low] = np.vstack([cf["x"], z, cf["theta"], cf["M"], cf["Fx"], cf["Fz"]])
            return y

        lower = (L1 + arc[-1], lower_state)
        h0 = math.sqrt(3.5 * lam * delta)
        attempts += [(st.zL + f * h0, r1["liftoff_reaction"], lower) for f in (1.0, 0.7, 1.4)]
    cf_tip = model.conforming(st.zL, T_guess)
    cos_cat = 1.0 - float(model.W(st.xL)) / float(cf_tip["Te"])
    th_cat = math.acos(min(max(cos_cat, -1.0), 1.0))
    R_cat = max(float(cf_tip["Te"]) * (th_cat - float(cf_tip["theta"])), 0.0) + 1e3
    for f in (1.0, 0.3, 2.0, 0.1):
        attempts.append((st.zL + f * lam, R_cat, None))
    errors = []
    for z_c0, R_tip0, lower in attempts:
        z_c0 = min(z_c0, st.zL + 0.9 * (st.zU - st.zL))
        try:
            sc, sol = _solve_regime(model, "tip", T_top, T_bottom, tol, z_c0, 0.0, R_tip0, lower)
        except _ToleranceError:
            raise
        except RuntimeError as e:
            errors.append(str(e))
            continue
        if sc.z_c(sol.p) <= st.zU:
            return _collect(sc, sol)
        errors.append(f"z_c = {sc.z_c(sol.p)} beyond the stinger's upper end")
    raise RuntimeError(f"S-lay tip regime failed (a={st.a}): " + "; ".join(errors[-3:]))


def slay_elastica(EI, w_sub, w_dry, depth, a, lower, upper, T_top=None, T_bottom=None, tol=1e-8,
                  *, regime=None):
    """Large-deflection inextensible planar elastica of an S-lay pipe on a rigid
    frictionless quadratic stinger, clamped along the stinger at its upper end.

    Parameters
    ----------
    EI : float
        Bending stiffness [N m^2].
    w_sub, w_dry : float
        Effective weight per length below / above the water surface [N/m].
    depth : float
        Water depth [m] (surface at x = depth).
    a : float
        Stinger curvature coefficient [1/m] (x = a z^2 + b z + c).
    lower, upper : (float, float)
        Stinger end points (x_L, z_L), (x_U, z_U) [m]; the pipe's top is upper.
    T_top, T_bottom : float
        Top effective tension [N], or bottom (laid pipe) tension [N]; exactly one.
    tol : float
        ``solve_bvp`` relative tolerance (boundary conditions too).
    regime : None, "liftoff" or "tip"
        None: decide (see the module docstring); otherwise force a regime, the
        admissibility checks (R >= 0, gap >= 0, z range) then left to the caller
        (used to study the switch).

    Returns
    -------
    dict with regime; liftoff_z [m] (last contact going down: lift-off point or
    tip z_L); conform_end_z [m] (end of the conforming region; = liftoff_z in
    regime 1); liftoff_angle_deg [deg] (pipe angle there, leaving side); tdp_z
    [m]; overbend_max_moment [N m] (max |M| where hogging, conforming part
    included); sagbend_max_moment [N m] (max M); top_tension, bottom_tension [N];
    tip_reaction [N] (0 in regime 1); liftoff_reaction [N] (concentrated
    reaction where the conforming region ends); seabed_reaction [N] (at the TDP);
    top_force (Fz, Fx) [N] and top_moment [N m] (internal force/moment at the
    top); free_length [m]; free_segments [(s0, s1, w)]; min_gap [m] (smallest
    normal gap of the free span over [z_L, z_c]); arrays s, x, z, theta_deg,
    moment, tension from the TDP to the top; ``stinger`` (geometry),
    ``stinger_reaction(z)`` [N/m] (closed form), ``free_state(s)`` and ``bvp``.
    """
    if (T_top is None) == (T_bottom is None):
        raise ValueError("give exactly one of T_top and T_bottom")
    st = Stinger(a, lower, upper)
    if not (0.0 < st.xL and st.xU > 0.0):
        raise ValueError("the stinger must lie above the seabed")
    model = _Model(EI, w_sub, w_dry, depth, st)
    if regime == "liftoff":
        return _liftoff_solution(model, T_top, T_bottom, tol)
    if regime == "tip":
        try:
            r1 = _liftoff_solution(model, T_top, T_bottom, tol)
        except RuntimeError:
            r1 = None
        return _tip_solution(model, T_top, T_bottom, tol, r1)
    if regime is not None:
        raise ValueError(f"unknown regime {regime!r}")
    try:
        r1 = _liftoff_solution(model, T_top, T_bottom, tol)
    except RuntimeError:
        r1 = None
    gap_tol = -1e-6 * st.xL
    if r1 is not None and st.zL <= r1["liftoff_z"] <= st.zU and r1["liftoff_reaction"] >= 0.0 \
            and r1["min_gap"] >= gap_tol:
        if r1["min_stinger_reaction"] < 0.0:
            raise RuntimeError(f"S-lay a={a}: the stinger would have to pull the pipe "
                               f"(p = {r1['min_stinger_reaction']:.6g} N/m)")
        return r1
    r2 = _tip_solution(model, T_top, T_bottom, tol, r1)
    bad = []
    if r2["tip_reaction"] < 0.0:
        bad.append(f"tip reaction {r2['tip_reaction']:.6g} N < 0")
    if r2["liftoff_reaction"] < 0.0:
        bad.append(f"lift-off reaction {r2['liftoff_reaction']:.6g} N < 0")
    if r2["min_stinger_reaction"] < 0.0:
        bad.append(f"stinger reaction {r2['min_stinger_reaction']:.6g} N/m < 0")
    if r2["min_gap"] < gap_tol:
        bad.append(f"pipe penetrates the stinger by {-r2['min_gap']:.3g} m")
    if bad:
        raise RuntimeError(f"S-lay a={a}: no admissible regime ({'; '.join(bad)})")
    return r2


def slay_regime_switch(EI, w_sub, w_dry, depth, lower, upper, a_lo, a_hi, T_top=None,
                       T_bottom=None, tol=1e-9, xtol=1e-10):
    """The stinger coefficient a [1/m] in [a_lo, a_hi] where regime 1's lift-off
    point reaches the tip (z_lo = z_L), by brentq on z_lo(a) - z_L."""
    zL = float(lower[1])

    def f(a):
        r = slay_elastica(EI, w_sub, w_dry, depth, a, lower, upper, T_top, T_bottom, tol,
                          regime="liftoff")
        return r["liftoff_z"] - zL

    return brentq(f, a_lo, a_hi, xtol=xtol)

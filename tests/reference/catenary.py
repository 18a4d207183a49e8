"""Closed-form natural catenary (no bending stiffness) touching a flat seabed.

Reference solution for the tests, independent of ``pipelay_fast``.

Coordinates: ``x`` height above the seabed [m], ``z`` horizontal [m] towards the
vessel; ``zeta = z - z_tdp``. The cable leaves the seabed tangentially at the
touchdown point (TDP, x = 0, zero slope) and carries a constant horizontal force
``H`` [N] (no horizontal loads). With a uniform effective weight ``w`` [N/m] and
catenary parameter ``a = H / w`` [m]:

    x(zeta) = a (cosh(zeta / a) - 1)       height
    s(zeta) = a sinh(zeta / a)             arc length from the TDP
    tan(theta) = dx/dzeta = s / a          tangent angle from horizontal
    T = H cosh(zeta / a) = H + w x         effective tension
    s^2 = x^2 + 2 a x                      (from cosh^2 - sinh^2 = 1)

With two weights (``w_sub`` below the water surface x = d, ``w_dry`` above it),
the effective tension is still ``T(x) = H + int_0^x w dx`` and the slope is
continuous at the surface. Above the surface the curve is a catenary of parameter
``a2 = H / w_dry`` whose own (virtual) vertex lies below the surface; the arc
length measured from that virtual vertex is ``sigma = a2 tan(theta)``, so

    sigma_s = a2 p,   p = tan(theta_surface) = sqrt((1 + d/a1)^2 - 1)
    x - d   = sqrt(a2^2 + sigma^2) - sqrt(a2^2 + sigma_s^2)
    z - z_s = a2 (asinh(sigma / a2) - asinh(sigma_s / a2))
    s - s_s = sigma - sigma_s

which is the same curve as in the brief's ``cosh`` form (``sigma = a2 sinh u``).
"""

from __future__ import annotations

import math

import numpy as np


def _horizontal_force(x_top, T_top, T_bottom, weight_rise):
    """H [N] from exactly one of T_top / T_bottom; ``weight_rise = int_0^x_top w dx``."""
    if (T_top is None) == (T_bottom is None):
        raise ValueError("give exactly one of T_top and T_bottom")
    H = float(T_bottom) if T_bottom is not None else float(T_top) - weight_rise
    if not H > 0.0:
        raise ValueError(f"horizontal tension must be positive, got H = {H} N")
    if not x_top > 0.0:
        raise ValueError(f"x_top must be positive, got {x_top} m")
    return H


def _segment(a, x_rise, sigma0):
    """A catenary of parameter a [m] starting at arc length sigma0 from its vertex
    and rising by x_rise [m]. Returns (arc length, span, sigma at the end)."""
    x0 = math.sqrt(a * a + sigma0 * sigma0)  # a cosh(u0)
    x1 = x0 + x_rise  # a cosh(u1)
    sigma1 = math.sqrt(x1 * x1 - a * a)  # a sinh(u1)
    span = a * (math.asinh(sigma1 / a) - math.asinh(sigma0 / a))
    return sigma1 - sigma0, span, sigma1


def natural_catenary(w, x_top, T_top=None, T_bottom=None):
    """Natural catenary of uniform effective weight.

    Parameters
    ----------
    w : float
        Effective weight per unit length [N/m], > 0.
    x_top : float
        Height of the top above the seabed [m].
    T_top, T_bottom : float
        Effective tension at the top [N], or at the bottom (= horizontal force H)
        [N]; exactly one.

    Returns
    -------
    dict with H [N], T_top [N], suspended_length [m] (TDP to top),
    horizontal_span [m] (z_top - z_tdp), top_angle_deg [deg from horizontal],
    catenary_parameter [m] (H / w).
    """
    H = _horizontal_force(x_top, T_top, T_bottom, w * x_top)
    a = H / w
    length, span, sigma = _segment(a, x_top, 0.0)
    return {
        "H": H,
        "T_top": H + w * x_top,
        "suspended_length": length,
        "horizontal_span": span,
        "top_angle_deg": math.degrees(math.atan2(sigma, a)),
        "catenary_parameter": a,
    }


def natural_catenary_two_weights(w_sub, w_dry, depth, x_top, T_top=None, T_bottom=None):
    """Natural catenary with w_sub [N/m] below the water surface x = depth [m] and
    w_dry [N/m] above it (the top may be above the surface).

    Same arguments and keys as :func:`natural_catenary`, plus
    ``surface_length`` [m] (arc length TDP -> surface), ``surface_span`` [m]
    (z_surface - z_tdp) and ``surface_angle_deg`` [deg] (None when the top is
    below the surface, in which case the result is the single-weight catenary).
    """
    if x_top <= depth:
        out = natural_catenary(w_sub, x_top, T_top=T_top, T_bottom=T_bottom)
        out.update(surface_length=None, surface_span=None, surface_angle_deg=None)
        return out
    rise = w_sub * depth + w_dry * (x_top - depth)
    H = _horizontal_force(x_top, T_top, T_bottom, rise)
    a1, a2 = H / w_sub, H / w_dry
    len1, span1, sigma1 = _segment(a1, depth, 0.0)
    slope = sigma1 / a1  # tan(theta) at the surface, continuous across it
    len2, span2, sigma2 = _segment(a2, x_top - depth, a2 * slope)
    return {
        "H": H,
        "T_top": H + rise,
        "suspended_length": len1 + len2,
        "horizontal_span": span1 + span2,
        "top_angle_deg": math.degrees(math.atan2(sigma2, a2)),
        "catenary_parameter": a1,
        "surface_length": len1,
        "surface_span": span1,
        "surface_angle_deg": math.degrees(math.atan(slope)),
    }


def catenary_profile(w_sub, w_dry, depth, H, s):
    """Profile of the two-weight catenary with horizontal force H [N] at arc
    lengths s [m] from the TDP (array). Returns dict of arrays x, z (from the TDP),
    theta [rad], curvature [1/m] (d theta / ds), Fx (vertical force = H tan theta)
    [N] and tension [N]. Used as the initial guess of the elastica."""
    s = np.asarray(s, dtype=float)
    a1, a2 = H / w_sub, H / w_dry
    x = np.sqrt(a1 * a1 + s * s) - a1
    z = a1 * np.arcsinh(s / a1)
    theta = np.arctan2(s, a1)
    curv = np.cos(theta) ** 2 / a1
    above = x > depth
    if np.any(above):
        len1, span1, sigma1 = _segment(a1, depth, 0.0)
        sig0 = a2 * sigma1 / a1
        sig = sig0 + (s[above] - len1)
        x[above] = depth + np.sqrt(a2 * a2 + sig * sig) - math.sqrt(a2 * a2 + sig0 * sig0)
        z[above] = span1 + a2 * (np.arcsinh(sig / a2) - math.asinh(sig0 / a2))
        theta[above] = np.arctan2(sig, a2)
        curv[above] = np.cos(theta[above]) ** 2 / a2
    Fx = H * np.tan(theta)
    tension = np.hypot(H, Fx)
    return {"x": x, "z": z, "theta": theta, "curvature": curv, "Fx": Fx, "tension": tension}

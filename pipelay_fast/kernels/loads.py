"""Distributed loads at a point of the pipe: effective weight, pressures, current.

They take the height ``x`` above the seabed [m], the ``props`` vector of
:mod:`pipelay_fast.kernels.layout` and the element's ``section`` row ``sec`` (S_*).
"""

from __future__ import annotations

import math

from . import layout as L
from ._jit import jit, phase
from .bed import bed_height
from .tuning import POWER_FLOOR


@jit(_nrt=False)
def effective_weight(props, sec, x):
    """Effective weight per unstretched length [N/m] at height ``x``.

    Submerged weight below the water surface, dry weight above it, contents
    counted below their free surface. Its jump at the surface enters the
    element's tangent through the movement of the cut there
    (:func:`.element_dle._cut_jumps`).
    """
    w = sec[L.S_W_DRY]
    if x < props[L.H_CONT]:
        w += sec[L.S_W_CONT]
    if x < props[L.DEPTH]:
        w -= sec[L.S_W_BUOY]
    return w


@phase
def seabed_surface(props, bed, z):
    """(x [m], dx/dz [-]) of the elastic seabed's surface at z [m]: the
    sloped plane tan(a) (z - z0) (props ``SEABED_TAN``, ``SEABED_Z0``; the
    arithmetic of :func:`.supports.support_height`'s plane) or, flat, the
    profile's height (:func:`.bed.bed_height` of the knots ``bed``; 0
    without)."""
    m = props[L.SEABED_TAN]
    if m != 0.0:
        return m * (z - props[L.SEABED_Z0]), m
    return bed_height(bed, z)


@phase
def foundation(props, bed, k_bed, x, z):
    """The elastic seabed's load at (``x``, ``z``) [m]: (q_x, q_z [N/m],
    dq_x/dx, dq_x/dz, dq_z/dx, dq_z/dz [N/m2]), zeros above the seabed's
    height x_b(z) (:func:`seabed_surface`) or with
    ``k_bed`` 0 (rigid). It pushes where x <= x_b(z) (at x = x_b its tangent:
    the pipe lands on it) along the plane's normal n = (1, -m) / sqrt(1 +
    m^2), m = props[SEABED_TAN] the sloped plane's tan(angle), with k_bed
    [N/m per m] times the normal penetration (x_b - x) / sqrt(1 + m^2):
    q = k_bed (x_b - x) / (1 + m^2) (1, -m); m = 0 (the flat seabed, a
    profile): vertically, k_bed (x_b - x) e_x."""
    if k_bed <= 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    x_b, dx_b = seabed_surface(props, bed, z)
    if x > x_b:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    m = props[L.SEABED_TAN]
    if m == 0.0:
        return k_bed * (x_b - x), 0.0, -k_bed, k_bed * dx_b, 0.0, 0.0
    kn = k_bed / (1.0 + m * m)
    pen = x_b - x
    return kn * pen, -kn * m * pen, -kn, kn * dx_b, kn * m, -kn * m * dx_b


@jit(_nrt=False)
def wall_minus_effective(props, sec, x):
    """Tw - Te = pi Ai - pe Ae [N] at height ``x``, and its derivative d/dx [N/m]."""
    val = 0.0
    dval = 0.0
    hi = props[L.H_CONT]
    if x < hi:
        val += props[L.RHOI_G] * (hi - x) * sec[L.S_AREA_I]
        dval -= props[L.RHOI_G] * sec[L.S_AREA_I]
    d = props[L.DEPTH]
    if x < d:
        val -= props[L.RHOW_G] * (d - x) * sec[L.S_AREA_E]
        dval += props[L.RHOW_G] * sec[L.S_AREA_E]
    return val, dval


@jit(_nrt=False)
def current_speed(props, table, x):
    """Current speed [m/s] at height ``x`` and its derivative d/dx [1/s].

    Zero above the water surface and below the seabed. The power law
    V0 (x/d)^p has an infinite derivative at the seabed: below x = xs d
    (POWER_FLOOR) it is continued by the quadratic that vanishes at the
    seabed and matches its value and slope at xs d, V = Vs xi (2 - p + (p -
    1) xi) with xi = x / (xs d), Vs = V0 xs^p, so that the derivative is
    that of the profile used (an exact Newton tangent).
    """
    d = props[L.DEPTH]
    v0 = props[L.CUR_SPEED]
    if v0 == 0.0 or x > d or x < 0.0:
        return 0.0, 0.0
    kind = int(props[L.CUR_PROFILE])
    if kind == L.PROFILE_UNIFORM:
        return v0, 0.0
    if kind == L.PROFILE_LINEAR:
        return v0 * x / d, v0 / d
    if kind == L.PROFILE_POWER:
        p = props[L.CUR_EXP]
        xs = POWER_FLOOR
        if x > xs * d:
            v = v0 * (x / d) ** p
            return v, p * v / x
        vs = v0 * xs**p
        xi = x / (xs * d)
        return (vs * xi * (2.0 - p + (p - 1.0) * xi),
                vs * (2.0 - p + 2.0 * (p - 1.0) * xi) / (xs * d))
    # table: piecewise linear in x, constant beyond its ends
    n = table.shape[0]
    if x <= table[0, 0]:
        return table[0, 1], 0.0
    for k in range(n - 1):
        x0 = table[k, 0]
        x1 = table[k + 1, 0]
        if x <= x1:
            slope = (table[k + 1, 1] - table[k, 1]) / (x1 - x0)
            return table[k, 1] + slope * (x - x0), slope
    return table[n - 1, 1], 0.0


@jit(by_dimension=True, _nrt=False)
def drag_force(model, sec, nd, x, rp, q, dq_drp, dq_dx, work):
    """Morison drag per unstretched length on the current normal to the pipe.

    q = C |r'| |Vn| Vn with C = 1/2 rho_w C_D D_h (``sec``), Vn = V - (V.t) t, t = r'/|r'|.
    Writes q [N/m] and its derivatives dq/dr' [N/m] (nd x nd) and dq/dx [N/m2];
    returns False (and writes nothing) when there is no drag at this point.
    ``work`` is scratch space of at least 15 floats.
    """
    props = model.props
    cf = model.factors[L.F_CURRENT]
    if cf == 0.0:
        return False
    u, du = current_speed(props, model.table, x)
    if u == 0.0:
        return False
    c = sec[L.S_DRAG] * cf
    ey = props[L.CUR_EY]
    ez = props[L.CUR_EZ]
    t = work[0:nd]
    v = work[3:3 + nd]
    dv = work[6:6 + nd]
    vn = work[9:9 + nd]
    dvn = work[12:12 + nd]
    a = 0.0
    for i in range(nd):
        a += rp[i] * rp[i]
    a = math.sqrt(a)
    vt = 0.0
    dvt = 0.0
    for i in range(nd):
        t[i] = rp[i] / a
        # the current has no x component; slot nd-1 is z, slot 1 of 3D is y
        if i == 0:
            comp = 0.0
        elif i == nd - 1:
            comp = ez
        else:
            comp = ey
        v[i] = u * comp
        dv[i] = du * comp
        vt += v[i] * t[i]
        dvt += dv[i] * t[i]
    m = 0.0
    for i in range(nd):
        vn[i] = v[i] - vt * t[i]
        dvn[i] = dv[i] - dvt * t[i]
        m += vn[i] * vn[i]
    m = math.sqrt(m)
    if m == 0.0:
        return False
    for i in range(nd):
        q[i] = c * a * m * vn[i]
    # dVn/dr' = B = -(t V^T + (V.t) I) P with P = (I - t t^T) / a = dt/dr', so
    # B_ij = -(t_i (P V)_j + (V.t) P_ij) (P symmetric); dm/dr' = Vn^T B / m and
    # dq/dr' = C (m Vn t^T + a Vn (dm/dr') + a m B) (d|r'|/dr' = t^T)
    vt_over_a = vt / a
    for j in range(nd):
        # B_ij into dq_drp first ((P V)_j = (V_j - (V.t) t_j) / a = Vn_j / a)
        acc = 0.0
        for i in range(nd):
            b_ij = -(t[i] * vn[j] / a + vt_over_a * ((1.0 if i == j else 0.0) - t[i] * t[j]))
            dq_drp[i, j] = b_ij
            acc += vn[i] * b_ij
        dm_j = acc / m
        for i in range(nd):
            dq_drp[i, j] = c * (m * vn[i] * t[j] + a * vn[i] * dm_j + a * m * dq_drp[i, j])
    vdv = 0.0
    for k in range(nd):
        vdv += vn[k] * dvn[k]
    for i in range(nd):
        dq_dx[i] = c * a * (m * dvn[i] + vn[i] * vdv / m)
    return True

"""The rod element in the x-z plane: the 2D kernel the planar solves run.

The same weak form as :mod:`.element` (read its docstring: Garrett's rod,
cubic Hermite r, linear lam, 4 Gauss points a piece, the pieces split at the
water surface and the contents level, the exact tangent and dG/dle), written
for nd = 2 with scalars: no loops over components, no 3-vectors, no zero
slots, no torque (a planar case has none; the distributed moment's y
component, the one a planar case may carry, is kept). The generic kernel
:func:`.element.element_force_ws` solves 3D; with nd = 2 it is this kernel's
reference, and ``tests/test_element.py`` checks both against a NumPy
quadrature of the weak form.

Per Gauss point it computes the residual, the tangent's blocks and dG/dle in
one pass: the bending and lam blocks, which are the same for x and z, are
summed as 4 x 4 scalars and spread onto ``ke`` once after the loop.

The drag on a current along z, V = (0, v), in closed form (t = r'/|r'|):
the normal velocity is v t_x (-t_z, t_x), so

    q = C |r'| |Vn| Vn = C v|v| x'|x'| (-z', x') / |r'|^2,

C = 1/2 rho_w C_D D_h times the current's factor; its derivatives in r' and
x follow from it directly.
"""

from __future__ import annotations

from . import layout as L
from ._jit import jit, phase
from .element import _extension
from .element_dle import _cut_jumps
from .element_shapes import _CUTLEV, _CUTS, GAUSS_W, GAUSS_XI, level_cuts
from .loads import current_speed, effective_weight, foundation

# element unknowns: node a (x, z, x', z', lam) then node b
_XA, _ZA, _XPA, _ZPA, _LA = 0, 1, 2, 3, 4
_XB, _ZB, _XPB, _ZPB, _LB = 5, 6, 7, 8, 9
# scratch offsets in ``ws`` (below :mod:`.element_shapes`' cuts; :func:`.element_dle._cut_jumps`
# takes these slots as its own scratch once they are spread onto ``ke``)
_KA = 0  # (4, 4) sum of wl (EI N_k'' N_l'' + lam N_k' N_l')
_KX = 16  # (4, 4) sum of wl dqx/dx N_k N_l (the elastic seabed)


@jit(_nrt=False)
def _drag_2d(c, v, dv_dx, xp, zp):
    """Drag per unstretched length on a current (0, v) along z, and its
    derivatives: (qx, qz, dqx/dx', dqx/dz', dqz/dx', dqz/dz', dqx/dx, dqz/dx)."""
    a2 = xp * xp + zp * zp
    k = c * v * abs(v)
    s = xp * abs(xp)
    phi = s / a2
    dphi_dxp = 2.0 * abs(xp) / a2 - 2.0 * s * xp / (a2 * a2)
    dphi_dzp = -2.0 * s * zp / (a2 * a2)
    qx = -k * phi * zp
    qz = k * phi * xp
    dk = c * 2.0 * abs(v) * dv_dx
    return (qx, qz, -k * zp * dphi_dxp, -k * (phi + zp * dphi_dzp),
            k * (phi + xp * dphi_dxp), k * xp * dphi_dzp, -dk * phi * zp, dk * phi * xp)


@jit(_nrt=False)
def element_2d(nd, le, ue, model, sec, torque, fe, ke, want_tangent, dfe, want_dle, ws, wm):
    """Force vector ``fe`` (= G), tangent ``ke`` = dG/due and dG/dle ``dfe``
    of one planar element (unknowns per node x, z, x', z', lam); the
    arguments as :func:`.element.element_force_ws`'s, ``nd`` (2) and
    ``torque`` unused (:func:`.assembly.element_forces`)."""
    props = model.props
    ei = sec[L.S_EI]
    ea = sec[L.S_EA]
    extensible = props[L.EXTENSIBLE] != 0.0
    k_bed = props[L.SEABED_K]
    my = props[L.MOM_Y]
    c_drag = sec[L.S_DRAG] * model.factors[L.F_CURRENT]
    ez = props[L.CUR_EZ]
    has_current = c_drag != 0.0 and props[L.CUR_SPEED] != 0.0
    for a in range(10):
        fe[a] = 0.0
    if want_dle:
        for a in range(10):
            dfe[a] = 0.0
    if want_tangent:
        for a in range(10):
            for b in range(10):
                ke[a, b] = 0.0
        for a in range(32):
            ws[a] = 0.0
    xa = ue[_XA]
    za = ue[_ZA]
    xpa = ue[_XPA]
    zpa = ue[_ZPA]
    xpb = ue[_XPB]
    zpb = ue[_ZPB]
    la = ue[_LA]
    lb = ue[_LB]
    cx = ue[_XB] - xa  # the chord (round-off relative to the element, not the origin)
    cz = ue[_ZB] - za
    inv_le = 1.0 / le

    cuts = ws[_CUTS:_CUTS + 4]
    cutlev = ws[_CUTLEV:_CUTLEV + 4]
    ncut = level_cuts(props, le, xa, xpa, ue[_XB], xpb, cuts, cutlev)

    for gg in range(4 * ncut):
        part = gg // 4
        span = cuts[part + 1] - cuts[part]
        t = cuts[part] + span * GAUSS_XI[gg % 4]
        wl = GAUSS_W[gg % 4] * span * le
        t2 = t * t
        t3 = t2 * t
        # cubic Hermite (r_a, r'_a, r_b, r'_b; N_0 = 1 - N_2 acts through the chord)
        n0 = 1.0 - 3.0 * t2 + 2.0 * t3
        n1 = le * (t - 2.0 * t2 + t3)
        n2 = 3.0 * t2 - 2.0 * t3
        n3 = le * (t3 - t2)
        d1 = 1.0 - 4.0 * t + 3.0 * t2
        d2 = (6.0 * t - 6.0 * t2) * inv_le
        d0 = -d2
        d3 = 3.0 * t2 - 2.0 * t
        dd1 = (6.0 * t - 4.0) * inv_le
        dd2 = (6.0 - 12.0 * t) * inv_le * inv_le
        dd0 = -dd2
        dd3 = (6.0 * t - 2.0) * inv_le
        x = xa + n1 * xpa + n2 * cx + n3 * xpb
        z = za + n1 * zpa + n2 * cz + n3 * zpb
        xp = d1 * xpa + d2 * cx + d3 * xpb
        zp = d1 * zpa + d2 * cz + d3 * zpb
        xpp = dd1 * xpa + dd2 * cx + dd3 * xpb
        zpp = dd1 * zpa + dd2 * cz + dd3 * zpb
        p0 = 1.0 - t
        p1 = t
        lam = p0 * la + p1 * lb
        ext = _extension(props, sec, extensible, ei, ea, x, lam, xpp * xpp + zpp * zpp)
        loads = _loads_2d(model, sec, k_bed, has_current, c_drag, ez, x, z, xp, zp)
        # (-my z', my x'): the distributed moment's term r' x m on dr'
        state = (xp, zp, xpp, zpp, lam, -my * zp, my * xp)
        # --- residual
        shape = ((n0, n1, n2, n3), (d0, d1, d2, d3), (dd0, dd1, dd2, dd3))
        nn_, dn, ddn = shape
        off = (0, 2, 5, 7)  # the x unknown of each shape function (z: + 1)
        bx, bz, ax, az, wqx, wqz = _weighted_terms(wl, ei, state, loads)
        for k in range(4):
            fe[off[k]] += bx * ddn[k] + ax * dn[k] - wqx * nn_[k]
            fe[off[k] + 1] += bz * ddn[k] + az * dn[k] - wqz * nn_[k]
        cval = 0.5 * (xp * xp + zp * zp - 1.0) - ext[0]
        fe[_LA] += wl * p0 * cval
        fe[_LB] += wl * p1 * cval
        if want_dle:
            _dle_2d(dfe, wl, inv_le, ei, ea, extensible, my, (xpa, zpa, xpb, zpb), state, loads,
                    ext, shape, cval, p0, p1)
        if want_tangent:
            _tangent_2d(ke, ws, wl, ei, ea, extensible, my, state, loads, ext, shape, p0, p1)

    if want_tangent:
        off = (0, 2, 5, 7)
        for k in range(4):
            for l in range(4):
                kl = 4 * k + l if l >= k else 4 * l + k
                v = ws[_KA + kl]
                ke[off[k], off[l]] += v - ws[_KX + kl]
                ke[off[k] + 1, off[l] + 1] += v

    # (after the spread: _cut_jumps takes ws's first slots as its scratch)
    if (want_tangent or want_dle) and ncut > 1:
        _cut_jumps(2, le, ue, model, sec, ncut, cuts, cutlev, ke, want_tangent, dfe, want_dle,
                   ws, wm)


@phase
def _loads_2d(model, sec, k_bed, has_current, c_drag, ez, x, z, xp, zp):
    """The distributed load at (``x``, ``z``) [m] with slope (``xp``, ``zp``):
    (q_x, q_z [N/m], the seabed's dq_x/dx [N/m2], the drag's dq_x/dx',
    dq_x/dz', dq_z/dx', dq_z/dz' [N/m], dq_x/dx, dq_z/dx (the drag's and the
    seabed's) [N/m2] and the seabed's dq_x/dz, dq_z/dz [N/m2]); ``sec`` the
    element's section row. The elastic seabed: :func:`.loads.foundation`."""
    props = model.props
    qx = -effective_weight(props, sec, x)
    qz = 0.0
    fx, fz, dqx_bed, dqxz_bed, dqzx_bed, dqzz_bed = foundation(props, model.bed, k_bed, x, z)
    if dqx_bed != 0.0:
        qx += fx
        qz += fz
    dxx = 0.0  # drag: dq/dr' (dxx = dqx/dx' ...) and dq/dx
    dxz = 0.0
    dzx = 0.0
    dzz = 0.0
    dqx_dx = 0.0
    dqz_dx = 0.0
    if has_current:
        v, dv = current_speed(props, model.table, x)
        if v != 0.0:
            fx, fz, dxx, dxz, dzx, dzz, dqx_dx, dqz_dx = _drag_2d(c_drag, v * ez, dv * ez,
                                                                   xp, zp)
            qx += fx
            qz += fz
    return qx, qz, dqx_bed, dxx, dxz, dzx, dzz, dqx_dx, dqz_dx + dqzx_bed, dqxz_bed, dqzz_bed


@phase
def _weighted_terms(wl, ei, state, loads):
    """The integrand's factors of N_k'', N_k' and N_k in x and z, times
    ``wl``: (wl EI x'', wl EI z'', wl (lam x' + c_x), wl (lam z' + c_z),
    wl q_x, wl q_z); ``state`` (x', z', x'', z'', lam [N], the moment's c_x,
    c_z [N m/m]), ``loads`` :func:`_loads_2d`'s."""
    xp, zp, xpp, zpp, lam, cmx, cmz = state
    qx, qz = loads[0], loads[1]
    return (wl * ei * xpp, wl * ei * zpp, wl * (lam * xp + cmx), wl * (lam * zp + cmz),
            wl * qx, wl * qz)


@phase
def _dle_2d(dfe, wl, inv_le, ei, ea, extensible, my, slopes, state, loads, ext, shape, cval, p0,
            p1):
    """A Gauss point's share of dG/dle at fixed unknowns and abscissae
    (:mod:`.element_dle`'s docstring), weight ``wl`` [m]: ``slopes`` the
    nodal (x'_a, z'_a, x'_b, z'_b), ``state`` and ``loads`` as
    :func:`_weighted_terms`', ``ext`` :func:`.element._extension`'s,
    ``shape`` the shape functions (N, N', N'' as 4-tuples), ``cval`` the
    constraint's value, ``p0``, ``p1`` the multiplier's shape functions."""
    xpa, zpa, xpb, zpb = slopes
    xp, zp, xpp, zpp, lam, _cmx, _cmz = state
    _qx, _qz, dqx_bed, dxx, dxz, dzx, dzz, dqx_dx, dqz_dx, dqxz_bed, dqzz_bed = loads
    _e, de_deps, deps_dx = ext
    nn_, dn, ddn = shape
    dx = (nn_[1] * xpa + nn_[3] * xpb) * inv_le
    dxp = (dn[1] * xpa + dn[3] * xpb - xp) * inv_le
    dzp = (dn[1] * zpa + dn[3] * zpb - zp) * inv_le
    dxpp = (ddn[1] * xpa + ddn[3] * xpb - 2.0 * xpp) * inv_le
    dzpp = (ddn[1] * zpa + ddn[3] * zpb - 2.0 * zpp) * inv_le
    dcval = xp * dxp + zp * dzp
    if extensible:
        dcval -= de_deps * (2.0 * ei * (xpp * dxpp + zpp * dzpp) / ea + deps_dx * dx)
    dqx = (dqx_bed + dqx_dx) * dx + dxx * dxp + dxz * dzp
    if dqxz_bed != 0.0:
        dqx += dqxz_bed * (nn_[1] * zpa + nn_[3] * zpb) * inv_le
    dqz = dqz_dx * dx + dzx * dxp + dzz * dzp
    if dqzz_bed != 0.0:
        dqz += dqzz_bed * (nn_[1] * zpa + nn_[3] * zpb) * inv_le
    dlam = wl * (cval * inv_le + dcval)
    dfe[_LA] += p0 * dlam
    dfe[_LB] += p1 * dlam
    # N_k = le^p_k f_k(xi), p = (0, 1, 0, 1): the terms in 1/le
    off = (0, 2, 5, 7)
    gbx, gbz, gax, gaz, gqx, gqz = _weighted_terms(wl * inv_le, ei, state, loads)
    ebx = wl * ei * dxpp
    ebz = wl * ei * dzpp
    eax = wl * (lam * dxp - my * dzp)
    eaz = wl * (lam * dzp + my * dxp)
    eqx = wl * dqx
    eqz = wl * dqz
    for k in range(4):
        if k % 2 == 0:  # p_k = 0
            dfe[off[k]] += (ebx - gbx) * ddn[k] + eax * dn[k] - (eqx + gqx) * nn_[k]
            dfe[off[k] + 1] += (ebz - gbz) * ddn[k] + eaz * dn[k] - (eqz + gqz) * nn_[k]
        else:  # p_k = 1
            dfe[off[k]] += ebx * ddn[k] + (eax + gax) * dn[k] - (eqx + 2.0 * gqx) * nn_[k]
            dfe[off[k] + 1] += (ebz * ddn[k] + (eaz + gaz) * dn[k]
                                - (eqz + 2.0 * gqz) * nn_[k])


@phase
def _tangent_2d(ke, ws, wl, ei, ea, extensible, my, state, loads, ext, shape, p0, p1):
    """A Gauss point's share of the tangent: the bending and lam blocks and
    the seabed's into the 4 x 4 sums at ``ws[_KA]``, ``ws[_KX]`` (upper
    triangles), the load stiffness, the moment's term and the multipliers'
    rows and columns into ``ke``; the arguments as :func:`_dle_2d`'s."""
    xp, zp, xpp, zpp, lam, _cmx, _cmz = state
    _qx, _qz, dqx_bed, dxx, dxz, dzx, dzz, dqx_dx, dqz_dx, dqxz_bed, dqzz_bed = loads
    _e, de_deps, deps_dx = ext
    nn_, dn, ddn = shape
    off = (0, 2, 5, 7)
    wei = wl * ei
    wlam = wl * lam
    for k in range(4):
        for l in range(k, 4):
            ws[_KA + 4 * k + l] += wei * ddn[k] * ddn[l] + wlam * dn[k] * dn[l]
    if dqx_bed != 0.0:
        wq = wl * dqx_bed
        for k in range(4):
            for l in range(k, 4):
                ws[_KX + 4 * k + l] += wq * nn_[k] * nn_[l]
    if dqxz_bed != 0.0:  # the profile's slope: -N_k dq_x/dz N_l
        wq = wl * dqxz_bed
        for k in range(4):
            for l in range(4):
                ke[off[k], off[l] + 1] -= wq * nn_[k] * nn_[l]
    if dqzz_bed != 0.0:  # a sloped plane's normal: -N_k dq_z/dz N_l
        wq = wl * dqzz_bed
        for k in range(4):
            for l in range(4):
                ke[off[k] + 1, off[l] + 1] -= wq * nn_[k] * nn_[l]
    if (dxx != 0.0 or dxz != 0.0 or dzx != 0.0 or dzz != 0.0 or dqx_dx != 0.0
            or dqz_dx != 0.0 or my != 0.0):
        # load stiffness -N_k dq_i/du_(l,j), and the moment's H-free term
        for k in range(4):
            wn = wl * nn_[k]
            wd = wl * my * dn[k]
            ik = off[k]
            for l in range(4):
                jl = off[l]
                ke[ik, jl] -= wn * (dxx * dn[l] + dqx_dx * nn_[l])
                ke[ik, jl + 1] -= wn * dxz * dn[l] + wd * dn[l]
                ke[ik + 1, jl] -= wn * (dzx * dn[l] + dqz_dx * nn_[l]) - wd * dn[l]
                ke[ik + 1, jl + 1] -= wn * dzz * dn[l]
    for m in range(2):
        pm = p0 if m == 0 else p1
        lm = _LA if m == 0 else _LB
        wp = wl * pm
        ex = 0.0
        ez_ = 0.0
        ew = 0.0
        if extensible:
            ex = wp * de_deps * 2.0 * ei * xpp / ea
            ez_ = wp * de_deps * 2.0 * ei * zpp / ea
            ew = wp * de_deps * deps_dx
            ke[lm, _LA] -= wp * p0 * de_deps / ea
            ke[lm, _LB] -= wp * p1 * de_deps / ea
        for k in range(4):
            ik = off[k]
            vx = wp * xp * dn[k]
            vz = wp * zp * dn[k]
            ke[ik, lm] += vx
            ke[ik + 1, lm] += vz
            ke[lm, ik] += vx - ex * ddn[k] - ew * nn_[k]
            ke[lm, ik + 1] += vz - ez_ * ddn[k]

"""The rod element's derivative with respect to its length, dG/dle, and the
movement of its cuts (where the load jumps) in the tangent and in dG/dle.

dG/dle is taken at fixed nodal unknowns and fixed Gauss abscissae xi (the
mesh mapped onto moving contact boundaries, :mod:`.constraints`). The shape
functions are N_k = le^p_k f_k(xi) with p = (0, 1, 0, 1) (k = 0..3 for r_a,
r'_a, r_b, r'_b), so with ' = d/ds = (1/le) d/dxi and ds = le dxi

    d(N_k ds) = (p_k + 1) N_k ds / le,   d(N_k' ds) = p_k N_k' ds / le,
    d(N_k'' ds) = (p_k - 1) N_k'' ds / le,
    dr   =  (N_1 r'_a + N_3 r'_b) / le,
    dr'  = -(r'  - N_1' r'_a - N_3' r'_b) / le,
    dr'' = -(2 r'' - N_1'' r'_a - N_3'' r'_b) / le,

where d = d/dle, dx is the x component of dr and lam (linear in xi) does not
change. The rest is the chain rule: dq = (dq/dx) dx + (dq/dz) dz + (dq/dr') dr' with
the load derivatives the tangent uses (seabed, drag), dc3 = H (dr' x r'' +
r' x dr'') + dr' x m, and in the constraint row d[(r'.r' - 1)/2 - e] = r'.dr'
- (1 + eps) (2 EI r''.dr'' + (dTw/dx) dx) / EA. The cut points move with le
too: the jump of the integrand there enters both, as in the tangent
(:func:`_cut_jumps`).
"""

from __future__ import annotations

import numpy as np

from . import layout as L
from ._jit import jit
from .element_shapes import (
    _C3,
    _DDN,
    _DN,
    _DQ,
    _DQ_DX,
    _DRP,
    _DRPP,
    _M3,
    _N,
    _P,
    _Q,
    _RP,
    _RP3,
    _RPP,
    _RPP3,
    _cross_t,
    _point_views,
    hermite,
)
from .loads import drag_force, effective_weight


@jit(by_dimension=True, _nrt=False)
def _cut_jumps(nd, le, ue, model, sec, ncut, cuts, cutlev, ke, want_tangent, dfe, want_dle, ws,
               wm):
    """The movement of the cuts: the load q jumps at a crossed level (the
    weight at the water surface and the contents level, the drag at the water
    surface), and each cut xi_c, X(xi_c) = level with X the height x along the
    element, moves with the nodal x unknowns and with le. By Leibniz' rule
    dG_(k,i) = le (h_L - h_R)(xi_c) dxi_c, h = -q_i N_k the load's integrand,
    L and R the pieces below and above xi_c, with dxi_c/du_(l,x) = -N_l /
    (le x') and dxi_c/dle = -(N_1 x'_a + N_3 x'_b) / (le^2 x'). ``sec``: the
    element's section row (:mod:`.layout` ``S_*``)."""
    ndn = 2 * nd + 1
    off = (0, nd, ndn, ndn + nd)
    props = model.props
    n, dn, ddn, rp, qd, dq_dx, dq_drp, dwork = _point_views(nd, ws, wm)
    jump = ws[_DQ:_DQ + nd]
    for c in range(1, ncut):
        xi_c = cuts[c]
        level = cutlev[c]
        hermite(xi_c, le, n, dn, ddn)
        for i in range(nd):
            chord = ue[ndn + i] - ue[i]
            rp[i] = dn[1] * ue[nd + i] + dn[2] * chord + dn[3] * ue[ndn + nd + i]
        if rp[0] == 0.0:
            continue
        # q below minus q above the level, then signed: L is node a's side
        for i in range(nd):
            jump[i] = 0.0
        for side in range(2):
            x_s = np.nextafter(level, -np.inf) if side == 0 else np.nextafter(level, np.inf)
            sgn = 1.0 if side == 0 else -1.0
            jump[0] -= sgn * effective_weight(props, sec, x_s)
            if drag_force(model, sec, nd, x_s, rp, qd, dq_drp, dq_dx, dwork):
                for i in range(nd):
                    jump[i] += sgn * qd[i]
        if ue[0] > level:
            for i in range(nd):
                jump[i] = -jump[i]
        inv = 1.0 / rp[0]
        dle_x = (n[1] * ue[nd] + n[3] * ue[ndn + nd]) / (le * le)
        for k in range(4):
            for i in range(nd):
                a = jump[i] * n[k] * inv  # (q_L - q_R)_i N_k / x'
                if want_tangent:
                    for l in range(4):
                        ke[off[k] + i, off[l]] += a * n[l]
                if want_dle:
                    dfe[off[k] + i] += a * dle_x * le


@jit(by_dimension=True, _nrt=False)
def _dle_gauss_point(nd, le, ue, props, sec, torque, wl, p0, p1, lam, cval, de_deps, deps_dx,
                     dq_bed, has_drag, ws, wm, dfe):
    """Add one Gauss point's share of dG/dle to ``dfe`` (module docstring).

    Reads the point's values that :func:`.element.element_force_ws` left in
    ``ws`` and ``wm``; ``sec`` the element's section row; ``dq_bed`` the
    seabed's load derivatives (dq_x/dx, dq_x/dz, dq_z/dx, dq_z/dz) [N/m2]
    (:func:`.loads.foundation`); ``torque`` is 0
    where the torque term is off. A
    function of its own, not inlined, so that the kernel's Gauss loop runs as
    fast without it.
    """
    ndn = 2 * nd + 1
    off = (0, nd, ndn, ndn + nd)
    slot3 = (0, 1 if nd == 3 else 2, 2)
    ei = sec[L.S_EI]
    ea = sec[L.S_EA]
    inv_le = 1.0 / le
    dx = (ws[_N + 1] * ue[nd] + ws[_N + 3] * ue[ndn + nd]) * inv_le
    dcval = 0.0
    drpp_rpp = 0.0
    for i in range(nd):
        ta = ue[nd + i]
        tb = ue[ndn + nd + i]
        drp = (ws[_DN + 1] * ta + ws[_DN + 3] * tb - ws[_RP + i]) * inv_le
        drpp = (ws[_DDN + 1] * ta + ws[_DDN + 3] * tb - 2.0 * ws[_RPP + i]) * inv_le
        ws[_DRP + i] = drp
        ws[_DRPP + i] = drpp
        dcval += ws[_RP + i] * drp
        drpp_rpp += ws[_RPP + i] * drpp
    dqx_dx, dqx_dz, dqz_dx, dqz_dz = dq_bed
    for i in range(nd):
        dq = dqx_dx * dx if i == 0 else 0.0
        if i == 0 and dqx_dz != 0.0:  # the profile's slope: dz as dx
            dz = (ws[_N + 1] * ue[2 * nd - 1] + ws[_N + 3] * ue[ndn + 2 * nd - 1]) * inv_le
            dq += dqx_dz * dz
        if i == nd - 1 and dqz_dx != 0.0:  # a sloped plane's normal
            dz = (ws[_N + 1] * ue[2 * nd - 1] + ws[_N + 3] * ue[ndn + 2 * nd - 1]) * inv_le
            dq += dqz_dx * dx + dqz_dz * dz
        if has_drag:
            dq += ws[_DQ_DX + i] * dx
            for j in range(nd):
                dq += wm[i, j] * ws[_DRP + j]
        ws[_DQ + i] = dq
    if props[L.EXTENSIBLE] != 0.0:
        dcval -= de_deps * (2.0 * ei * drpp_rpp / ea + deps_dx * dx)
    d_lam_row = wl * (cval * inv_le + dcval)
    dfe[2 * nd] += p0 * d_lam_row
    dfe[ndn + 2 * nd] += p1 * d_lam_row

    # c3 (computed by the kernel) and dc3 = H (dr' x r'' + r' x dr'') + dr' x m
    c3 = (0.0, 0.0, 0.0)
    dc3 = (0.0, 0.0, 0.0)
    m3 = (ws[_M3], ws[_M3 + 1], ws[_M3 + 2])
    use_moment = m3[0] != 0.0 or m3[1] != 0.0 or m3[2] != 0.0
    if torque != 0.0 or use_moment:
        c3 = (ws[_C3], ws[_C3 + 1], ws[_C3 + 2])
        drp3 = (ws[_DRP], ws[_DRP + 1] if nd == 3 else 0.0, ws[_DRP + nd - 1])
        drpp3 = (ws[_DRPP], ws[_DRPP + 1] if nd == 3 else 0.0, ws[_DRPP + nd - 1])
        h1 = _cross_t(drp3, (ws[_RPP3], ws[_RPP3 + 1], ws[_RPP3 + 2]))
        h2 = _cross_t((ws[_RP3], ws[_RP3 + 1], ws[_RP3 + 2]), drpp3)
        dm = _cross_t(drp3, m3)
        dc3 = (torque * (h1[0] + h2[0]) + dm[0], torque * (h1[1] + h2[1]) + dm[1],
               torque * (h1[2] + h2[2]) + dm[2])
    for k in range(4):
        pk = _P[k]
        nk = ws[_N + k]
        dnk = ws[_DN + k]
        ddnk = ws[_DDN + k]
        for i in range(nd):
            rp_term = lam * ws[_RP + i] + c3[slot3[i]]
            drp_term = lam * ws[_DRP + i] + dc3[slot3[i]]
            dfe[off[k] + i] += wl * (
                (ei * ws[_RPP + i] * ddnk * (pk - 1.0) + rp_term * dnk * pk
                 - ws[_Q + i] * nk * (pk + 1.0)) * inv_le
                + ei * ws[_DRPP + i] * ddnk + drp_term * dnk - ws[_DQ + i] * nk)


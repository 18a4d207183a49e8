"""Garrett's rod element: internal-minus-external force vector, its tangent, and
its derivative with respect to the element length.

Weak form over one element of unstretched length ``le`` (s the unstretched arc
length, ``d`` a virtual field, ``'`` = d/ds):

    G_r   = int [ EI r''.dr'' + lam r'.dr' + H (r' x r'').dr' + (r' x m).dr' - q.dr ] ds
    G_lam = int dlam [ (r'.r' - 1)/2 - e ] ds,   e = eps + eps^2/2,  eps = Tw/EA

so that |r'| = 1 + eps exactly, with Te = lam + EI kappa^2 (kappa^2 = r''.r''),
Tw = Te + pi Ai - pe Ae (inextensible: e = 0). r is cubic Hermite (nodal r, r'),
lam linear (nodal values). Gauss-Legendre with 4 points integrates every
polynomial term exactly (the highest is lam (r'.dr'), degree 5).

An element that crosses the water surface or the contents level is integrated
piecewise, 4 points on each side of the crossing.

Loads q: effective weight -w(x) e_x, Morison drag on
the normal current (times the current factor), an elastic seabed -k x e_x where
x < 0. The torque and distributed-moment terms are evaluated only when they are
non-zero. The tangent is the exact derivative of G, the movement of the cuts
included (the load's jump there, :func:`_cut_jumps`).

Derivative with respect to the element length (for meshes mapped onto moving
contact boundaries), at fixed nodal unknowns and fixed Gauss abscissae xi.
The shape functions are N_k = le^p_k f_k(xi) with p = (0, 1, 0, 1) (k = 0..3
for r_a, r'_a, r_b, r'_b), so with ' = d/ds = (1/le) d/dxi and ds = le dxi

    d(N_k ds) = (p_k + 1) N_k ds / le,   d(N_k' ds) = p_k N_k' ds / le,
    d(N_k'' ds) = (p_k - 1) N_k'' ds / le,
    dr   =  (N_1 r'_a + N_3 r'_b) / le,
    dr'  = -(r'  - N_1' r'_a - N_3' r'_b) / le,
    dr'' = -(2 r'' - N_1'' r'_a - N_3'' r'_b) / le,

where d = d/dle, dx is the x component of dr and lam (linear in xi) does not
change. The rest is the chain rule: dq = (dq/dx) dx + (dq/dr') dr' with
the load derivatives the tangent uses (seabed, drag), dc3 = H (dr' x r'' +
r' x dr'') + dr' x m, and in the constraint row d[(r'.r' - 1)/2 - e] = r'.dr'
- (1 + eps) (2 EI r''.dr'' + (dTw/dx) dx) / EA. The cut points move with le
too: the jump of the integrand there enters both, as in the tangent
(:func:`_cut_jumps`).

The same code serves 2D (nd = 2: slots x, z) and 3D (nd = 3: x, y, z), so the
planar model is a reduction of the spatial one, not a second model.
"""

from __future__ import annotations

import numpy as np

from . import layout as L
from ._jit import jit
from .loads import drag_force, effective_weight, wall_minus_effective
from .types import Model, load_factors

_G = np.sqrt(3.0 / 7.0 - 2.0 / 7.0 * np.sqrt(6.0 / 5.0))
_H = np.sqrt(3.0 / 7.0 + 2.0 / 7.0 * np.sqrt(6.0 / 5.0))
_WG = (18.0 + np.sqrt(30.0)) / 36.0
_WH = (18.0 - np.sqrt(30.0)) / 36.0
GAUSS_XI = np.array([0.5 - 0.5 * _H, 0.5 - 0.5 * _G, 0.5 + 0.5 * _G, 0.5 + 0.5 * _H])
GAUSS_W = np.array([0.5 * _WH, 0.5 * _WG, 0.5 * _WG, 0.5 * _WH])


@jit(_nrt=False)
def hermite(xi, le, n, dn, ddn):
    """Cubic Hermite shape functions on [0, le] at xi = s/le, with d/ds and d2/ds2.

    Order: r_a, r'_a, r_b, r'_b.
    """
    xi2 = xi * xi
    xi3 = xi2 * xi
    n[0] = 1.0 - 3.0 * xi2 + 2.0 * xi3
    n[1] = le * (xi - 2.0 * xi2 + xi3)
    n[2] = 3.0 * xi2 - 2.0 * xi3
    n[3] = le * (-xi2 + xi3)
    dn[0] = (-6.0 * xi + 6.0 * xi2) / le
    dn[1] = 1.0 - 4.0 * xi + 3.0 * xi2
    dn[2] = (6.0 * xi - 6.0 * xi2) / le
    dn[3] = -2.0 * xi + 3.0 * xi2
    ddn[0] = (-6.0 + 12.0 * xi) / (le * le)
    ddn[1] = (-4.0 + 6.0 * xi) / le
    ddn[2] = (6.0 - 12.0 * xi) / (le * le)
    ddn[3] = (-2.0 + 6.0 * xi) / le


@jit(_nrt=False)
def hermite_crossing(xa, pa, xb, pb, le, level):
    """xi in (0, 1) where a Hermite coordinate crosses ``level``, else -1.

    ``xa, xb`` are the nodal values of the coordinate, ``pa, pb`` their
    derivatives d/ds (the height x at the water surface, z at the stinger tip). Newton from
    the chord estimate; the root is unique when the element is monotone in x,
    which holds for any element shorter than the local radius of curvature.
    """
    fa = xa - level
    fb = xb - level
    if fa * fb >= 0.0:
        return -1.0
    xi = fa / (fa - fb)
    for _ in range(30):
        xi2 = xi * xi
        xi3 = xi2 * xi
        f = ((1.0 - 3.0 * xi2 + 2.0 * xi3) * xa + le * (xi - 2.0 * xi2 + xi3) * pa
             + (3.0 * xi2 - 2.0 * xi3) * xb + le * (-xi2 + xi3) * pb - level)
        df = ((-6.0 * xi + 6.0 * xi2) * xa + le * (1.0 - 4.0 * xi + 3.0 * xi2) * pa
              + (6.0 * xi - 6.0 * xi2) * xb + le * (-2.0 * xi + 3.0 * xi2) * pb)
        if df == 0.0:
            break
        step = f / df
        xi -= step
        if xi <= 0.0 or xi >= 1.0:
            return fa / (fa - fb)
        if abs(step) < 1e-14:
            break
    return xi


@jit(_nrt=False)
def level_cuts(props, le, xa, pa, xb, pb, cuts, cutlev):
    """The pieces an element is integrated in: split where its height x
    (nodal xa, xb and slopes pa, pb) crosses the water surface or the
    contents level. Writes the abscissae 0 = cuts[0] < ... < cuts[ncut] = 1
    and the level each inner cut crosses (``cutlev``); returns ncut."""
    cuts[0] = 0.0
    ncut = 1
    for lev in range(2):
        level = props[L.DEPTH] if lev == 0 else props[L.H_CONT]
        xi_c = hermite_crossing(xa, pa, xb, pb, le, level)
        if xi_c > 0.0:
            cuts[ncut] = xi_c
            cutlev[ncut] = level
            ncut += 1
    cuts[ncut] = 1.0
    if ncut == 3 and cuts[1] > cuts[2]:
        cuts[1], cuts[2] = cuts[2], cuts[1]
        cutlev[1], cutlev[2] = cutlev[2], cutlev[1]
    return ncut


@jit(_nrt=False)
def _cross3(a, b, out):
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@jit(_nrt=False)
def _cross_t(a, b):
    """a x b of two 3-tuples, as a tuple."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


# Layout of the scratch vector ``ws``: offsets of the per-Gauss-point values.
# The kernel views them through slices; _dle_gauss_point indexes ``ws`` directly
# (slices there would cost more than its arithmetic).
_N, _DN, _DDN = 0, 4, 8  # shape functions and their d/ds, d2/ds2
_R, _RP, _RPP = 12, 15, 18  # r, r', r''
_Q, _QD, _DQ_DX = 21, 24, 27  # load, drag, d(drag)/dx
_RP3, _RPP3, _M3, _C3, _E3 = 30, 33, 36, 39, 42  # 3-vectors of the torque terms
_CUTS, _DWORK = 45, 49  # crossing abscissae; drag_force's scratch (15)
_DRP, _DRPP, _DQ = 64, 67, 70  # d/dle of r', r'', q
_KA, _KX = 73, 89  # (4, 4) sums over the Gauss points: EI N''N'' + lam N'N', N dqx/dx N
_CUTLEV = 105  # the level each crossing abscissa crosses
WORK_SIZE = 109
_P = (0.0, 1.0, 0.0, 1.0)  # power of le in each shape function


def element_force(nd, le, ue, props, table, torque, fe, ke, want_tangent, dfe=None,
                  current_factor=1.0):
    """Force vector ``fe`` (= G), tangent ``ke`` = dG/due and, if ``dfe`` is
    given, ``dfe`` = dG/dle of one element, with the current's drag times
    ``current_factor``.

    Allocating Python wrapper of the kernel the solves run (in 2D the planar
    one, :func:`.element2d.element_2d`; in 3D :func:`element_force_ws`) for
    tests and one-off calls; it always calls it with the same argument types.
    """
    from .assembly import element_forces_py  # (assembly imports this module)

    want_dle = dfe is not None
    model = Model(props, table, load_factors(current_factor, False))
    element_forces_py(nd, le, ue, model, torque, fe, ke, want_tangent,
                      dfe if want_dle else np.zeros(ue.size), want_dle,
                      np.empty(WORK_SIZE), np.empty((3, 3)))


@jit(by_dimension=True, _nrt=False)
def element_force_ws(nd, le, ue, model, torque, fe, ke, want_tangent, dfe, want_dle, ws, wm):
    """Force vector ``fe`` (= G), tangent ``ke`` = dG/due, and dG/dle of one element.

    Parameters
    ----------
    nd : int
        2 or 3 space dimensions.
    le : float
        Unstretched element length [m].
    ue : (2*(2nd+1),) float64
        Nodal unknowns of the two nodes (layout in :mod:`.layout`).
    model : :data:`.types.Model`
        The case's data ``props`` (:mod:`.layout`), the current table
        ``[[x, speed], ...]`` and the load path's factors (``F_*``).
    torque : float
        Torque H in this element [N m] (3D only).
    fe, ke : float64 arrays, overwritten
        Residual [N, N m, m] and tangent.
    want_tangent : bool
        Skip the tangent when only the residual is needed (line search).
    dfe : float64 array, overwritten when ``want_dle``
        dG/dle [N/m, N, 1] at fixed ``ue`` (length ``ue.size``; may be empty
        when not wanted).
    want_dle : bool
        Compute ``dfe`` (in the same pass over the Gauss points).
    ws, wm : float64 work arrays of sizes ``WORK_SIZE`` and (3, 3)
        Scratch space, so the kernel allocates nothing.
    """
    ndn = 2 * nd + 1
    ne = 2 * ndn
    props = model.props
    ei = props[L.EI]
    ea = props[L.EA]
    extensible = props[L.EXTENSIBLE] != 0.0
    k_bed = props[L.SEABED_K]
    use_torque = nd == 3 and torque != 0.0
    mx = props[L.MOM_X]
    my = props[L.MOM_Y]
    mz = props[L.MOM_Z]
    use_moment = mx != 0.0 or my != 0.0 or mz != 0.0
    for a in range(ne):
        fe[a] = 0.0
    # the tangent's blocks that are the same for each component i (the
    # bending and lam terms, and the seabed's x-x stiffness), summed over the
    # Gauss points as 4 x 4 scalars and spread onto ke once, after the loop
    ka = ws[_KA:_KA + 16]
    kx = ws[_KX:_KX + 16]
    if want_tangent:
        for a in range(ne):
            for b in range(ne):
                ke[a, b] = 0.0
        for a in range(16):
            ka[a] = 0.0
            kx[a] = 0.0
    if want_dle:
        for a in range(ne):
            dfe[a] = 0.0

    # local index of shape function k, component i:  off[k] + i
    off = (0, nd, ndn, ndn + nd)
    lam_idx = (2 * nd, ndn + 2 * nd)

    n = ws[_N:_N + 4]
    dn = ws[_DN:_DN + 4]
    ddn = ws[_DDN:_DDN + 4]
    r = ws[_R:_R + nd]
    rp = ws[_RP:_RP + nd]
    rpp = ws[_RPP:_RPP + nd]
    q = ws[_Q:_Q + nd]
    qd = ws[_QD:_QD + nd]
    dq_dx = ws[_DQ_DX:_DQ_DX + nd]
    dq_drp = wm[:nd, :nd]
    # 3-vectors for the torque / moment terms (2D embeds y = 0)
    rp3 = ws[_RP3:_RP3 + 3]
    rpp3 = ws[_RPP3:_RPP3 + 3]
    m3 = ws[_M3:_M3 + 3]
    m3[0] = mx
    m3[1] = my
    m3[2] = mz
    c3 = ws[_C3:_C3 + 3]
    e3 = ws[_E3:_E3 + 3]
    dwork = ws[_DWORK:_DWORK + 15]
    slot3 = (0, 1 if nd == 3 else 2, 2)

    # Split the element where it crosses the water surface or the contents level,
    # so the jump of the effective weight is integrated exactly.
    cuts = ws[_CUTS:_CUTS + 4]
    cutlev = ws[_CUTLEV:_CUTLEV + 4]
    ncut = level_cuts(props, le, ue[0], ue[nd], ue[ndn], ue[ndn + nd], cuts, cutlev)
    for gg in range(4 * ncut):
        part = gg // 4
        g = gg % 4
        span = cuts[part + 1] - cuts[part]
        xi = cuts[part] + span * GAUSS_XI[g]
        wl = GAUSS_W[g] * span * le
        hermite(xi, le, n, dn, ddn)
        p0 = 1.0 - xi
        p1 = xi
        # r' and r'' from the chord r_b - r_a (their shape functions of r_a and
        # r_b are opposite), which keeps round-off relative to the element size
        # rather than to the distance from the origin
        for i in range(nd):
            ra = ue[i]
            chord = ue[ndn + i] - ra
            r[i] = ra + n[1] * ue[nd + i] + n[2] * chord + n[3] * ue[ndn + nd + i]
            rp[i] = dn[1] * ue[nd + i] + dn[2] * chord + dn[3] * ue[ndn + nd + i]
            rpp[i] = ddn[1] * ue[nd + i] + ddn[2] * chord + ddn[3] * ue[ndn + nd + i]
        lam = p0 * ue[lam_idx[0]] + p1 * ue[lam_idx[1]]
        x = r[0]
        rp2 = 0.0
        kap2 = 0.0
        for i in range(nd):
            rp2 += rp[i] * rp[i]
            kap2 += rpp[i] * rpp[i]

        # --- extensibility ------------------------------------------------
        e = 0.0
        de_deps = 0.0
        deps_dx = 0.0
        if extensible:
            dtw, ddtw_dx = wall_minus_effective(props, x)
            eps = (lam + ei * kap2 + dtw) / ea
            e = eps + 0.5 * eps * eps
            de_deps = 1.0 + eps
            deps_dx = ddtw_dx / ea

        # --- distributed loads --------------------------------------------
        for i in range(nd):
            q[i] = 0.0
        q[0] = -effective_weight(props, x)
        dqx_dx = 0.0
        if k_bed > 0.0 and x <= 0.0:  # (at x = 0 its tangent: the pipe lands on it)
            q[0] -= k_bed * x
            dqx_dx = -k_bed
        has_drag = drag_force(model, nd, x, rp, qd, dq_drp, dq_dx, dwork)
        if has_drag:
            for i in range(nd):
                q[i] += qd[i]

        # --- residual -----------------------------------------------------
        for k in range(4):
            for i in range(nd):
                fe[off[k] + i] += wl * (ei * rpp[i] * ddn[k] + lam * rp[i] * dn[k] - q[i] * n[k])
        cval = 0.5 * (rp2 - 1.0) - e
        fe[lam_idx[0]] += wl * p0 * cval
        fe[lam_idx[1]] += wl * p1 * cval

        if use_torque or use_moment:
            for i in range(3):
                rp3[i] = 0.0
                rpp3[i] = 0.0
            for i in range(nd):
                rp3[slot3[i]] = rp[i]
                rpp3[slot3[i]] = rpp[i]
            # c3 = H (r' x r'') + r' x m   acts on dr'
            _cross3(rp3, rpp3, c3)
            hh = torque if use_torque else 0.0
            for i in range(3):
                c3[i] *= hh
            if use_moment:
                _cross3(rp3, m3, e3)
                for i in range(3):
                    c3[i] += e3[i]
            for k in range(4):
                for i in range(nd):
                    fe[off[k] + i] += wl * c3[slot3[i]] * dn[k]

        if want_dle:
            _dle_gauss_point(nd, le, ue, props, torque if use_torque else 0.0, wl, p0, p1, lam,
                             cval, de_deps, deps_dx, dqx_dx, has_drag, ws, wm, dfe)

        if not want_tangent:
            continue

        # --- tangent ------------------------------------------------------
        wei = wl * ei
        wlam = wl * lam
        for k in range(4):
            for l in range(k, 4):
                ka[4 * k + l] += wei * ddn[k] * ddn[l] + wlam * dn[k] * dn[l]
        if dqx_dx != 0.0:
            wq = wl * dqx_dx
            for k in range(4):
                for l in range(k, 4):
                    kx[4 * k + l] += wq * n[k] * n[l]
        if has_drag:
            # load stiffness: -N_k dq_i/du_(l,j)
            for k in range(4):
                for l in range(4):
                    for i in range(nd):
                        for j in range(nd):
                            ke[off[k] + i, off[l] + j] -= wl * n[k] * dq_drp[i, j] * dn[l]
                        ke[off[k] + i, off[l]] -= wl * n[k] * dq_dx[i] * n[l]
        for m in range(2):
            pm = p0 if m == 0 else p1
            lm = lam_idx[m]
            for k in range(4):
                for i in range(nd):
                    v = wl * pm * rp[i] * dn[k]
                    ke[off[k] + i, lm] += v
                    v2 = v
                    if extensible:
                        v2 -= wl * pm * de_deps * (2.0 * ei * rpp[i] / ea) * ddn[k]
                    ke[lm, off[k] + i] += v2
                if extensible:
                    ke[lm, off[k]] -= wl * pm * de_deps * deps_dx * n[k]
            if extensible:
                for mm in range(2):
                    pn = p0 if mm == 0 else p1
                    ke[lm, lam_idx[mm]] -= wl * pm * pn * de_deps / ea

        if use_torque or use_moment:
            hh = torque if use_torque else 0.0
            for l in range(4):
                for j in range(nd):
                    for i in range(3):
                        e3[i] = 0.0
                    e3[slot3[j]] = 1.0
                    # d(c3)/du_(l,j) = H [dN_l (e_j x r'') + ddN_l (r' x e_j)] + dN_l (e_j x m)
                    _cross3(e3, rpp3, c3)
                    d0 = hh * dn[l] * c3[0]
                    d1 = hh * dn[l] * c3[1]
                    d2 = hh * dn[l] * c3[2]
                    _cross3(rp3, e3, c3)
                    d0 += hh * ddn[l] * c3[0]
                    d1 += hh * ddn[l] * c3[1]
                    d2 += hh * ddn[l] * c3[2]
                    if use_moment:
                        _cross3(e3, m3, c3)
                        d0 += dn[l] * c3[0]
                        d1 += dn[l] * c3[1]
                        d2 += dn[l] * c3[2]
                    dv = (d0, d1, d2)
                    for k in range(4):
                        for i in range(nd):
                            ke[off[k] + i, off[l] + j] += wl * dn[k] * dv[slot3[i]]

    if (want_tangent or want_dle) and ncut > 1:
        _cut_jumps(nd, le, ue, model, ncut, cuts, cutlev, ke, want_tangent, dfe, want_dle, ws, wm)

    if want_tangent:
        for k in range(4):
            for l in range(4):
                kl = 4 * k + l if l >= k else 4 * l + k  # symmetric: the upper triangle
                for i in range(nd):
                    ke[off[k] + i, off[l] + i] += ka[kl]
                ke[off[k], off[l]] -= kx[kl]


@jit(by_dimension=True, _nrt=False)
def _cut_jumps(nd, le, ue, model, ncut, cuts, cutlev, ke, want_tangent, dfe, want_dle, ws, wm):
    """The movement of the cuts: the load q jumps at a crossed level (the
    weight at the water surface and the contents level, the drag at the water
    surface), and each cut xi_c, X(xi_c) = level with X the height x along the
    element, moves with the nodal x unknowns and with le. By Leibniz' rule
    dG_(k,i) = le (h_L - h_R)(xi_c) dxi_c, h = -q_i N_k the load's integrand,
    L and R the pieces below and above xi_c, with dxi_c/du_(l,x) = -N_l /
    (le x') and dxi_c/dle = -(N_1 x'_a + N_3 x'_b) / (le^2 x')."""
    ndn = 2 * nd + 1
    off = (0, nd, ndn, ndn + nd)
    props = model.props
    n = ws[_N:_N + 4]
    dn = ws[_DN:_DN + 4]
    ddn = ws[_DDN:_DDN + 4]
    rp = ws[_RP:_RP + nd]
    qd = ws[_QD:_QD + nd]
    dq_dx = ws[_DQ_DX:_DQ_DX + nd]
    jump = ws[_DQ:_DQ + nd]
    dq_drp = wm[:nd, :nd]
    dwork = ws[_DWORK:_DWORK + 15]
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
            jump[0] -= sgn * effective_weight(props, x_s)
            if drag_force(model, nd, x_s, rp, qd, dq_drp, dq_dx, dwork):
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
def _dle_gauss_point(nd, le, ue, props, torque, wl, p0, p1, lam, cval, de_deps, deps_dx,
                     dqx_dx, has_drag, ws, wm, dfe):
    """Add one Gauss point's share of dG/dle to ``dfe`` (module docstring).

    Reads the point's values that :func:`element_force_ws` left in ``ws`` and
    ``wm``; ``torque`` is 0 where the torque term is off. A function of its own,
    not inlined, so that the kernel's Gauss loop runs as fast without it.
    """
    ndn = 2 * nd + 1
    off = (0, nd, ndn, ndn + nd)
    slot3 = (0, 1 if nd == 3 else 2, 2)
    ei = props[L.EI]
    ea = props[L.EA]
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
    for i in range(nd):
        dq = dqx_dx * dx if i == 0 else 0.0
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


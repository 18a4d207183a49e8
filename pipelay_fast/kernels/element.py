"""Garrett's rod element: internal-minus-external force vector, its tangent, and
its derivative with respect to the element length.

Weak form over one element of unstretched length ``le`` (s the unstretched arc
length, ``d`` a virtual field, ``'`` = d/ds):

    G_r   = int [ EI r''.dr'' + lam r'.dr' + H (r' x r'').dr' + (r' x m).dr' - q.dr ] ds
    G_lam = int dlam [ (r'.r' - 1)/2 - e ] ds,   e = eps + eps^2/2,  eps = Tw/EA

so that |r'| = 1 + eps exactly, with Te = lam + EI kappa^2 (kappa^2 = r''.r''),
Tw = Te + pi Ai - pe Ae (inextensible: e = 0). r is cubic Hermite (nodal r, r'),
lam linear (nodal values), integrated by Gauss-Legendre in pieces split at
the water surface and the contents level (:mod:`.element_shapes`).

Loads q: effective weight -w(x) e_x, Morison drag on the normal current
(times the current factor), an elastic seabed -k x e_x where x < 0. The
torque and distributed-moment terms are evaluated only when they are
non-zero. The tangent is the exact derivative of G, the movement of the cuts
included (the load's jump there, :func:`.element_dle._cut_jumps`); dG/dle
is :mod:`.element_dle`'s.

The same code serves 2D (nd = 2: slots x, z) and 3D (nd = 3: x, y, z), so the
planar model is a reduction of the spatial one, not a second model.
"""

from __future__ import annotations

from . import layout as L
from ._jit import jit, phase
from .element_dle import _cut_jumps, _dle_gauss_point
from .element_shapes import (
    _C3,
    _CUTLEV,
    _CUTS,
    _E3,
    _KA,
    _KX,
    _M3,
    _Q,
    _R,
    _RP3,
    _RPP,
    _RPP3,
    GAUSS_W,
    GAUSS_XI,
    _cross3,
    _point_views,
    hermite,
    level_cuts,
)
from .loads import drag_force, effective_weight, foundation, wall_minus_effective


@jit(by_dimension=True, _nrt=False)
def element_force_ws(nd, le, ue, model, sec, torque, fe, ke, want_tangent, dfe, want_dle, ws,
                     wm):
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
        The scene's ``props`` (:mod:`.layout`), the current table
        ``[[x, speed], ...]`` and the load path's factors (``F_*``).
    sec : (N_SECTION,) float64
        This element's section (:mod:`.layout` ``S_*``: EI, EA, weights,
        steel areas, drag), its row of ``model.section``.
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
    props = model.props
    ei = sec[L.S_EI]
    ea = sec[L.S_EA]
    extensible = props[L.EXTENSIBLE] != 0.0
    k_bed = props[L.SEABED_K]
    use_torque = nd == 3 and torque != 0.0
    hh = torque if use_torque else 0.0
    mx = props[L.MOM_X]
    my = props[L.MOM_Y]
    mz = props[L.MOM_Z]
    use_moment = mx != 0.0 or my != 0.0 or mz != 0.0
    # the tangent's blocks that are the same for each component i (the
    # bending and lam terms, and the seabed's x-x stiffness), summed over the
    # Gauss points as 4 x 4 scalars and spread onto ke once, after the loop
    ka = ws[_KA:_KA + 16]
    kx = ws[_KX:_KX + 16]
    ne = 2 * ndn
    for a in range(ne):
        fe[a] = 0.0
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

    n, dn, ddn, rp, qd, dq_dx, dq_drp, dwork = _point_views(nd, ws, wm)
    r = ws[_R:_R + nd]
    rpp = ws[_RPP:_RPP + nd]
    q = ws[_Q:_Q + nd]
    # 3-vectors for the torque / moment terms (2D embeds y = 0)
    rp3 = ws[_RP3:_RP3 + 3]
    rpp3 = ws[_RPP3:_RPP3 + 3]
    m3 = ws[_M3:_M3 + 3]
    m3[0] = mx
    m3[1] = my
    m3[2] = mz
    c3 = ws[_C3:_C3 + 3]
    e3 = ws[_E3:_E3 + 3]
    slot3 = (0, 1 if nd == 3 else 2, 2)

    cuts = ws[_CUTS:_CUTS + 4]
    cutlev = ws[_CUTLEV:_CUTLEV + 4]
    ncut = level_cuts(props, le, ue[0], ue[nd], ue[ndn], ue[ndn + nd], cuts, cutlev)
    pt = (n, dn, ddn, r, rp, rpp, q, qd, dq_drp, dq_dx, dwork)
    idx = (off, lam_idx, slot3)
    moments = (rp3, rpp3, m3, c3, e3)
    use_moments = use_torque or use_moment
    for gg in range(4 * ncut):
        part = gg // 4
        g = gg % 4
        span = cuts[part + 1] - cuts[part]
        xi = cuts[part] + span * GAUSS_XI[g]
        wl = GAUSS_W[g] * span * le
        p0 = 1.0 - xi
        p1 = xi
        lam = p0 * ue[lam_idx[0]] + p1 * ue[lam_idx[1]]
        rp2, kap2, dq_bed, has_drag = _point_values(nd, le, ue, xi, model, sec, k_bed, pt)
        e, de_deps, deps_dx = _extension(props, sec, extensible, ei, ea, r[0], lam, kap2)
        cval = _point_residual(nd, idx, wl, ei, lam, rp2, e, p0, p1, pt, hh, use_moments,
                               use_moment, moments, fe)
        if want_dle:
            _dle_gauss_point(nd, le, ue, props, sec, hh, wl, p0, p1, lam, cval, de_deps, deps_dx,
                             dq_bed, has_drag, ws, wm, dfe)
        if want_tangent:
            _point_tangent(nd, idx, wl, ei, ea, lam, extensible, de_deps, deps_dx, dq_bed,
                           has_drag, p0, p1, pt, ka, kx, hh, use_moments, use_moment, moments, ke)

    if (want_tangent or want_dle) and ncut > 1:
        _cut_jumps(nd, le, ue, model, sec, ncut, cuts, cutlev, ke, want_tangent, dfe, want_dle,
                   ws, wm)

    if want_tangent:
        for k in range(4):
            for l in range(4):
                kl = 4 * k + l if l >= k else 4 * l + k  # symmetric: the upper triangle
                for i in range(nd):
                    ke[off[k] + i, off[l] + i] += ka[kl]
                ke[off[k], off[l]] -= kx[kl]


@phase
def _point_values(nd, le, ue, xi, model, sec, k_bed, pt):
    """A Gauss point's values at ``xi`` into the views ``pt``: the shape
    functions, r, r', r'', the distributed load q [N/m] (the effective
    weight, the elastic seabed, :func:`.loads.foundation`; the drag, its derivatives,
    :func:`.loads.drag_force`; ``sec`` the element's section row). Returns
    (r'.r', kappa^2 = r''.r'' [1/m2], the seabed's (dq_x/dx, dq_x/dz,
    dq_z/dx, dq_z/dz) [N/m2], whether drag acts)."""
    n, dn, ddn, r, rp, rpp, q, qd, dq_drp, dq_dx, dwork = pt
    ndn = 2 * nd + 1
    props = model.props
    hermite(xi, le, n, dn, ddn)
    # r' and r'' from the chord r_b - r_a (their shape functions of r_a and
    # r_b are opposite), which keeps round-off relative to the element size
    # rather than to the distance from the origin
    for i in range(nd):
        ra = ue[i]
        chord = ue[ndn + i] - ra
        r[i] = ra + n[1] * ue[nd + i] + n[2] * chord + n[3] * ue[ndn + nd + i]
        rp[i] = dn[1] * ue[nd + i] + dn[2] * chord + dn[3] * ue[ndn + nd + i]
        rpp[i] = ddn[1] * ue[nd + i] + ddn[2] * chord + ddn[3] * ue[ndn + nd + i]
    rp2 = 0.0
    kap2 = 0.0
    for i in range(nd):
        rp2 += rp[i] * rp[i]
        kap2 += rpp[i] * rpp[i]
    x = r[0]
    for i in range(nd):
        q[i] = 0.0
    q[0] = -effective_weight(props, sec, x)
    fx, fz, dqx_dx, dqx_dz, dqz_dx, dqz_dz = foundation(props, model.bed, k_bed, x, r[nd - 1])
    if dqx_dx != 0.0:
        q[0] += fx
        q[nd - 1] += fz
    has_drag = drag_force(model, sec, nd, x, rp, qd, dq_drp, dq_dx, dwork)
    if has_drag:
        for i in range(nd):
            q[i] += qd[i]
    return rp2, kap2, (dqx_dx, dqx_dz, dqz_dx, dqz_dz), has_drag


@phase
def _extension(props, sec, extensible, ei, ea, x, lam, kap2):
    """The extensible rod's strain term at height ``x`` [m]: (e = eps +
    eps^2 / 2 with eps = Tw / EA, de/deps, deps/dx [1/m]); zeros when
    inextensible. ``lam`` [N], ``kap2`` [1/m2]."""
    e = 0.0
    de_deps = 0.0
    deps_dx = 0.0
    if extensible:
        dtw, ddtw_dx = wall_minus_effective(props, sec, x)
        eps = (lam + ei * kap2 + dtw) / ea
        e = eps + 0.5 * eps * eps
        de_deps = 1.0 + eps
        deps_dx = ddtw_dx / ea
    return e, de_deps, deps_dx


@phase
def _point_residual(nd, idx, wl, ei, lam, rp2, e, p0, p1, pt, hh, use_moments, use_moment,
                    moments, fe):
    """A Gauss point's share (weight ``wl`` [m]) of G, ``p0``, ``p1`` the
    multiplier's shape functions. With ``use_moments``, the torque's (``hh``
    [N m]) and the distributed moment's (``m3`` [N m/m]) terms: c3 = H (r' x
    r'') + r' x m acts on dr' (r', r'' as 3-vectors into ``rp3``, ``rpp3``,
    c3 into ``c3``). Returns the constraint's value (r'.r' - 1) / 2 - e."""
    off, lam_idx, slot3 = idx
    n, dn, ddn, _r, rp, rpp, q = pt[0], pt[1], pt[2], pt[3], pt[4], pt[5], pt[6]
    rp3, rpp3, m3, c3, e3 = moments
    for k in range(4):
        for i in range(nd):
            fe[off[k] + i] += wl * (ei * rpp[i] * ddn[k] + lam * rp[i] * dn[k] - q[i] * n[k])
    cval = 0.5 * (rp2 - 1.0) - e
    fe[lam_idx[0]] += wl * p0 * cval
    fe[lam_idx[1]] += wl * p1 * cval
    if use_moments:
        for i in range(3):
            rp3[i] = 0.0
            rpp3[i] = 0.0
        for i in range(nd):
            rp3[slot3[i]] = rp[i]
            rpp3[slot3[i]] = rpp[i]
        _cross3(rp3, rpp3, c3)
        for i in range(3):
            c3[i] *= hh
        if use_moment:
            _cross3(rp3, m3, e3)
            for i in range(3):
                c3[i] += e3[i]
        for k in range(4):
            for i in range(nd):
                fe[off[k] + i] += wl * c3[slot3[i]] * dn[k]
    return cval


@phase
def _point_tangent(nd, idx, wl, ei, ea, lam, extensible, de_deps, deps_dx, dq_bed, has_drag, p0,
                   p1, pt, ka, kx, hh, use_moments, use_moment, moments, ke):
    """A Gauss point's share of the tangent: the bending and lam blocks and
    the seabed's x-x stiffness into the 4 x 4 sums ``ka``, ``kx`` (upper
    triangles), the seabed's other terms (``dq_bed`` = (dq_x/dx, dq_x/dz,
    dq_z/dx, dq_z/dz) [N/m2]: the profile's slope, a sloped plane's
    normal), the drag's load stiffness, the
    multipliers' rows and columns and, with ``use_moments``, the torque's
    and the moment's terms into ``ke`` (:func:`_point_residual`'s ``rp3``,
    ``rpp3``; ``c3``, ``e3`` scratch)."""
    off, lam_idx, slot3 = idx
    n, dn, ddn, rp, rpp = pt[0], pt[1], pt[2], pt[4], pt[5]
    dq_drp, dq_dx = pt[8], pt[9]
    rp3, rpp3, m3, c3, e3 = moments
    wei = wl * ei
    wlam = wl * lam
    dqx_dx, dqx_dz, dqz_dx, dqz_dz = dq_bed
    for k in range(4):
        for l in range(k, 4):
            ka[4 * k + l] += wei * ddn[k] * ddn[l] + wlam * dn[k] * dn[l]
    if dqx_dz != 0.0:  # -N_k dq_x/dz N_l
        for k in range(4):
            for l in range(4):
                ke[off[k], off[l] + nd - 1] -= wl * dqx_dz * n[k] * n[l]
    if dqz_dx != 0.0:  # a sloped plane's normal: -N_k dq_z/du_l N_l
        for k in range(4):
            for l in range(4):
                ke[off[k] + nd - 1, off[l]] -= wl * dqz_dx * n[k] * n[l]
                ke[off[k] + nd - 1, off[l] + nd - 1] -= wl * dqz_dz * n[k] * n[l]
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
    if not use_moments:
        return
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

"""The system the Newton kernel solves: the residual G and its tangent K
(band storage), in the nodal frames, with the rows and columns of the
bordered unknowns.

G is the elements' internal-minus-external forces (:mod:`.assembly`) with
the nodal loads, the load path's offset, the bottom tension on the sliding
lower end and the seabed's friction springs (forces in G and K, not
constraints). Its rows are forces [N] at the positions, moments [N m] at
the slopes and lengths [m] at the multipliers.

Nodal frames: a node with frame angles ``sup.phi_r``, ``sup.phi_rp`` has
its rows and columns of r and r' turned into them (a rigid point's node into
the pipe's normal and tangent, whose turn with r' enters K,
:func:`_frame_turn`). Stinger contacts are in curve coordinates instead
(:func:`.assembly.curve_node`): x = f(z) + c, x' = f'(z) z' + c', c = 0 and
c' = 0 held, z and z' sliding along the curve; the map's second
derivatives, weighted by the residual (the support's reaction), enter the
tangent, so a node that slides along the stinger keeps Newton quadratic
and the constraints hold exactly after every step.

Bordered unknowns (:func:`_border`): the bottom tension T_b when the top
tension is given, its equation Te(top) = R_top . t_top - T_top = 0 (the
reaction at the pinned top is the internal force there), its row and column
local to the two ends; and each contact boundary's arc length s_b, its
column dG/ds_b the elements' analytic dG/dle times the length rates
(:func:`.assembly.assemble`) plus the friction springs' anchor derivative
(anchors belong to material points, :func:`.contact.anchor_at`), its row its
equation's gradient (:mod:`.constraints`).
"""

from __future__ import annotations

import math

import numpy as np

from . import layout as L
from ._jit import jit, phase
from .assembly import assemble, curve_node, distribute_torque, element_work, rotate_node
from .constraints import _bnd_equation, _free_moment
from .contact import friction_forces, friction_length_derivative, node_arcs
from .layout import B_LO, B_TD, ROW_BED, SUP_POINT
from .scene import FRICTION, STINGER
from .supports import in_curve_coords, support_height
from .tuning import EPS


@jit(by_dimension=True, _nrt=False)
def _system(nd, s_el, u, model, torques, ab, kl, ku, g, ends, want_tangent, s_b, bnodes, bcols,
            ew, row_td, own_td, phi_td):
    """Residual (+ tangent, global frame, and the boundaries' columns dG/ds_b
    of the elements, :func:`.assembly.assemble`) with the nodal loads, the
    load path's offset and the bottom tension on the sliding lower end
    (along the seabed: in its frame, the lower end's, the tension's row is
    the slide's, :func:`_border`); returns touchdown's equation [N m] when
    touchdown is an unknown (``bnodes[B_TD] >= 0``, else 0), its gradients
    in ``row_td`` and ``own_td`` (:func:`.constraints._free_moment`, its
    frame turned by ``phi_td`` [rad]; ``row_td`` of size 0: the equation
    alone). ``ew``: the element's scratch (:func:`.assembly.element_work`).

    The one kernel between the element kernel and the Newton kernel's
    phases: each compiled function up the element's call chain optimises
    and compiles the element's machine code again in its own module
    (``benchmarks/bench_compile.py``)."""
    props = model.props
    if props[L.MOM_X] != 0.0 or props[L.MOM_Y] != 0.0 or props[L.MOM_Z] != 0.0:
        distribute_torque(nd, s_el, u, props, torques)
    assemble(nd, s_el, u, model, torques, ab, kl, ku, g, want_tangent, s_b, bnodes, bcols, ew)
    n = g.shape[0]
    for i in range(n):
        g[i] += ends.g_off[i] - ends.f_node[i]
    if ends.slide_dof >= 0:  # along the seabed, at ends.slide_angle above horizontal
        g[ends.slide_dof] += ends.tb[0] * math.cos(ends.slide_angle)
        g[ends.slide_dof - nd + 1] += ends.tb[0] * math.sin(ends.slide_angle)
    if bnodes[B_TD] < 0:
        return 0.0
    return _free_moment(nd, s_el, u, model, torques, bnodes[B_TD], s_b, row_td, own_td, phi_td,
                        ew)


@jit(entry=True, _nrt=True)
def system_2d(s_el, u, model, torques, ab, g, ends, want_tangent, s_b, bnodes, bcols):
    """:func:`_system` in the plane, from Python (kl = ku = 9)."""
    _system(2, s_el, u, model, torques, ab, 9, 9, g, ends, want_tangent, s_b, bnodes, bcols,
            element_work(2), np.zeros(0), np.zeros(0), 0.0)


@jit(entry=True, _nrt=True)
def system_3d(s_el, u, model, torques, ab, g, ends, want_tangent, s_b, bnodes, bcols):
    """:func:`_system` in space, from Python (kl = ku = 13)."""
    _system(3, s_el, u, model, torques, ab, 13, 13, g, ends, want_tangent, s_b, bnodes, bcols,
            element_work(3), np.zeros(0), np.zeros(0), 0.0)


@phase
def _evaluate(nd, u, mesh, model, sup, ends, w, g, want_tangent):
    """Every term that needs the element kernel: the residual ``g``
    (global frame) with the friction springs and, with ``want_tangent``, the
    tangent ``w.ab``, the top tension's row ``w.d``, each boundary's column
    dG/ds_b (``w.bcols``, with its top-tension rate ``w.d_top``) and
    touchdown's row (``w.row_td``, ``w.own_td``). The line search calls it
    for its trial states without the tangent.

    (The one phase that calls the element kernel's caller, :func:`_system`:
    numba optimises each kernel with all its callees linked in, so a kernel
    of its own above the element's would add the element's compile time
    again. The phases are inlined into the Newton kernel
    (:func:`.newton._newton_kernel`, :func:`._jit.phase`), and this keeps
    the element's caller in one place.)

    Returns (the top's effective tension [N], touchdown's equation [N m])."""
    ndn = 2 * nd + 1
    kl = 2 * ndn - 1
    bnodes = mesh.bnodes
    ab = w.ab if want_tangent else w.no_ab
    td = bnodes[B_TD]
    m_td = _system(nd, mesh.s_el, u, model, w.torques, ab, kl, kl, g, ends, want_tangent,
                   mesh.s_b, bnodes, w.bcols, w.ew,
                   w.row_td if want_tangent else w.no_row, w.own_td,
                   sup.phi_rp[td] if td >= 0 else 0.0)
    node_arcs(mesh.s_el, w.s_nd)
    if FRICTION:
        friction_forces(nd, u, g, ab, 2 * kl if want_tangent else 0, model,
                        sup.active[ROW_BED], sup.fric, w.fr_out, w.s_nd, False)
    te_top = 0.0
    if _solves_tb(ends):
        if want_tangent:
            te_top = _top_tension_row(nd, w.ab, kl, kl, g, u, ends.top_node, w.d)
        else:
            te_top = _top_te(nd, g, u, ends.top_node)
    if want_tangent:
        for b in range(bnodes.shape[0]):
            if bnodes[b] >= 0:
                if FRICTION:  # the springs' anchors are read at material points,
                    # which move with the boundary too (:func:`.contact.anchor_at`)
                    friction_length_derivative(nd, u, g, model, sup.active[ROW_BED], sup.fric,
                                               w.s_nd, mesh.s_b[b], w.bcols[b])
                w.d_top[b] = _top_te(nd, w.bcols[b], u, ends.top_node)
    return te_top, m_td


@phase
def _solves_tb(ends):
    """True when the bottom tension is an unknown (the top tension given)."""
    return ends.top_target > 0.0 and ends.slide_dof >= 0


@jit(_nrt=False)
def _top_te(nd, g, u, top_node):
    """Effective tension at the top: the top reaction (= G there) along the tangent."""
    ndn = 2 * nd + 1
    base = top_node * ndn
    a = 0.0
    te = 0.0
    for i in range(nd):
        a += u[base + nd + i] ** 2
        te += g[base + i] * u[base + nd + i]
    return te / math.sqrt(a)


@jit(_nrt=False)
def _top_tension_row(nd, ab, kl, ku, g, u, top_node, d):
    """Te at the top = G_top . t and its derivative row ``d`` (global frame)."""
    ndn = 2 * nd + 1
    kv = kl + ku
    n = g.shape[0]
    base = top_node * ndn
    a = 0.0
    for i in range(nd):
        a += u[base + nd + i] ** 2
    a = math.sqrt(a)
    te = _top_te(nd, g, u, top_node)
    d[:] = 0.0
    for i in range(nd):
        row = base + i
        ti = u[base + nd + i] / a
        for j in range(max(0, row - kl), min(n - 1, row + ku) + 1):
            d[j] += ti * ab[kv + row - j, j]
    # d(t)/d(r') = (I - t t^T) / a
    for j in range(nd):
        tj = u[base + nd + j] / a
        acc = 0.0
        for i in range(nd):
            ti = u[base + nd + i] / a
            acc += g[base + i] * ((1.0 if i == j else 0.0) - ti * tj) / a
        d[base + nd + j] += acc
    return te


@phase
def _to_nodal_system(nd, u, mesh, sup, ends, w, te_top, m_td):
    """The linear system in the nodal frames (stinger contacts in curve
    coordinates) and the bordered unknowns (:func:`_border`), touchdown's
    equation ``m_td`` [N m] into ``w.res_bnd``.
    Returns (the border unknowns, those of them other than the boundaries)."""
    kl = 4 * nd + 1
    _rotate_all(nd, w.ab, kl, kl, w.g, sup.phi_r, sup.phi_rp, True)
    if STINGER:  # the frames over the rigid points, the curve's contacts
        _frame_turn(nd, w.ab, kl, w.g, u, mesh, sup)
        _curve_all(nd, w.ab, kl, kl, w.g, u, sup, True)
    w.res_bnd[0] = m_td
    return _border(nd, u, mesh, sup, ends, w, te_top)


@phase
def _to_nodal_residual(nd, u, mesh, sup, w, m_td):
    """:func:`_to_nodal_system` without the tangent: the residual in the nodal frames and the
    boundaries' equations (:func:`_border`'s residuals), for an iteration
    that only tests convergence."""
    _to_nodal_frames(nd, w.g, u, sup, w)
    w.res_bnd[0] = m_td
    if STINGER:  # the boundaries above touchdown
        for b in range(B_LO, mesh.bnodes.shape[0]):
            if mesh.bnodes[b] >= 0:
                w.res_bnd[b] = _bnd_equation(nd, u, sup, b, mesh.bnodes[b], w.no_row)


@jit(_nrt=False)
def _to_nodal_frames(nd, v, u, sup, w):
    """A global-frame row or column into the nodal frames and curve
    coordinates. (A kernel: it has five callers.)"""
    kl = 4 * nd + 1
    _rotate_all(nd, w.no_ab, kl, kl, v, sup.phi_r, sup.phi_rp, False)
    if STINGER:
        _curve_all(nd, w.no_ab, kl, kl, v, u, sup, False)


@jit(_nrt=False)
def _from_nodal_frames(nd, v, u, sup):
    """The inverse of :func:`_to_nodal_frames` for a residual: ``v``, whose
    rows are in the nodal frames and curve coordinates (J^T g, J the map's
    derivative, :func:`.assembly.curve_node`), back to the global frame,
    g = J^-T v: the curves' maps undone in reverse order, then the frames'
    rotations (orthogonal: their inverse is their transpose, :func:`_to_global`)."""
    ndn = 2 * nd + 1
    for k in range(sup.kind.shape[0] - 1, -1, -1):
        kind = sup.kind[k]
        if not STINGER or not in_curve_coords(kind):
            continue
        for node in range(sup.active.shape[1]):
            if sup.active[k, node] != 0:
                base = node * ndn
                _f, fp, fpp = support_height(kind, sup.geom[k], u[base + nd - 1])
                # curve_node: v_z = g_z + f' g_x + f'' z' g_x', v_z' = g_z' + f' g_x'
                v[base + nd - 1] -= fp * v[base] + fpp * u[base + 2 * nd - 1] * v[base + nd]
                v[base + 2 * nd - 1] -= fp * v[base + nd]
    _to_global(nd, v, sup.phi_r, sup.phi_rp)


@jit(_nrt=False)
def _rotate_all(nd, ab, kl, ku, g, phi_r, phi_rp, want_tangent):
    """Turn every node with a frame (angles ``phi_r``, ``phi_rp`` [rad]) into
    it (:func:`.assembly.rotate_node`): the rows of ``g`` and, with
    ``want_tangent``, the rows and columns of the band ``ab``."""
    ndn = 2 * nd + 1
    for node in range(phi_r.shape[0]):
        if phi_r[node] != 0.0 or phi_rp[node] != 0.0:
            if not want_tangent and _zero_at(g, node * ndn, 2 * nd):
                continue  # (a row or column zero there stays zero: a point's is local)
            rotate_node(nd, ab, kl, ku, g, node, phi_r[node], phi_rp[node], want_tangent)


@jit(_nrt=False)
def _zero_at(v, start, count):
    """True when v[start:start + count] is all zero."""
    for i in range(start, start + count):
        if v[i] != 0.0:
            return False
    return True


@jit(_nrt=False)
def _curve_all(nd, ab, kl, ku, g, u, sup, want_tangent):
    """Express the contact nodes of every support held in curve coordinates
    in them (:func:`.supports.in_curve_coords`, :func:`.assembly.curve_node`)."""
    ndn = 2 * nd + 1
    for k in range(sup.kind.shape[0]):
        kind = sup.kind[k]
        if not in_curve_coords(kind):
            continue
        for node in range(sup.active.shape[1]):
            if sup.active[k, node] != 0:
                base = node * ndn
                if not want_tangent and _zero_at(g, base, 2 * nd):
                    continue
                _f, fp, fpp = support_height(kind, sup.geom[k], u[base + nd - 1])
                curve_node(nd, ab, kl, ku, g, node, fp, fpp, u[base + 2 * nd - 1],
                           want_tangent)


@jit(_nrt=False)
def _frame_turn(nd, ab, kl, g, u, mesh, sup):
    """The frame over a rigid point is the pipe's, phi = atan2(x', z')
    (:func:`.constraints._nodal_frames`), and turns with r': its rows (normal n . G,
    tangent t . G, ``g`` already in that frame) carry d/dphi = (-G_t, G_n)
    times dphi/dr' (the normal's reaction G_n turns into the tangent's row)."""
    ndn = 2 * nd + 1
    kv = 2 * kl
    for b in range(mesh.bnodes.shape[0]):
        kt = mesh.bnodes[b]
        if kt < 0 or sup.kind[b] != SUP_POINT:
            continue
        base = kt * ndn
        xp = u[base + nd]
        zp = u[base + 2 * nd - 1]
        a2 = xp * xp + zp * zp
        dx = zp / a2  # dphi/dx'
        dz = -xp / a2  # dphi/dz'
        phi = sup.phi_rp[kt]  # r' in its own frame: x' = c v_p + s v_q, z' = -s v_p + c v_q
        c = math.cos(phi)
        s = math.sin(phi)
        p2 = base + nd
        q2 = base + 2 * nd - 1
        d_p = c * dx - s * dz
        d_q = s * dx + c * dz
        p = base
        q = base + nd - 1
        g_n = g[p]
        g_t = g[q]
        ab[kv + q - p2, p2] += g_n * d_p
        ab[kv + q - q2, q2] += g_n * d_q
        ab[kv + p - p2, p2] -= g_t * d_p
        ab[kv + p - q2, q2] -= g_t * d_q


@jit(by_dimension=True, _nrt=False)
def _border(nd, u, mesh, sup, ends, w, te_top):
    """The bordered unknowns' rows (their equations' gradients),
    columns (dG/dz) and residuals: the bottom tension (its equation the top
    tension) and each boundary (its continuum condition). Returns (nb, the
    count of border unknowns other than the boundaries)."""
    nb = 0
    w.d_b[:, :] = 0.0
    if _solves_tb(ends):
        _to_nodal_frames(nd, w.d, u, sup, w)
        for i in range(w.d.shape[0]):  # (element by element: an array
            w.rows[nb, i] = w.d[i]      # assignment compiles numba's shape check)
        w.cols[nb, :] = 0.0
        w.cols[nb, ends.slide_dof] = 1.0
        w.res_b[nb] = te_top - ends.top_target
        w.kind[nb] = 0
        nb += 1
    nb_fixed = nb
    for b in range(mesh.bnodes.shape[0]):
        node = mesh.bnodes[b]
        if node < 0:
            continue
        for i in range(w.cols.shape[1]):
            w.cols[nb, i] = w.bcols[b, i]
        d_own = 0.0
        if b == B_TD:  # (evaluated by _evaluate)
            for i in range(w.rows.shape[1]):
                w.rows[nb, i] = w.row_td[i]
            d_own = w.own_td[B_TD]
        elif STINGER:  # (the boundaries above touchdown)
            w.res_bnd[b] = _bnd_equation(nd, u, sup, b, node, w.rows[nb])
        _to_nodal_frames(nd, w.cols[nb], u, sup, w)
        _to_nodal_frames(nd, w.rows[nb], u, sup, w)
        w.res_b[nb] = w.res_bnd[b]
        # the earlier border equations by s_b at fixed u: the top tension,
        # touchdown's moment (its element's length moves with s_b)
        for j in range(nb):
            if w.kind[j] == 0:
                w.d_b[j, nb] = w.d_top[b]
            elif w.kind[j] == 2 + B_TD:
                w.d_b[j, nb] = w.own_td[b]
        w.d_b[nb, nb] = d_own
        w.kind[nb] = 2 + b
        nb += 1
    return nb, nb_fixed


@phase
def _border_residuals(mesh, ends, w, te_top):
    """:func:`_border`'s residuals ``w.res_b`` and unknowns ``w.kind`` alone, in
    its order (the top tension's equation, then each boundary's, from
    ``w.res_bnd`` as :func:`_to_nodal_residual` leaves it), without its rows
    and columns. Returns their count."""
    nb = 0
    if _solves_tb(ends):
        w.res_b[nb] = te_top - ends.top_target
        w.kind[nb] = 0
        nb += 1
    for b in range(mesh.bnodes.shape[0]):
        if mesh.bnodes[b] >= 0:
            w.res_b[nb] = w.res_bnd[b]
            w.kind[nb] = 2 + b
            nb += 1
    return nb


@jit(_nrt=False)
def _to_global(nd, du_local, phi_r, phi_rp):
    """Rotate an increment from the nodal frames back to the global frame."""
    ndn = 2 * nd + 1
    for node in range(phi_r.shape[0]):
        for blk in range(2):
            phi = phi_r[node] if blk == 0 else phi_rp[node]
            if phi == 0.0:
                continue
            p = node * ndn + blk * nd
            q = p + nd - 1
            c = math.cos(phi)
            s = math.sin(phi)
            a = du_local[p]
            b = du_local[q]
            # inverse of R = [[c, -s], [s, c]] is R^T
            du_local[p] = c * a + s * b
            du_local[q] = -s * a + c * b


@jit(_nrt=False)
def _weighted_max(nd, g, cmask, fref, href):
    """The free rows of ``g`` (``cmask`` False) weighted: forces by ``fref``
    [N], moments by ``fref href`` [N m], lengths by ``href`` [m]. Returns
    (their largest magnitude, their sum of squares)."""
    ndn = 2 * nd + 1
    worst = 0.0
    ssq = 0.0
    for i in range(g.shape[0]):
        if cmask[i]:
            continue
        slot = i % ndn
        if slot < nd:
            v = g[i] / fref
        elif slot < 2 * nd:
            v = g[i] / (fref * href)
        else:
            v = g[i] / href
        v = abs(v)
        ssq += v * v
        if v > worst:
            worst = v
    return worst, ssq


@phase
def _roundoff_ratio(nd, u, ab, g, cmask):
    """How far the free rows' residual ``g`` (``cmask`` False) is above its
    round-off floor: the largest |G_i| / (eps sum_j |K_ij| |u_j|) (``ab``: the
    tangent, nodal frames, before scaling). The sum is what perturbing each unknown by its
    own round-off, eps |u_j|, changes G_i by: a residual within a small
    multiple of it is as small as a state held in float64 can make it (it
    grows like EI |r| eps / h^3: fine meshes far from the origin)."""
    kl = 4 * nd + 1
    kv = 2 * kl
    n = u.shape[0]
    worst = 0.0
    for i in range(n):
        if cmask[i] or g[i] == 0.0:
            continue
        acc = 0.0
        for j in range(max(0, i - kl), min(n - 1, i + kl) + 1):
            acc += abs(ab[kv + i - j, j] * u[j])
        ratio = abs(g[i]) / (EPS * acc) if acc > 0.0 else np.inf
        if ratio > worst:
            worst = ratio
    return worst

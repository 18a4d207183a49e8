"""Constraints of the Newton kernel: the nodal frames, the constraint set,
the contact boundaries' equations, the rigid points' complementarity, and
the mesh and the pipe's state along the moving boundaries.

The constraint set is a set of nodal unknowns prescribed in their nodal
frames (:func:`_constraint_set`): the held ends, the seabed contacts (on it
and tangent to it), the stinger contacts (on its curve and tangent to it,
in curve coordinates), the lateral hold, the node over each rigid point that
bears. Which nodes are in contact follows from the contact boundaries.

Contact boundaries as unknowns (``mesh.bnodes[b] >= 0``, :mod:`.layout`
``B_*``). The mesh follows each boundary b: node i at s_i = s_a[i] + sum_b
s_b[b, i] s_bd[b] (:func:`mesh_lengths`), so the contact stretches are
fixed sets of nodes (the seabed from the lower end to touchdown, the stinger
from lift-off to the top) and no node walks on or off a contact. Each arc
length s_bd[b] is a bordered unknown of Newton closed by its continuum
condition:

* touchdown: on the seabed, tangent to it, no moment on the free side (the
  free element's nodal residual at the slope unknown, :func:`_free_moment`);
* lift-off (or re-contact above a bearing tip): on the stinger, its node's
  slope free and the pipe tangent to the stinger there
  (:func:`.supports.tangency`), which leaves its curvature continuous;
* a rigid point (the quadratic stinger's tip, or each roller of a roller
  stinger): a node follows the material point over the point, t . (r -
  r_p) = 0 (:func:`_over_point`), and its normal contact is chosen by the
  complementarity min(R, c g) = 0, solved semismoothly (the branch the
  present reaction R and gap g select, each iteration,
  :func:`_points_update`). This is point-against-element contact with the
  element's end put on the contact point: the pipe's moment, which kinks
  under a point load, kinks at a node, where the cubic elements represent
  it, and the gap and its multiplier are the node's.
"""

from __future__ import annotations

import math

import numpy as np

from . import layout as L
from ._jit import jit, phase
from .assembly import element_forces
from .element_shapes import WORK_SIZE, hermite
from .layout import B_LO, B_TD, SUP_POINT, SUP_SEABED
from .supports import (
    frame_angle,
    in_curve_coords,
    normal_offset,
    support_gap,
    support_height,
    tangency,
)


@jit(by_dimension=True, _nrt=False)
def _nodal_frames(nd, u, mesh, sup, ends):
    """The nodal frames of the iteration: none on the contacts of a support
    held in curve coordinates (with one, every node's frame but the top's is
    cleared: :func:`.condensation._curve_reactions` left its contacts' there),
    the sloped seabed's on its contacts and the lower end
    (:func:`.supports.frame_angle`) and, over each rigid point, the pipe's
    (normal, tangent)."""
    ndn = 2 * nd + 1
    nn = sup.phi_r.shape[0]
    curved = False
    for k in range(sup.kind.shape[0]):
        curved = curved or in_curve_coords(sup.kind[k])
    if curved:
        for node in range(1, nn):
            if node != ends.top_node:
                sup.phi_r[node] = 0.0
                sup.phi_rp[node] = 0.0
    for k in range(sup.kind.shape[0]):
        angle = frame_angle(sup.kind[k], sup.geom[k])
        if angle != 0.0:  # its contacts and the lower end resting on it
            for node in range(nn):
                if node != ends.top_node and (node == 0 or sup.active[k, node] != 0):
                    sup.phi_r[node] = angle
                    sup.phi_rp[node] = angle
    for b in range(mesh.bnodes.shape[0]):
        kt = mesh.bnodes[b]
        if kt >= 0 and sup.kind[b] == SUP_POINT:
            base = kt * ndn
            sup.phi_r[kt] = math.atan2(u[base + nd], u[base + 2 * nd - 1])


@jit(_nrt=False)
def _local_value(nd, u, node, slot, phi_r, phi_rp):
    """Unknown ``slot`` of ``node`` in the node's rotated frame."""
    ndn = 2 * nd + 1
    base = node * ndn
    if slot == 2 * nd:
        return u[base + slot]
    blk = 0 if slot < nd else 1
    p = base + blk * nd
    q = p + nd - 1
    phi = phi_r[node] if blk == 0 else phi_rp[node]
    k = slot - blk * nd
    if phi == 0.0 or (k != 0 and k != nd - 1):
        return u[base + slot]
    c = math.cos(phi)
    s = math.sin(phi)
    if k == 0:
        return c * u[p] - s * u[q]
    return s * u[p] + c * u[q]


@jit(by_dimension=True, _nrt=False)
def _constraint_set(nd, u, mesh, sup, ends, w, href):
    """The constrained unknowns (``w.cmask``) and their prescribed
    increments (``w.delta``, nodal frames): fixed ends, the seabed contacts
    (on it and tangent), the stinger contacts (on the curve and tangent, but
    lift-off's slope, which its equation closes), the lateral hold, the node
    over each rigid point that bears. Returns the largest violation
    (positions in units of ``href`` [m], slopes [-])."""
    ndn = 2 * nd + 1
    nn = sup.phi_r.shape[0]
    n = u.shape[0]
    fix_mask = sup.fix_mask
    for i in range(n):
        w.cmask[i] = fix_mask[i] != 0
        w.delta[i] = 0.0
    for node in range(nn):
        base = node * ndn
        for slot in range(ndn):
            i = base + slot
            if fix_mask[i] != 0:
                w.delta[i] = sup.fix_val[i] - _local_value(nd, u, node, slot, sup.phi_r,
                                                           sup.phi_rp)
        if sup.y_held[node]:  # on the stinger's plane and tangent to it
            w.cmask[base + 1] = True
            w.delta[base + 1] = -u[base + 1]
            w.cmask[base + nd + 1] = True
            w.delta[base + nd + 1] = -u[base + nd + 1]
    for k in range(sup.kind.shape[0]):
        if sup.kind[k] == SUP_SEABED or in_curve_coords(sup.kind[k]):
            _hold_on_line(nd, u, sup, k, ends.top_node, w)
    for b in range(mesh.bnodes.shape[0]):
        kt = mesh.bnodes[b]
        if kt >= 0 and sup.kind[b] == SUP_POINT and sup.geom[b, L.PT_BEAR] != 0.0:
            # bearing on a point: the node on it along the pipe's normal
            w.cmask[kt * ndn] = True
            w.delta[kt * ndn] = -_point_gap(nd, u, sup.geom[b], kt, sup.phi_r[kt])
            if nd == 3 and sup.geom[b, L.PT_HOLD] != 0.0:  # a V roller: laterally too
                w.cmask[kt * ndn + 1] = True
                w.delta[kt * ndn + 1] = -u[kt * ndn + 1]
    max_delta = 0.0
    for i in range(n):
        lim = href if i % ndn < nd else 1.0
        if w.cmask[i] and abs(w.delta[i]) / lim > max_delta:
            max_delta = abs(w.delta[i]) / lim
    return max_delta


@jit(_nrt=False)
def _hold_on_line(nd, u, sup, k, top_node, w):
    """The nodes line support ``k`` holds, held on it (``w.cmask``,
    ``w.delta``, as :func:`_constraint_set`; the prescribed ends' unknowns
    left as they are). The seabed, in the node's frame (its own, turned by
    its angle): on it at its contacts, and tangent to it at every contact
    node, touchdown's included, and at the lower end (resting on a rigid
    seabed, or on an elastic one's foundation). A support in curve
    coordinates: on it (c = 0) and tangent to it (c' = 0) at its contacts,
    but at the lowest, the contact node with free pipe below it (lift-off),
    whose tangency is lift-off's equation;
    the held top excepted. One call per support, not per node: the
    constraint set is built every iteration."""
    kind = sup.kind[k]
    ndn = 2 * nd + 1
    fix_mask = sup.fix_mask
    for node in range(sup.active.shape[1]):
        base = node * ndn
        on = sup.active[k, node] != 0
        if kind == SUP_SEABED:  # in its frame: slot x its normal, slot z its tangent
            if on and fix_mask[base] == 0:
                w.cmask[base] = True
                w.delta[base] = -(_local_value(nd, u, node, 0, sup.phi_r, sup.phi_rp)
                                  - normal_offset(kind, sup.geom[k]))
            if (on or node == 0) and fix_mask[base + nd] == 0:
                w.cmask[base + nd] = True
                w.delta[base + nd] = -_local_value(nd, u, node, nd, sup.phi_r, sup.phi_rp)
        elif on and node != top_node and fix_mask[base] == 0:
            z_n = u[base + nd - 1]
            _f, fp, _fpp = support_height(kind, sup.geom[k], z_n)
            w.cmask[base] = True
            w.delta[base] = -support_gap(kind, sup.geom[k], u[base], z_n, 0.0)
            if node > 0 and sup.active[k, node - 1] != 0:
                w.cmask[base + nd] = True
                w.delta[base + nd] = -(u[base + nd] - fp * u[base + 2 * nd - 1])


@jit(by_dimension=True, _nrt=True)
def _free_moment(nd, s_el, u, model, torques, td_node, s_b, row, own, phi):
    """Touchdown's equation: the moment at touchdown on the free side, the
    residual [N m] of the first free element at the slope unknown of its lower
    node (on the seabed, its slope held), which vanishes with that moment as
    the continuum's does (the laid side carries none). It is the element's
    nodal residual, not the end moment of its cubic: that one converges an
    order slower, and the laid element's consistent-load couple would enter a
    node-equilibrium form of it. The slope unknown is the node's frame's,
    turned by ``phi`` [rad] (a sloped seabed's: the normal component of r',
    x' cos(phi) - z' sin(phi), the turn of the tangent; x' when flat).
    ``row`` gets its derivative d/du, ``own`` (nbnd,) its derivatives by each
    boundary's arc length at fixed u (the element's length moves with every
    boundary whose rates ``s_b`` reach it: a graded mesh's with all of
    them); returns it."""
    ndn = 2 * nd + 1
    ne = 2 * ndn
    e = td_node
    fe = np.zeros(ne)
    ke = np.zeros((ne, ne))
    dfe = np.zeros(ne)
    want = row.shape[0] == u.shape[0]
    sec = model.section[e]
    element_forces(nd, s_el[e], u[e * ndn:e * ndn + ne], model, sec, torques[e], fe, ke,
                   want, dfe, want, np.empty(WORK_SIZE), np.empty((3, 3)))
    if phi != 0.0:  # the slope unknown of the node's frame (x' row of the turned pair)
        c = math.cos(phi)
        s = math.sin(phi)
        fe[nd] = c * fe[nd] - s * fe[2 * nd - 1]
        dfe[nd] = c * dfe[nd] - s * dfe[2 * nd - 1]
        for j in range(ne):
            ke[nd, j] = c * ke[nd, j] - s * ke[2 * nd - 1, j]
    if not want:
        return fe[nd]
    for i in range(row.shape[0]):
        row[i] = 0.0
    for j in range(ne):
        row[e * ndn + j] = ke[nd, j]
    for b in range(own.shape[0]):
        own[b] = (s_b[b, e + 1] - s_b[b, e]) * dfe[nd]
    return fe[nd]


@jit(_nrt=False)
def _over_point(nd, u, point, node, row):
    """A point's boundary equation: node ``node`` is the material point over
    the rigid point ``point``, t . (r - r_p) = 0 with t = r'/|r'| the pipe's
    tangent [m] (the point's projection on the pipe). ``row`` gets d/du
    (global frame); an empty ``row``: the value alone."""
    ndn = 2 * nd + 1
    base = node * ndn
    z_l = point[L.PT_Z]
    x_l = point[L.PT_X]
    for i in range(row.shape[0]):
        row[i] = 0.0
    a = 0.0
    for i in range(nd):
        a += u[base + nd + i] ** 2
    a = math.sqrt(a)
    # r - r_p, component by component (x, then y in 3D, then z; no array)
    d_x, d_y, d_z = u[base] - x_l, u[base + 1], u[base + nd - 1] - z_l
    e = 0.0
    for i in range(nd):
        d_i = d_x if i == 0 else (d_z if i == nd - 1 else d_y)
        e += d_i * u[base + nd + i] / a
    if row.shape[0] == 0:
        return e
    for i in range(nd):
        d_i = d_x if i == 0 else (d_z if i == nd - 1 else d_y)
        t_i = u[base + nd + i] / a
        row[base + i] = t_i
        row[base + nd + i] = (d_i - e * t_i) / a
    return e


@phase
def _bnd_equation(nd, u, sup, b, node, row):
    """The equation of boundary b >= B_LO at its node, by the kind of its
    support (row b): over a point (:func:`_over_point`), else tangent to the
    support (:func:`.supports.tangency`, lift-off's); ``row`` gets its
    derivative d/du. (Touchdown's, a moment, comes from
    :func:`.system._evaluate`, :func:`_free_moment`.)"""
    if sup.kind[b] == SUP_POINT:
        return _over_point(nd, u, sup.geom[b], node, row)
    return tangency(nd, u, sup.kind[b], sup.geom[b], node, row)


@jit(_nrt=False)
def _bnd_scale(b, fref, href):
    """The scale of boundary b's equation: a moment (touchdown), a slope
    (lift-off), a length (a point's)."""
    if b == B_TD:
        return fref * href
    return 1.0 if b == B_LO else href


@jit(_nrt=False)
def _point_gap(nd, u, point, node, phi):
    """Clearance [m] of node ``node`` from the rigid point ``point`` (its row
    of ``sup.geom``) along the normal of a frame turned by ``phi`` (the
    pipe's, see :func:`_over_point`; :func:`.supports.support_gap`)."""
    base = node * (2 * nd + 1)
    return support_gap(SUP_POINT, point, u[base], u[base + nd - 1], phi)


@jit(entry=True, _nrt=False)
def point_gaps(nd, u, points, nodes, gaps):
    """Each point's clearance [m] into ``gaps``: :func:`_point_gap` of the
    node ``nodes[j]`` over point j, along the normal of the pipe's tangent
    there (the results' roller clearances, :func:`.results.roller_gaps`)."""
    ndn = 2 * nd + 1
    for j in range(nodes.shape[0]):
        k = nodes[j]
        phi = math.atan2(u[k * ndn + nd], u[k * ndn + 2 * nd - 1])
        gaps[j] = _point_gap(nd, u, points[j], k, phi)


@phase
def _points_update(nd, u, mesh, sup, react, settings):
    """Each rigid point's contact by the complementarity
    min(R, c g) = 0 (semismooth Newton: the branch that the present normal
    reaction R and gap g select): it bears when R - c g > 0, its node then
    held on it, else R = 0 (c = fref / href, R the reaction ``react`` at its
    node's normal row [N], g its gap [m]). Returns how many branches changed."""
    ndn = 2 * nd + 1
    changes = 0
    for b in range(mesh.bnodes.shape[0]):
        kt = mesh.bnodes[b]
        if kt < 0 or sup.kind[b] != SUP_POINT:
            continue
        point = sup.geom[b]
        bearing = point[L.PT_BEAR] != 0.0
        r_n = react[kt * ndn] if bearing else 0.0
        g_n = _point_gap(nd, u, point, kt, sup.phi_r[kt])
        bears = r_n - (settings.fref / settings.href) * g_n > 0.0
        point[L.PT_BEAR] = 1.0 if bears else 0.0
        point[L.PT_R] = r_n if bears else 0.0
        if bears != bearing:
            changes += 1
    return changes


@jit(_nrt=False)
def mesh_lengths(s_a, s_b, s_bd, s_el):
    """Element lengths [m] of the mesh that follows the contact boundaries:
    node i sits at s_i = s_a[i] + sum_b s_b[b, i] s_bd[b], s_bd the arc lengths
    of the boundaries (touchdown, lift-off, the points: ``B_*``)."""
    for e in range(s_el.shape[0]):
        le = s_a[e + 1] - s_a[e]
        for b in range(s_bd.shape[0]):
            le += (s_b[b, e + 1] - s_b[b, e]) * s_bd[b]
        s_el[e] = le


@jit(_nrt=False)
def _has_boundaries(mesh):
    """True when some contact boundary is an unknown (the mesh follows it)."""
    for b in range(mesh.bnodes.shape[0]):
        if mesh.bnodes[b] >= 0:
            return True
    return False


@jit(_nrt=False)
def _element_at(s_old, node, t):
    """(element, xi) of material point ``t`` [m] on nodes ``s_old`` [m],
    searched from node ``node``."""
    nn = s_old.shape[0]
    e = min(node, nn - 2)
    while e > 0 and t < s_old[e]:
        e -= 1
    while e < nn - 2 and t > s_old[e + 1]:
        e += 1
    return e, (t - s_old[e]) / (s_old[e + 1] - s_old[e])


@jit(_nrt=False)
def _pipe_at(nd, u_old, s_old, e, xi, sh, value, rate):
    """The pipe of state ``u_old`` on nodes ``s_old`` at ``xi`` of element
    ``e``: its nodal unknowns (r, r', lambda) into ``value`` and their
    derivatives along it (r', r'', lambda') into ``rate``; cubic Hermite in r
    (:func:`.element_shapes.hermite`, ``sh`` (3, 4) its scratch), linear in lambda."""
    ndn = 2 * nd + 1
    le = s_old[e + 1] - s_old[e]
    n, dn, ddn = sh[0], sh[1], sh[2]
    hermite(xi, le, n, dn, ddn)
    a = e * ndn
    b = a + ndn
    for i in range(nd):
        pa = u_old[a + nd + i]
        pb = u_old[b + nd + i]
        chord = u_old[b + i] - u_old[a + i]
        value[i] = u_old[a + i] + n[1] * pa + n[2] * chord + n[3] * pb
        value[nd + i] = dn[1] * pa + dn[2] * chord + dn[3] * pb
        rate[i] = value[nd + i]
        rate[nd + i] = ddn[1] * pa + ddn[2] * chord + ddn[3] * pb
    value[2 * nd] = (1.0 - xi) * u_old[a + 2 * nd] + xi * u_old[b + 2 * nd]
    rate[2 * nd] = (u_old[b + 2 * nd] - u_old[a + 2 * nd]) / le


@jit(_nrt=False)
def _onto_curves(nd, u, u_old, dv, alpha, sup):
    """State at ``u_old`` + ``alpha`` ``dv`` for the contact nodes of the
    supports in curve coordinates, whose increments ``dv`` are in curve
    coordinates (c, z, c', z'): z and z' move linearly, x = f(z) + c and
    x' = f'(z) z' + c' follow the curve exactly."""
    ndn = 2 * nd + 1
    for k in range(sup.kind.shape[0]):
        kind = sup.kind[k]
        if not in_curve_coords(kind):
            continue
        g = sup.geom[k]
        for node in range(sup.active.shape[1]):
            if sup.active[k, node] == 0:
                continue
            p = node * ndn
            q = p + nd - 1
            z0 = u_old[q]
            f0, fp0, _c0 = support_height(kind, g, z0)
            c0 = u_old[p] - f0
            cp0 = u_old[p + nd] - fp0 * u_old[q + nd]
            z1 = u[q]  # u_old + alpha dv, or where a boundary's move carried it
            zp1 = u[q + nd]
            f1, fp1, _c1 = support_height(kind, g, z1)
            u[p] = f1 + c0 + alpha * dv[p]
            u[p + nd] = fp1 * zp1 + cp0 + alpha * dv[p + nd]

"""Contact laws as kernels: the stinger's geometry, the tip, the lateral
hold, seabed friction. Normal contacts act through the condensation
(:mod:`.condensation`): a contact node's unknowns are prescribed in its
nodal frame, its reaction read back from the constrained rows; the contact
boundaries, unknowns of Newton, say which nodes are in contact
(:mod:`.constraints`: the seabed from the lower end to touchdown, the
stinger from lift-off to the top). This module carries:

* :func:`tip_geometry`: the stinger's tip as a point against the element
  spanning it (the material point whose z is the tip's);
* :func:`lateral_hold`: the nodes the stinger holds laterally in 3D;
* :func:`friction_forces`, :func:`friction_track`, :func:`friction_commit`:
  an elastic-perfectly-plastic friction spring at each seabed contact (a
  force in the residual, not a constraint), its normal reaction tracked each
  iteration and its anchor moved by the return mapping at the end of a step;
  :func:`friction_step`, the step that takes no sliding spring through its
  stick zone.
"""

from __future__ import annotations

import math

import numpy as np

from . import layout as L
from ._jit import jit
from .element_shapes import hermite_crossing
from .loads import seabed_surface
from .supports import holds_laterally, support_height, support_span
from .tuning import LATERAL_HYSTERESIS, ROUNDOFF


@jit(_nrt=False)
def lateral_hold(nd, s_el, u, sup, top_node, held):
    """Mark in ``held`` the nodes the stinger holds laterally (3D): those over
    the z range of a support that holds laterally
    (:func:`.supports.holds_laterally`), the held top and fixed nodes
    excepted. They are held on the stinger's plane and tangent to it (y = 0
    and y' = 0), so the free span below the tip is clamped laterally there.

    A node the mesh put on the tip sits on either side of z_L as it slides
    between iterations: within LATERAL_HYSTERESIS of its elements of the tip
    it is held too, so that it does not flip between held and free.
    """
    nn = held.shape[0]
    ndn = 2 * nd + 1
    for node in range(nn):
        held[node] = False
        if nd != 3 or node == top_node or sup.fix_mask[node * ndn] != 0:
            continue
        h_near = s_el[min(node, nn - 2)]
        if node > 0:
            h_near = min(h_near, s_el[node - 1])
        z_n = u[node * ndn + nd - 1]
        for k in range(sup.kind.shape[0]):
            if not holds_laterally(sup.kind[k]):
                continue
            z_lo, z_hi = support_span(sup.kind[k], sup.geom[k])
            held[node] = held[node] or z_lo - LATERAL_HYSTERESIS * h_near <= z_n <= z_hi


@jit(entry=True, _nrt=False)
def tip_geometry(nd, s_el, u, kind, g):
    """The pipe over the stinger tip (x_L, z_L), the lower end of the support
    ``kind`` with parameters ``g`` (the stinger's curve): the material point
    whose z equals z_L (on the element spanning it). Returns (found, the
    vertical clearance x - x_L there [m], its arc length [m])."""
    ndn = 2 * nd + 1
    nel = s_el.shape[0]
    z_l, _z_u = support_span(kind, g)
    x_l, _fp, _fpp = support_height(kind, g, z_l)
    zi = nd - 1
    e = -1
    for k in range(nel):
        if u[k * ndn + zi] <= z_l < u[(k + 1) * ndn + zi]:
            e = k
            break
    if e < 0:
        return False, 0.0, 0.0
    a = e * ndn
    b = a + ndn
    le = s_el[e]
    za, zb = u[a + zi], u[b + zi]
    pa, pb = u[a + nd + zi], u[b + nd + zi]
    xi = 0.0 if za == z_l else hermite_crossing(za, pa, zb, pb, le, z_l)
    x2 = xi * xi
    x3 = x2 * xi
    x = ((1 - 3 * x2 + 2 * x3) * u[a] + le * (xi - 2 * x2 + x3) * u[a + nd]
         + (3 * x2 - 2 * x3) * u[b] + le * (-x2 + x3) * u[b + nd])
    s_tip = 0.0
    for k in range(e):
        s_tip += s_el[k]
    return True, x - x_l, s_tip + xi * le


@jit(_nrt=False)
def _friction_dofs(nd, props, comp):
    """(dof slot, coefficient, anchor column, direction column) of component
    ``comp`` (0 lateral, 1 axial); slot -1 when that friction is absent."""
    if comp == 0:
        if nd != 3:
            return -1, 0.0, 0, 0
        return 1, props[L.MU_Y], L.FR_Y, L.FR_DIR
    return nd - 1, props[L.MU_Z], L.FR_Z, L.FR_DIRZ


@jit(_nrt=False)
def node_arcs(s_el, s):
    """Node arc lengths [m] from the element lengths (the lower end at s = 0)."""
    s[0] = 0.0
    for e in range(s_el.shape[0]):
        s[e + 1] = s[e] + s_el[e]


@jit(_nrt=False)
def _anchor_partner(fric, s, node):
    """(other node, t) of :func:`anchor_at`: the anchor of node ``node``'s
    material point is its own anchor plus t times the difference to the
    neighbour ``other``'s (-1, 0.0: its own alone)."""
    nn = s.shape[0]
    s_n = s[node]
    s0 = fric[node, L.FR_S]
    if s_n == s0:
        return -1, 0.0
    other = node - 1 if s_n < s0 else node + 1
    if other < 0 or other >= nn:
        return -1, 0.0
    s1 = fric[other, L.FR_S]
    if s1 == s0:
        return -1, 0.0
    return other, (s_n - s0) / (s1 - s0)


@jit(_nrt=False)
def anchor_at(fric, col, s, node):
    """Anchor ``col`` of the material point at node ``node``'s arc length s[node]:
    the anchors belong to material points (column FR_S), and a mesh that follows
    touchdown moves its nodes along the pipe, so the anchor is interpolated
    linearly between the neighbouring nodes' anchor points."""
    other, t = _anchor_partner(fric, s, node)
    if other < 0:
        return fric[node, col]
    return fric[node, col] + t * (fric[other, col] - fric[node, col])


@jit(_nrt=False)
def _anchor_slope(fric, col, s, node):
    """d(anchor)/ds [-] of :func:`anchor_at` at node ``node``: the slope of the
    segment it interpolates on (their mean where the node sits on its own
    anchor point, between the two segments)."""
    nn = s.shape[0]
    s0 = fric[node, L.FR_S]
    total = 0.0
    count = 0
    for other in (node - 1, node + 1):
        if other < 0 or other >= nn:
            continue
        on_side = (s[node] < s0) == (other < node)
        if s[node] != s0 and not on_side:
            continue
        ds = fric[other, L.FR_S] - s0
        if ds != 0.0:
            total += (fric[other, col] - fric[node, col]) / ds
            count += 1
    return total / count if count > 0 else 0.0


@jit(_nrt=False)
def plane_normal(props):
    """(n_x, n_z) [-]: the unit normal of the seabed's plane, (cos a, -sin a)
    with tan a = props[SEABED_TAN] ((1, 0) on the flat seabed)."""
    m = props[L.SEABED_TAN]
    if m == 0.0:
        return 1.0, 0.0
    c = 1.0 / math.sqrt(1.0 + m * m)
    return c, -m * c


@jit(_nrt=False)
def plane_tangent(props):
    """(t_x, t_z) [-]: the seabed plane's unit tangent along the route, where
    axial friction acts: (m c, c), m = props[SEABED_TAN], c = 1 / sqrt(1 +
    m^2) ((0, 1) flat)."""
    m = props[L.SEABED_TAN]
    if m == 0.0:
        return 0.0, 1.0
    c = 1.0 / math.sqrt(1.0 + m * m)
    return m * c, c


@jit(_nrt=False)
def slip_coordinate(nd, v, base, slot, t_x, t_z):
    """The coordinate [m] the friction spring at ``slot`` of the node at rows
    ``base`` measures in ``v`` (positions or a step): y (lateral), or along
    the plane's tangent (:func:`plane_tangent`) t_x x + t_z z (axial, slot
    nd - 1; z on the flat seabed, t_x = 0)."""
    if slot == nd - 1 and t_x != 0.0:
        return t_x * v[base] + t_z * v[base + slot]
    return v[base + slot]


@jit(_nrt=False)
def _add_along(v, nd, base, slot, t_x, t_z, value):
    """Add ``value`` along a spring's direction e to the node's rows of ``v``
    (from ``base``): y, or the axial spring's (x, z) rows times (t_x, t_z)."""
    if slot == nd - 1 and t_x != 0.0:
        v[base] += t_x * value
        v[base + slot] += t_z * value
    else:
        v[base + slot] += value


@jit(_nrt=False)
def _add_outer(ab, kv, nd, row_base, col_base, slot, t_x, t_z, k):
    """Add k e e^T to the tangent's rows of the node at ``row_base``, columns
    of the node at ``col_base``; e the spring's direction (:func:`_add_along`)."""
    if slot == nd - 1 and t_x != 0.0:
        for a in range(2):
            i = row_base + (0 if a == 0 else slot)
            t_i = t_x if a == 0 else t_z
            for b in range(2):
                j = col_base + (0 if b == 0 else slot)
                t_j = t_x if b == 0 else t_z
                ab[kv + i - j, j] += k * t_i * t_j
    else:
        ab[kv + row_base - col_base, col_base + slot] += k


@jit(_nrt=False)
def _add_normal_rate(ab, kv, n, nd, xrow, slot, t_x, t_z, f, n_z, n_x):
    """Add f e dW/du to the rows of the node at ``xrow``, e the spring's
    direction (:func:`_add_outer`): dW/du the normal's rows of the tangent
    (x, or n_x x + n_z z), their columns the node's and its neighbours'
    unknowns (within the y and z rows' band too), each read before written."""
    ndn = 2 * nd + 1
    zrow = xrow + nd - 1
    tilt = slot == nd - 1 and t_x != 0.0
    for j in range(max(0, xrow - ndn), min(n, xrow + 2 * ndn)):
        dw_j = ab[kv + xrow - j, j]
        if n_z != 0.0:
            dw_j = n_x * dw_j + n_z * ab[kv + zrow - j, j]
        if tilt:
            ab[kv + xrow - j, j] += f * t_x * dw_j
            ab[kv + zrow - j, j] += f * t_z * dw_j
        else:
            ab[kv + xrow + slot - j, j] += f * dw_j


@jit(_nrt=False)
def normal_force(nd, g, props, bed_active, fric, node, nodal):
    """The normal force W [N] a node's friction acts with: on a rigid seabed
    contact its reaction at the present state along the plane's normal
    (:func:`plane_normal`), from the residual's x and z rows ``g``
    (elements and loads, before friction; in the global frame, or with
    ``nodal`` in the nodal frames, where a contact's x row is its normal),
    not less than 0; on an elastic seabed the foundation's force
    (:func:`friction_track`)."""
    if bed_active[node] != 0:
        base = node * (2 * nd + 1)
        n_x, n_z = plane_normal(props)
        if n_z == 0.0 or nodal:
            return max(g[base], 0.0)
        return max(n_x * g[base] + n_z * g[base + nd - 1], 0.0)
    return fric[node, L.FR_W]


@jit(_nrt=False)
def friction_length_derivative(nd, u, g, model, bed_active, fric, s, s_b, col):
    """Add to ``col`` d(friction in the residual)/d s_T at fixed nodal unknowns:
    a sticking spring's stretch u - anchor(s_i) changes as its node moves along
    the pipe by ds_i/ds_T = s_b[i] (a sliding spring's force does not), and
    every spring's normal force W = G_x changes with the x row's column
    ``col`` (``g`` the residual W is read from, :func:`normal_force`)."""
    if model.factors[L.F_FRICTION] == 0.0:
        return
    props = model.props
    d_slip = props[L.FRICTION_SLIP]
    ndn = 2 * nd + 1
    t_x, t_z = plane_tangent(props)
    n_x, n_z = plane_normal(props)
    for node in range(bed_active.shape[0]):
        w = normal_force(nd, g, props, bed_active, fric, node, False)
        if w <= 0.0:
            continue
        dw = 0.0
        if bed_active[node] != 0:
            dw = n_x * col[node * ndn] + n_z * col[node * ndn + nd - 1]
        for comp in range(2):
            slot, mu, ccol, _dcol = _friction_dofs(nd, props, comp)
            if slot < 0 or mu <= 0.0:
                continue
            base = node * ndn
            d = (slip_coordinate(nd, u, base, slot, t_x, t_z)
                 - anchor_at(fric, ccol, s, node)) / d_slip
            clipped = min(max(d, -1.0), 1.0)
            # g -= force e, force = -mu w clip(d): dg = mu (dw clip(d) + w dd) e,
            # e the spring's direction (:func:`_add_along`)
            _add_along(col, nd, base, slot, t_x, t_z, mu * dw * clipped)
            if abs(d) < 1.0 and s_b[node] != 0.0:
                _add_along(col, nd, base, slot, t_x, t_z,
                           -(mu * w * _anchor_slope(fric, ccol, s, node) * s_b[node] / d_slip))


@jit(entry=True, _nrt=False)
def friction_forces(nd, u, g, ab, kv, model, bed_active, fric, out, s, nodal):
    """Add the seabed friction springs to the residual ``g`` (and, when ``ab``
    has more than one row, their stiffness to its diagonal row ``kv``).

    Each seabed contact resists lateral (and axial) motion from its anchor d
    with the force -mu W clip(d / d_slip, -1, 1): elastic up to the mobilising
    displacement d_slip, then sliding at mu W. The lateral spring acts along
    y; the axial one along the seabed plane's tangent e = (t_x, t_z)
    (:func:`plane_tangent`, z on the flat seabed), d measured along it
    (:func:`slip_coordinate`), so its force enters the x and z rows as
    force e and its stiffness as mu W / d_slip e e^T. The two springs are
    independent: each holds its own cone, |f_y| <= mu_y W and |f_t| <= mu_z W
    (a rectangle in the plane, not an ellipse). W is the node's normal force
    at the present state (:func:`normal_force`: the x row of ``g``, which
    holds the elements' residual when this is called; on a sloped plane
    its normal component), and the tangent carries its derivative, the x
    row of the tangent (the normal's rows) times mu clip(d) e (the band
    holds it: the x and z rows' columns lie within the y and z rows' band).
    ``out`` (ndof,) receives the force on the pipe, in the global frame;
    ``s`` (nn,) holds the node arc lengths [m] (see :func:`anchor_at`);
    ``nodal``: ``g``'s rows are in the nodal frames (:func:`normal_force`).
    """
    if model.factors[L.F_FRICTION] == 0.0:  # off on gravity's path
        return
    props = model.props
    d_slip = props[L.FRICTION_SLIP]
    ndn = 2 * nd + 1
    tangent = ab.shape[0] > 1
    n = g.shape[0]
    n_x, n_z = plane_normal(props)
    t_x, t_z = plane_tangent(props)
    for node in range(bed_active.shape[0]):
        w = normal_force(nd, g, props, bed_active, fric, node, nodal)
        if w <= 0.0:
            continue
        xrow = node * ndn
        for comp in range(2):
            slot, mu, col, _dcol = _friction_dofs(nd, props, comp)
            if slot < 0 or mu <= 0.0:
                continue
            dof = xrow + slot
            tilt = slot == nd - 1 and t_x != 0.0  # the axial spring on a sloped plane
            f_max = mu * w
            d = (slip_coordinate(nd, u, xrow, slot, t_x, t_z)
                 - anchor_at(fric, col, s, node)) / d_slip
            clipped = min(max(d, -1.0), 1.0)
            force = -f_max * clipped
            if tangent:
                # dW/du read before a tilted spring writes its x and z rows
                rate = bed_active[node] != 0
                if rate and tilt:
                    _add_normal_rate(ab, kv, n, nd, xrow, slot, t_x, t_z, mu * clipped, n_z, n_x)
                if abs(d) < 1.0:
                    _add_outer(ab, kv, nd, xrow, xrow, slot, t_x, t_z, f_max / d_slip)
                    # a neighbour off the seabed keeps its anchor on itself
                    # (:func:`friction_track`), so an anchor interpolated
                    # towards it (touchdown's node, moved past its anchor
                    # point) moves with that neighbour's own unknown
                    other, t = _anchor_partner(fric, s, node)
                    if other >= 0 and bed_active[other] == 0 and fric[other, L.FR_W] <= 0.0:
                        _add_outer(ab, kv, nd, xrow, other * ndn, slot, t_x, t_z,
                                   -(f_max / d_slip * t))
                if rate and not tilt:
                    _add_normal_rate(ab, kv, n, nd, xrow, slot, t_x, t_z, mu * clipped, n_z, n_x)
            _add_along(g, nd, xrow, slot, t_x, t_z, -force)
            out[dof] = force
            if tilt:
                out[xrow] = t_x * force
                out[dof] = t_z * force


@jit(entry=True, _nrt=False)
def friction_track(nd, u, react, props, bed, bed_active, fric, s):
    """Per Newton iteration: on an elastic seabed each node's normal force W,
    the foundation's force at a node below the surface, k (x_b(z) - x) over
    the node's share of the pipe (half of each element beside it; x_b the
    seabed's height, :func:`.loads.seabed_surface` (the profile's knots ``bed``); on a
    sloped plane its normal force, times cos(angle), :func:`.loads.foundation`); a rigid
    contact's W is its present reaction (:func:`normal_force`), and its
    linearised reaction ``react`` only says whether it still pushes. Nodes
    off the seabed (or whose contact pulls) keep their anchors where they
    are, so a node that lands is anchored there."""
    ndn = 2 * nd + 1
    nn = bed_active.shape[0]
    k_bed = props[L.SEABED_K]
    m = props[L.SEABED_TAN]  # a sloped plane: the normal penetration's
    root = math.sqrt(1.0 + m * m)
    t_x, t_z = plane_tangent(props)
    for node in range(nn):
        base = node * ndn
        if bed_active[node] != 0 and react[base] > 0.0:
            continue
        w = 0.0
        if bed_active[node] == 0 and k_bed > 0.0:
            x_b, _dx_b = seabed_surface(props, bed, u[base + nd - 1])
            if u[base] < x_b:
                share = 0.5 * (s[min(node + 1, nn - 1)] - s[max(node - 1, 0)])
                w = k_bed * (x_b - u[base]) * share / root
        if w > 0.0:
            fric[node, L.FR_W] = w
        else:
            fric[node, L.FR_W] = 0.0
            fric[node, L.FR_DIR] = 0.0
            fric[node, L.FR_DIRZ] = 0.0
            fric[node, L.FR_Z] = slip_coordinate(nd, u, base, nd - 1, t_x, t_z)
            fric[node, L.FR_S] = s[node]
            if nd == 3:
                fric[node, L.FR_Y] = u[base + 1]


@jit(_nrt=False)
def friction_step(nd, u, du, s, model, bed_active, fric, stop, alpha):
    """The longest fraction (at most ``alpha``) of the step ``du`` (global
    frame) that takes no sliding spring through its stick zone: a spring
    stretched beyond d_slip that the step would carry past the anchor's far
    side stops there, at -d_slip (it slides the other way from there on, if
    the next step asks). Crossing it in one step, Newton on a laid pipe
    sliding as a whole (its lateral stiffness then the suspended span's
    alone) can flip the slip direction every step.

    A spring this rule stopped at the far edge (``stop`` (nn,): 1 + the
    component, 0 lateral, 1 axial, set here for the next call of the same
    Newton solve; 0 none) that the next step carries back stops at its
    anchor instead, inside the stick zone where it has a stiffness: stopped
    at the edge each time, a spring the tracking of its anchor left a hair
    outside the stick zone could flip between the two edges with no
    stiffness at either."""
    if model.factors[L.F_FRICTION] == 0.0:
        return alpha
    props = model.props
    d_slip = props[L.FRICTION_SLIP]
    ndn = 2 * nd + 1
    t_x, t_z = plane_tangent(props)
    stop_node = -1
    stop_flag = 0.0
    for node in range(bed_active.shape[0]):
        if bed_active[node] == 0 and fric[node, L.FR_W] <= 0.0:
            continue
        for comp in range(2):
            slot, mu, col, _dcol = _friction_dofs(nd, props, comp)
            if slot < 0 or mu <= 0.0:
                continue
            base = node * ndn
            rel = slip_coordinate(nd, u, base, slot, t_x, t_z) - anchor_at(fric, col, s, node)
            if abs(rel) < d_slip:
                continue
            edge = -d_slip if rel > 0.0 else d_slip
            if stop[node] == comp + 1:
                edge = 0.0
            step = slip_coordinate(nd, du, base, slot, t_x, t_z)
            if (rel + alpha * step - edge) * (rel - edge) < 0.0:
                alpha = (edge - rel) / step
                stop_node = node
                stop_flag = 0.0 if edge == 0.0 else comp + 1.0
    stop[:] = 0.0
    if stop_node >= 0:
        stop[stop_node] = stop_flag
    return alpha


@jit(_nrt=True)
def friction_commit(nd, u, model, bed_active, fric, s):
    """End of a load step (return mapping): a spring stretched to or beyond
    its mobilising displacement slides, its anchor following the pipe to
    d_slip behind it; the slip direction is recorded (``FR_DIR``, ``FR_DIRZ``).
    Every anchor is then taken to the node's present material point."""
    props = model.props
    friction_on = model.factors[L.F_FRICTION] != 0.0
    d_slip = props[L.FRICTION_SLIP]
    ndn = 2 * nd + 1
    nn = bed_active.shape[0]
    t_x, t_z = plane_tangent(props)
    moved = np.empty((nn, 2))
    for node in range(nn):
        moved[node, 0] = anchor_at(fric, L.FR_Y, s, node)
        moved[node, 1] = anchor_at(fric, L.FR_Z, s, node)
    for node in range(nn):
        fric[node, L.FR_Y] = moved[node, 0]
        fric[node, L.FR_Z] = moved[node, 1]
        fric[node, L.FR_S] = s[node]
    for node in range(nn):
        for comp in range(2):
            slot, mu, col, dcol = _friction_dofs(nd, props, comp)
            if slot < 0:
                continue
            fric[node, dcol] = 0.0
            if fric[node, L.FR_W] <= 0.0 or mu <= 0.0 or not friction_on:
                continue
            pos = slip_coordinate(nd, u, node * ndn, slot, t_x, t_z)
            d = pos - fric[node, col]
            if abs(d) >= d_slip * (1.0 - ROUNDOFF):
                sgn = 1.0 if d > 0.0 else -1.0
                fric[node, col] = pos - sgn * d_slip
                fric[node, dcol] = -sgn

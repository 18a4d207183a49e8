"""Newton iteration with contact by condensation (the paper's Sec. 3.2).

One kernel runs the whole iteration for one load level, so a solve crosses the
Python/numba boundary once per load step:

1. assemble the residual G and tangent K in band storage (global frame);
2. add nodal loads, express rotated nodes in their local frames;
3. condensation: every constrained unknown (fixed ends, seabed contacts, ...)
   gets its increment prescribed, ``K_ff du_f = -G_f - K_fc du_c``; the free
   unknowns are solved from the band system and the reactions recovered from
   the constrained rows, ``R_c = G_c + K_cf du_f + K_cc du_c``;
4. a backtracking line search on the weighted residual norm;
5. the tip's contact by its complementarity (below); seabed friction enters
   as spring forces in G and K, not as constraints; converged when the
   residual is below the tolerance, the constraints and the boundaries'
   equations hold and the tip's branch no longer changes (the lateral hold
   is each iteration's: the nodes over the stinger where they are).

No node walks on or off a contact: the contact boundaries are unknowns of
Newton (below). The node-walking active set this replaced (session notes,
issue 10) took 5 to 150 iterations and a stack of rules: freezing on
revisit, doubling releases, the clamp-couple release, a contact history,
a contact-pull refusal, remesh passes to put a node on each boundary.

When the top tension is given, the bottom tension T_b is one more unknown with
the equation Te(top) = R_top . t_top - T_top = 0 (the reaction at the pinned top
is the internal force there). Its row and column are local to the two ends, so
the bordered system is solved with the band factors and one extra solve.

Stinger contacts are expressed in curve coordinates, not in frames rotated
to the stinger (:func:`.assembly.curve_node`): x = f(z) + c, x' = f'(z) z' + c',
c = 0 and c' = 0 held, z and z' sliding along the curve; the map's second
derivatives, weighted by the residual (the support's reaction), enter the
tangent, so a node that slides along the stinger keeps Newton quadratic, and
the constraints hold exactly after every step.

Contact boundaries as unknowns (``bnodes[b] >= 0``). The mesh follows each
boundary b: node i at s_i = s_a[i] + sum_b s_b[b, i] s_bd[b] (:func:`mesh_lengths`):
every span between anchors mapped onto its present ends, or a mesh graded at
the boundaries moving with its grading (:meth:`.Problem.follow_rates`). The
contact stretches are then fixed sets, no node walks: the seabed from the
lower end to touchdown (b = 0), the stinger from lift-off (b = 1) to the
top. Each arc length is a bordered unknown closed by its continuum
condition:

* touchdown: on the seabed, tangent to it, no moment on the free side (the
  free element's nodal residual at the slope unknown, :func:`_free_moment`);
* lift-off (or re-contact above a bearing tip): on the stinger, its node's
  slope free and the pipe tangent to the stinger there (:func:`_tangency`),
  which leaves its curvature continuous;
* a rigid point (b = 2, 3, ..., one per row of ``sup.points``: the
  quadratic stinger's tip, or each roller of a roller stinger, which has
  no curve): a node follows the material point over the point,
  t . (r - r_p) = 0 (:func:`_over_point`), and its normal contact is chosen
  by the complementarity min(R, c g) = 0, solved semismoothly (the branch
  the present reaction R and gap g select, each iteration,
  :func:`_points_update`). This is the point-against-element contact with
  the element's end put on the contact point: the pipe's moment, which
  kinks under a point load, is then kinked at a node, where the cubic
  elements represent it, and the gap and its multiplier are the node's.

Their columns dG/ds_b are the elements' analytic dG/dle times the length
rates (:func:`.assembly.assemble`, in the tangent's pass) plus the friction
springs' anchor derivative (anchors belong to material points,
:func:`.contact.anchor_at`). All border unknowns (bottom tension, the
boundaries) are eliminated by one dense Schur complement (:func:`_solve_dense`).

The boundaries move only from equilibrium: while the weighted residual of
the pipe with the boundaries where they are exceeds INNER_RATIO times the
boundaries' own imbalance (their equations' residuals), an iteration
holds them (lift-off's node then tangent to the stinger); from a state in
equilibrium the bordered step is the reduced Newton step of the boundaries'
own equations. Without this, a step from a state out of balance followed a
linearisation that could point the wrong way (re-contact above a bearing
tip, started one flexural length off, ran up the stinger: S67 at a =
-0.00116 failed, -0.00115 took 150 iterations; with it they take 58 and 44).
The step is then the full Newton step within limits: a boundary moves at most
``settings.bstep`` (:func:`pipelay_fast.continuation.boundary_step`), no
element of a zone shrinks below a tenth, lift-off goes no further than the
tip, the span between re-contact and a bearing tip at most halves or
doubles (it grows like sqrt(a - a_switch) past the change of regime), no
sliding friction spring passes through its stick zone
(:func:`.contact.friction_step`; a step so cut is doubled back towards the
limited one while the merit falls, :func:`_past_friction_cut`); the merit
may rise up to MERIT_RISE times
(the weighted residual rises across good steps while the element lengths
move with the boundaries); the nodes a step of the stinger's boundaries moves along the
pipe are carried along its curve (:func:`_take_step`). When lift-off
reaches the tip from above and Newton moves it further (or a step would
take it past the tip: the step is taken up to the tip), the kernel stops
with PAST_TIP and the caller switches to bearing on the tip
(:func:`pipelay_fast.continuation.newton_in_regime`); bearing, when a step
would more than halve a gap span already shorter than an element (no
bearing solution: Newton would only creep towards a span of zero), or when
the tip's branch changes with the residual no lower than at its last change
(the branch cycles with no progress), it stops with SPAN_CLOSED or TIP_CYCLE
and the caller switches to lifting off; when a step
would take touchdown more than half way to the modelled lower end, it stops
with SHORT_LAID and the caller prepends laid pipe
(:func:`pipelay_fast.solver._solve_gravity`).

The kernel never raises: it writes a status code (:mod:`.layout`) into ``info``.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from . import layout as L
from ._jit import jit, phase
from .assembly import assemble, curve_node, distribute_torque, element_forces, rotate_node
from .banded import band_factor, band_solve_many
from .contact import (
    ST_A,
    ST_B,
    ST_C,
    ST_ON,
    ST_ZL,
    friction_commit,
    friction_forces,
    friction_length_derivative,
    friction_step,
    friction_track,
    lateral_hold,
    node_arcs,
    normal_force,
    stinger_angle,
)
from .element import WORK_SIZE, hermite

# info slots
I_STATUS = 0
I_ITER = 1
I_RES = 2  # weighted residual (max norm) at exit
I_DELTA = 3  # largest constraint violation at exit [m]
I_TOP_RES = 4  # relative top-tension residual
I_PAST = 5  # PAST_TIP: how far [m] along the pipe the step would take lift-off past the tip
N_INFO = 6


@jit(by_dimension=True, _nrt=True)
def _system(nd, s_el, u, model, torques, ab, kl, ku, g, ends, want_tangent, s_b, bnodes, bcols):
    """Residual (+ tangent, global frame, and the boundaries' columns dG/ds_b
    of the elements, :func:`.assembly.assemble`) with the nodal loads, the
    load path's offset and the bottom tension on the sliding lower end."""
    props = model.props
    if props[L.MOM_X] != 0.0 or props[L.MOM_Y] != 0.0 or props[L.MOM_Z] != 0.0:
        distribute_torque(nd, s_el, u, props, torques)
    assemble(nd, s_el, u, model, torques, ab, kl, ku, g, want_tangent, s_b, bnodes, bcols)
    n = g.shape[0]
    for i in range(n):
        g[i] += ends.g_off[i] - ends.f_node[i]
    if ends.slide_dof >= 0:
        g[ends.slide_dof] += ends.tb[0]


@jit(_nrt=False)
def _rotate_all(nd, ab, kl, ku, g, phi_r, phi_rp, want_tangent):
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
def _curve_all(nd, ab, kl, ku, g, u, stinger, st_active, want_tangent):
    """Express every stinger contact node in the stinger's curve coordinates
    (:func:`.assembly.curve_node`)."""
    ndn = 2 * nd + 1
    fpp = 2.0 * stinger[ST_A]
    for node in range(st_active.shape[0]):
        if st_active[node] != 0:
            base = node * ndn
            if not want_tangent and _zero_at(g, base, 2 * nd):
                continue
            fp = fpp * u[base + nd - 1] + stinger[ST_B]
            curve_node(nd, ab, kl, ku, g, node, fp, fpp, u[base + 2 * nd - 1], want_tangent)


@jit(_nrt=False)
def _onto_curve(nd, u, u_old, dv, alpha, stinger, st_active):
    """State at ``u_old`` + ``alpha`` ``dv`` for the stinger contact nodes, whose
    increments ``dv`` are in curve coordinates (c, z, c', z'): z and z' move
    linearly, x = f(z) + c and x' = f'(z) z' + c' follow the curve exactly."""
    ndn = 2 * nd + 1
    a = stinger[ST_A]
    b = stinger[ST_B]
    cc = stinger[ST_C]
    for node in range(st_active.shape[0]):
        if st_active[node] == 0:
            continue
        p = node * ndn
        q = p + nd - 1
        z0 = u_old[q]
        c0 = u_old[p] - ((a * z0 + b) * z0 + cc)
        cp0 = u_old[p + nd] - (2.0 * a * z0 + b) * u_old[q + nd]
        z1 = u[q]  # u_old + alpha dv, or where a boundary's move carried it
        zp1 = u[q + nd]
        u[p] = (a * z1 + b) * z1 + cc + c0 + alpha * dv[p]
        u[p + nd] = (2.0 * a * z1 + b) * zp1 + cp0 + alpha * dv[p + nd]


@jit(_nrt=False)
def _curve_reactions(nd, u, stinger, st_active, phi_r, phi_rp, react):
    """Reactions of the stinger contacts in the rotated frame the results read:
    in curve coordinates the support's force is G_x (1, -f'), so its normal
    component is G_x / cos(psi), psi the stinger's angle (and likewise for the
    slope's); the frames are set to psi."""
    ndn = 2 * nd + 1
    for node in range(st_active.shape[0]):
        if st_active[node] == 0:
            continue
        base = node * ndn
        psi = stinger_angle(stinger, u[base + nd - 1])
        phi_r[node] = psi
        phi_rp[node] = psi
        c = math.cos(psi)
        react[base] /= c
        react[base + nd] /= c


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


MERIT_RISE = 1e8  # boundaries mode: the largest rise of the merit a step may bring
# a weighted residual above RUNAWAY times the larger of its start and 1 (forces
# a million times the reference force) has diverged (a 50 m/s current in 2D,
# accepted steps and all, went on to 1e98 over 81 iterations)
RUNAWAY = 1e6
# a residual within this multiple of its round-off floor is converged
# (:func:`_roundoff_ratio`): at the floor the ratio measured 0.4 to 1.8 (S125
# 3D on 0.05 m elements, J125 on 19 000), one Newton step before it 50 to 200
# and more; the step test (below) never held there (the steps stay at 7e3
# eps |r|), and those solves ran to the cap
ROUNDOFF_RATIO = 10.0
# ... and so is one whose Newton step no longer moves the state beyond
# STALL_STEP eps |r| (with a weighted residual below 1e-4): where the tangent
# is not exact (the power-law current's dV/dx at the seabed is a secant) the
# residual can stall a few times above the tolerance but 10 to 20 times
# above its floor (S67 3D at 8 m, a = -0.00115: 31 iterations with this test,
# 339 without; random case 7: 113 and 222)
STALL_STEP = 1e3
INNER_RATIO = 1.0  # the boundaries move once the pipe's imbalance is below this times theirs
# the boundaries that can be unknowns (``mesh.bnodes``, the rows of
# ``mesh.s_b``): touchdown, lift-off from the stinger (or re-contact above a
# bearing tip), then one per rigid point (``sup.points``, the stinger's tip
# first): the material point over it
B_TD = 0
B_LO = 1
B_PT = 2


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
def _solve_dense(nb, sm, rh, dz):
    """Solve the nb x nb border system ``sm dz = rh`` (Gaussian elimination with
    partial pivoting; sm and rh are overwritten). Returns False when singular."""
    for k in range(nb):
        p = k
        for i in range(k + 1, nb):
            if abs(sm[i, k]) > abs(sm[p, k]):
                p = i
        if sm[p, k] == 0.0:
            return False
        if p != k:
            for j in range(nb):
                tmp = sm[k, j]
                sm[k, j] = sm[p, j]
                sm[p, j] = tmp
            tmp = rh[k]
            rh[k] = rh[p]
            rh[p] = tmp
        for i in range(k + 1, nb):
            f = sm[i, k] / sm[k, k]
            for j in range(k, nb):
                sm[i, j] -= f * sm[k, j]
            rh[i] -= f * rh[k]
    for k in range(nb - 1, -1, -1):
        acc = rh[k]
        for j in range(k + 1, nb):
            acc -= sm[k, j] * dz[j]
        dz[k] = acc / sm[k, k]
    return True


@jit(_nrt=False)
def _tangency(nd, u, stinger, b, node, row):
    """The pipe tangent to its support at a boundary node whose slope is
    otherwise free: lift-off's equation (b = 1), c' = x' - f'(z) z' = 0 on the
    stinger x = f(z) (b = 0: x' = 0 on the seabed). ``row`` gets its
    derivative d/du (global frame); an empty ``row``: the value alone."""
    ndn = 2 * nd + 1
    base = node * ndn
    want = row.shape[0] > 0
    if want:
        for i in range(row.shape[0]):
            row[i] = 0.0
        row[base + nd] = 1.0
    if b == 0:
        return u[base + nd]
    fpp = 2.0 * stinger[ST_A]
    fp = fpp * u[base + nd - 1] + stinger[ST_B]
    zp = u[base + 2 * nd - 1]
    if want:
        row[base + nd - 1] = -fpp * zp
        row[base + 2 * nd - 1] = -fp
    return u[base + nd] - fp * zp


@jit(by_dimension=True, _nrt=True)
def _free_moment(nd, s_el, u, model, torques, td_node, rate_b, row):
    """Touchdown's equation: the moment at touchdown on the free side, the
    residual [N m] of the first free element at the slope unknown of its lower
    node (on the seabed, its slope held), which vanishes with that moment as
    the continuum's does (the laid side carries none). It is the element's
    nodal residual, not the end moment of its cubic: that one converges an
    order slower, and the laid element's consistent-load couple would enter a
    node-equilibrium form of it (1.7 to 14 mm of touchdown on J125 at 4 m).
    ``row`` gets its derivative d/du; returns it and d/ds_T at fixed u."""
    ndn = 2 * nd + 1
    ne = 2 * ndn
    e = td_node
    fe = np.zeros(ne)
    ke = np.zeros((ne, ne))
    dfe = np.zeros(ne)
    want = row.shape[0] == u.shape[0]
    element_forces(nd, s_el[e], u[e * ndn:e * ndn + ne], model, torques[e], fe, ke,
                   want, dfe, want, np.empty(WORK_SIZE), np.empty((3, 3)))
    if not want:
        return fe[nd], 0.0
    for i in range(row.shape[0]):
        row[i] = 0.0
    for j in range(ne):
        row[e * ndn + j] = ke[nd, j]
    return fe[nd], (rate_b[e + 1] - rate_b[e]) * dfe[nd]


@jit(_nrt=False)
def _bnd_scale(b, fref, href):
    """The scale of boundary b's equation: a moment (touchdown), a slope
    (lift-off), a length (a point's)."""
    if b == B_TD:
        return fref * href
    return 1.0 if b == B_LO else href


@jit(_nrt=False)
def _point_gap(nd, u, point, node, phi):
    """Clearance [m] of node ``node`` from the rigid point ``point`` (a row of
    ``sup.points``) along the normal of a frame turned by ``phi`` (the pipe's,
    see :func:`_over_point`)."""
    base = node * (2 * nd + 1)
    return (math.cos(phi) * (u[base] - point[L.PT_X])
            - math.sin(phi) * (u[base + nd - 1] - point[L.PT_Z]))


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
    """The equation of boundary b >= B_LO at its node: lift-off's tangency
    (:func:`_tangency`) or a point's (:func:`_over_point`); ``row`` gets its
    derivative d/du. (Touchdown's, a moment, comes from :func:`_evaluate`.)"""
    if b == B_LO:
        return _tangency(nd, u, sup.stinger, b, node, row)
    return _over_point(nd, u, sup.points[b - B_PT], node, row)


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
    (:func:`.element.hermite`, ``sh`` (3, 4) its scratch), linear in lambda."""
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
def _take_step(nd, alpha, u, u_old, du, stinger, st_active, tb, tb_old, dtb, has_bnd, mesh, w):
    """The state a fraction ``alpha`` along the Newton step: nodal unknowns
    (stinger contacts along their curve), bottom tension and boundary arc
    lengths (from ``w.bnd_old`` by ``w.d_bnd``) with the element lengths they give.

    A node that the stinger's boundaries (lift-off or re-contact, the tip's
    point) move along the pipe by sigma is carried along the pipe's present
    curve: it takes the curve's values at its new material point
    (:func:`_pipe_at`), plus the Newton step's increment less the part of
    it that this transport makes to first order (the curve's derivative at
    the node, on the side it moves to, times sigma). To first order this is
    the Newton step; beyond it the pipe keeps its strains where the mesh
    slides along it, instead of being
    stretched between nodes held in place (its axial stiffness EA, some 1e4
    times the tension, made that stretch the largest residual after a long
    step of re-contact). Touchdown's zone is not carried: where touchdown
    moves, suspended pipe comes to lie on the seabed (carried, J125 took 21
    iterations instead of 6)."""
    ndn = 2 * nd + 1
    nn = st_active.shape[0]
    for i in range(u.shape[0]):
        u[i] = u_old[i] + alpha * du[i]
    if has_bnd:
        for node in range(nn):
            rate = 0.0
            for b in range(B_LO, mesh.s_b.shape[0]):
                rate += mesh.s_b[b, node] * w.d_bnd[b]
            if rate == 0.0:
                continue
            if rate > 0.0:
                _pipe_at(nd, u_old, w.s_old, node, 0.0, w.sh, w.at, w.at_rate)
            else:
                _pipe_at(nd, u_old, w.s_old, node - 1, 1.0, w.sh, w.at, w.at_rate)
            e, xi = _element_at(w.s_old, node, w.s_old[node] + alpha * rate)
            _pipe_at(nd, u_old, w.s_old, e, xi, w.sh, w.at, w.at_scratch)
            base = node * ndn
            for i in range(ndn):
                u[base + i] += w.at[i] - u_old[base + i] - alpha * w.at_rate[i] * rate
    _onto_curve(nd, u, u_old, du, alpha, stinger, st_active)
    tb[0] = tb_old + alpha * dtb
    if has_bnd:
        for b in range(mesh.s_bd.shape[0]):
            mesh.s_bd[b] = w.bnd_old[b] + alpha * w.d_bnd[b]
        mesh_lengths(mesh.s_a, mesh.s_b, mesh.s_bd, mesh.s_el)


# ---- the iteration's phases ---------------------------------------------------
# the Newton kernel (:func:`_newton_kernel`) runs them in order each
# iteration, each over the named tuples (:mod:`.types`) and the work arrays
# (:data:`Work`): a kernel of its own, or a phase inlined into it.

Work = namedtuple("Work", [
    "ab", "ab0", "ipiv", "g", "g_trial", "d", "delta", "cmask", "du", "du_free", "u_old",
    "scale", "torques", "rows", "cols", "res_b", "d_b", "kind", "dz", "sm", "rh",
    "bcols", "res_bnd", "d_top", "d_bnd", "bnd_old", "s_nd", "fr_out",
    "no_row", "no_ab", "row_td", "own_td", "s_old", "at", "at_rate", "at_scratch", "sh",
    "fr_stop", "rhs"])


@phase
def _work(nd, n, nn, nel, nbnd, props, href):
    """The iteration's work arrays, allocated once per call (:data:`Work`);
    ``nbnd`` boundaries, so 1 + nbnd bordered unknowns at most. The border's
    rows and columns, the boundaries' columns and the multi-RHS block are
    written before they are read (left unzeroed: on a roller stinger's 26
    boundaries, 0.5 MB a call)."""
    ndn = 2 * nd + 1
    n_border = 1 + nbnd
    kl = 2 * ndn - 1
    rows_ab = 3 * kl + 1
    scale = np.empty(n)  # per unknown: lengths 1, slopes href, multipliers EI / href^2
    for i in range(n):
        slot = i % ndn
        if slot < nd:
            scale[i] = 1.0
        elif slot < 2 * nd:
            scale[i] = href
        else:
            scale[i] = props[L.EI] / (href * href)
    return Work(
        np.zeros((n, rows_ab)).T, np.zeros((n, rows_ab)).T, np.zeros(n, dtype=np.int64),
        np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n, dtype=np.bool_),
        np.zeros(n), np.zeros(n), np.zeros(n), scale, np.full(nel, props[L.TORQUE]),
        np.empty((n_border, n)), np.empty((n_border, n)),
        np.zeros(n_border), np.zeros((n_border, n_border)), np.zeros(n_border, dtype=np.int64),
        np.zeros(n_border), np.zeros((n_border, n_border)), np.zeros(n_border),
        np.empty((nbnd, n)), np.zeros(nbnd), np.zeros(nbnd),
        np.zeros(nbnd), np.zeros(nbnd), np.zeros(nn), np.zeros(n), np.zeros(0),
        np.zeros((1, 1)).T, np.zeros(n), np.zeros(1), np.zeros(nn), np.zeros(ndn),
        np.zeros(ndn), np.zeros(ndn), np.zeros((3, 4)), np.zeros(nn),
        np.empty((n, 1 + n_border)))


@phase
def _solves_tb(ends):
    """True when the bottom tension is an unknown (the top tension given)."""
    return ends.top_target > 0.0 and ends.slide_dof >= 0


@phase
def _evaluate(nd, u, mesh, model, sup, ends, w, g, want_tangent):
    """Phase 1, every term that needs the element kernel: the residual ``g``
    (global frame) with the friction springs and, with ``want_tangent``, the
    tangent ``w.ab``, the top tension's row ``w.d``, each boundary's column
    dG/ds_b (``w.bcols``, with its top-tension rate ``w.d_top``) and
    touchdown's row (``w.row_td``, ``w.own_td``). The line search calls it
    for its trial states without the tangent.

    (The one phase that calls the element kernel's callers: numba optimises
    each kernel with all its callees linked in, so a kernel of its own above
    the element's adds the element's compile time again. The phases are
    inlined into the Newton kernel (:func:`_newton_kernel`,
    :func:`pipelay_fast.kernels._jit.phase`), and this keeps the element's callers in
    one place.)

    Returns (the top's effective tension [N], touchdown's equation [N m])."""
    ndn = 2 * nd + 1
    kl = 2 * ndn - 1
    bnodes = mesh.bnodes
    ab = w.ab if want_tangent else w.no_ab
    _system(nd, mesh.s_el, u, model, w.torques, ab, kl, kl, g, ends, want_tangent, mesh.s_b,
            bnodes, w.bcols)
    node_arcs(mesh.s_el, w.s_nd)
    friction_forces(nd, u, g, ab, 2 * kl if want_tangent else 0, model, sup.bed_active,
                    sup.fric, w.fr_out, w.s_nd)
    te_top = 0.0
    if _solves_tb(ends):
        if want_tangent:
            te_top = _top_tension_row(nd, w.ab, kl, kl, g, u, ends.top_node, w.d)
        else:
            te_top = _top_te(nd, g, u, ends.top_node)
    if want_tangent:
        for b in range(bnodes.shape[0]):
            if bnodes[b] >= 0:
                # the springs' anchors are read at material points, which move
                # with the boundary too (:func:`.contact.anchor_at`)
                friction_length_derivative(nd, u, g, model, sup.bed_active, sup.fric, w.s_nd,
                                           mesh.s_b[b], w.bcols[b])
                w.d_top[b] = _top_te(nd, w.bcols[b], u, ends.top_node)
    m_td = 0.0
    if bnodes[B_TD] >= 0:
        row = w.row_td if want_tangent else w.no_row
        m_td, own = _free_moment(nd, mesh.s_el, u, model, w.torques, bnodes[B_TD],
                                 mesh.s_b[B_TD], row)
        if want_tangent:
            w.own_td[0] = own
    return te_top, m_td


@phase
def _nodal_frames(nd, u, mesh, sup, ends):
    """The nodal frames of the iteration: none on the stinger's contacts (they
    are in curve coordinates) and, over each rigid point, the pipe's (normal,
    tangent)."""
    ndn = 2 * nd + 1
    nn = sup.phi_r.shape[0]
    if sup.stinger[ST_ON] != 0.0:
        for node in range(1, nn):
            if node != ends.top_node:
                sup.phi_r[node] = 0.0
                sup.phi_rp[node] = 0.0
    for b in range(B_PT, mesh.bnodes.shape[0]):
        kt = mesh.bnodes[b]
        if kt >= 0:
            base = kt * ndn
            sup.phi_r[kt] = math.atan2(u[base + nd], u[base + 2 * nd - 1])


@jit(_nrt=False)
def _frame_turn(nd, ab, kl, g, u, mesh, sup):
    """The frame over a rigid point is the pipe's, phi = atan2(x', z')
    (:func:`_nodal_frames`), and turns with r': its rows (normal n . G,
    tangent t . G, ``g`` already in that frame) carry d/dphi = (-G_t, G_n)
    times dphi/dr' (the normal's reaction G_n turns into the tangent's row)."""
    ndn = 2 * nd + 1
    kv = 2 * kl
    for b in range(B_PT, mesh.bnodes.shape[0]):
        kt = mesh.bnodes[b]
        if kt < 0:
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


@phase
def _to_nodal_system(nd, u, mesh, sup, ends, w, te_top, m_td):
    """Phase 2: the linear system in the nodal frames (stinger contacts in
    curve coordinates) and the bordered unknowns (:func:`_border`).
    Returns (the border unknowns, those of them other than the boundaries)."""
    kl = 4 * nd + 1
    _rotate_all(nd, w.ab, kl, kl, w.g, sup.phi_r, sup.phi_rp, True)
    _frame_turn(nd, w.ab, kl, w.g, u, mesh, sup)
    _curve_all(nd, w.ab, kl, kl, w.g, u, sup.stinger, sup.st_active, True)
    w.res_bnd[0] = m_td
    return _border(nd, u, mesh, sup, ends, w, te_top)


@phase
def _to_nodal_residual(nd, u, mesh, sup, w, m_td):
    """Phase 2 without the tangent: the residual in the nodal frames and the
    boundaries' equations (:func:`_border`'s residuals), for an iteration
    that only tests convergence."""
    _to_nodal_frames(nd, w.g, u, sup, w)
    w.res_bnd[0] = m_td
    for b in range(B_LO, mesh.bnodes.shape[0]):
        if mesh.bnodes[b] >= 0:
            w.res_bnd[b] = _bnd_equation(nd, u, sup, b, mesh.bnodes[b], w.no_row)


@jit(_nrt=False)
def _to_nodal_frames(nd, v, u, sup, w):
    """A global-frame row or column into the nodal frames and curve
    coordinates. (A kernel: it has five callers.)"""
    kl = 4 * nd + 1
    _rotate_all(nd, w.no_ab, kl, kl, v, sup.phi_r, sup.phi_rp, False)
    _curve_all(nd, w.no_ab, kl, kl, v, u, sup.stinger, sup.st_active, False)


@phase
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
            d_own = w.own_td[0]
        else:
            w.res_bnd[b] = _bnd_equation(nd, u, sup, b, node, w.rows[nb])
        _to_nodal_frames(nd, w.cols[nb], u, sup, w)
        _to_nodal_frames(nd, w.rows[nb], u, sup, w)
        w.res_b[nb] = w.res_bnd[b]
        # the earlier border equations by s_b at fixed u: the top tension
        for j in range(nb):
            if w.kind[j] == 0:
                w.d_b[j, nb] = w.d_top[b]
        w.d_b[nb, nb] = d_own
        w.kind[nb] = 2 + b
        nb += 1
    return nb, nb_fixed


@phase
def _constraint_set(nd, u, mesh, sup, ends, w, href):
    """Phase 3: the constrained unknowns (``w.cmask``) and their prescribed
    increments (``w.delta``, nodal frames): fixed ends, the seabed contacts
    (on it and tangent), the stinger contacts (on the curve and tangent, but
    lift-off's slope, which its equation closes), the lateral hold, the node
    over each rigid point that bears. Returns the largest violation [href, rad]."""
    ndn = 2 * nd + 1
    nn = sup.phi_r.shape[0]
    n = u.shape[0]
    fix_mask = sup.fix_mask
    stinger = sup.stinger
    has_stinger = stinger[ST_ON] != 0.0
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
        if sup.bed_active[node] != 0 and fix_mask[base] == 0:
            w.cmask[base] = True
            w.delta[base] = -_local_value(nd, u, node, 0, sup.phi_r, sup.phi_rp)
        # a pipe lying on the flat seabed is tangent to it: the slope is held
        # at every contact node, touchdown's included, and at the lower end
        # (resting on a rigid seabed, or on an elastic one's foundation)
        on_bed = sup.bed_active[node] != 0 or node == 0
        if on_bed and fix_mask[base + nd] == 0:
            w.cmask[base + nd] = True
            w.delta[base + nd] = -u[base + nd]
        if has_stinger and node != ends.top_node and fix_mask[base] == 0:
            x_n = u[base]
            z_n = u[base + nd - 1]
            if sup.st_active[node] != 0:
                # on the stinger: on the curve, and tangent to it except at
                # lift-off (the contact node with free pipe below it), whose
                # tangency is lift-off's equation
                fp = 2.0 * stinger[ST_A] * z_n + stinger[ST_B]
                w.cmask[base] = True
                w.delta[base] = -(x_n - ((stinger[ST_A] * z_n + stinger[ST_B]) * z_n
                                         + stinger[ST_C]))
                if node > 0 and sup.st_active[node - 1] != 0:
                    w.cmask[base + nd] = True
                    w.delta[base + nd] = -(u[base + nd] - fp * u[base + 2 * nd - 1])
            if sup.y_held[node]:  # on the stinger's plane and tangent to it
                w.cmask[base + 1] = True
                w.delta[base + 1] = -u[base + 1]
                w.cmask[base + nd + 1] = True
                w.delta[base + nd + 1] = -u[base + nd + 1]
    for b in range(B_PT, mesh.bnodes.shape[0]):
        kt = mesh.bnodes[b]
        point = sup.points[b - B_PT]
        if kt >= 0 and point[L.PT_BEAR] != 0.0:
            # bearing on a point: the node on it along the pipe's normal
            w.cmask[kt * ndn] = True
            w.delta[kt * ndn] = -_point_gap(nd, u, point, kt, sup.phi_r[kt])
            if nd == 3 and point[L.PT_HOLD] != 0.0:  # a V roller: laterally too
                w.cmask[kt * ndn + 1] = True
                w.delta[kt * ndn + 1] = -u[kt * ndn + 1]
    max_delta = 0.0
    for i in range(n):
        lim = href if i % ndn < nd else 1.0
        if w.cmask[i] and abs(w.delta[i]) / lim > max_delta:
            max_delta = abs(w.delta[i]) / lim
    return max_delta


@phase
def _imbalance(nd, mesh, ends, w, settings, te_top):
    """The residuals convergence is judged on: (weighted max and sum of
    squares of the free rows, the top tension's relative residual, the
    boundaries' largest scaled residual)."""
    res_max, res_ssq = _weighted_max(nd, w.g, w.cmask, settings.fref, settings.href)
    top_res = 0.0
    if _solves_tb(ends):
        top_res = abs(te_top - ends.top_target) / ends.top_target
    bnd_res = 0.0
    for b in range(mesh.bnodes.shape[0]):
        if mesh.bnodes[b] >= 0:
            bnd_res = max(bnd_res, abs(w.res_bnd[b]) / _bnd_scale(b, settings.fref,
                                                                  settings.href))
    return res_max, res_ssq, top_res, bnd_res


@phase
def _roundoff_ratio(nd, u, w):
    """How far the free rows' residual is above its round-off floor: the
    largest |G_i| / (eps sum_j |K_ij| |u_j|) (``w.ab``: the tangent, nodal
    frames, before scaling). The sum is what perturbing each unknown by its
    own round-off, eps |u_j|, changes G_i by: a residual within a small
    multiple of it is as small as a state held in float64 can make it (it
    grows like EI |r| eps / h^3: fine meshes far from the origin)."""
    kl = 4 * nd + 1
    kv = 2 * kl
    n = u.shape[0]
    worst = 0.0
    for i in range(n):
        if w.cmask[i] or w.g[i] == 0.0:
            continue
        acc = 0.0
        for j in range(max(0, i - kl), min(n - 1, i + kl) + 1):
            acc += abs(w.ab[kv + i - j, j] * u[j])
        ratio = abs(w.g[i]) / (2.2e-16 * acc) if acc > 0.0 else np.inf
        if ratio > worst:
            worst = ratio
    return worst


@phase
def _hold_boundaries(nd, u, mesh, sup, w, settings, bnd_res):
    """Phase 4: whether this iteration holds the boundaries where they are.

    A step of the boundaries from a state out of equilibrium (u not yet in
    balance on the present mesh) follows a linearisation that may point the
    wrong way (re-contact above a bearing tip ran away from a guess one
    flexural length off). Until the pipe is nearer equilibrium, with the
    boundaries where they are, than the boundaries are to theirs
    (INNER_RATIO), the step holds them, lift-off's node tangent to the
    stinger; from equilibrium the bordered step is the reduced Newton step of
    the boundaries' own equations. Touchdown alone moves with the pipe (J125
    with 20 kN at the bottom took 16 iterations held so, 12 without). After
    a step that moved the boundaries and lowered the merit the call does not
    hold them again (the Newton kernel skips this test): near equilibrium it
    alternated held and unheld steps, and the residual fell by only 10 to 20
    times an iteration (S67 2D, a warm start's last 4 iterations: 1e-4,
    9e-6, 4e-7, 1e-8); unheld, it falls quadratically. Nor does a call that
    starts from a state in balance (``settings.hold`` False: the pass to the
    tolerance after the loose one, on the same mesh or on one graded anew,
    the state interpolated): there the held first step only cost an
    iteration (S67 2D warm: 1.1e-4 held to 8e-5, then 8.8e-6, 1e-8; not
    held, 8.8e-6 after the first)."""
    if mesh.bnodes[B_LO] < 0:
        return False
    ndn = 2 * nd + 1
    j_lo = mesh.bnodes[B_LO] * ndn + nd  # lift-off's slope
    # the boundaries' own imbalance: their equations, and the moment on
    # lift-off's slope that its tangency would hold
    own = max(bnd_res, abs(w.g[j_lo]) / (settings.fref * settings.href))
    keep = w.cmask[j_lo]
    w.cmask[j_lo] = True  # as held: lift-off's slope constrained
    res_eq, _rs = _weighted_max(nd, w.g, w.cmask, settings.fref, settings.href)
    if res_eq > INNER_RATIO * own:
        w.delta[j_lo] = -_tangency(nd, u, sup.stinger, B_LO, mesh.bnodes[B_LO], w.no_row)
        return True
    w.cmask[j_lo] = keep
    return False


@phase
def _condensed_solve(nd, w, nb):
    """Phase 5: the Newton step by condensation and the bordered solve.

    The system is scaled (``w.scale``: lengths, slopes, multipliers), every
    constrained unknown gets its prescribed increment (K_ff du_f = -G_f - K_fc
    du_c), the band is factored once, and the nb border unknowns are
    eliminated by a dense Schur complement: du = y0 - sum_j dz_j Y_j with S dz
    = rows . y0 + res. Leaves the scaled step in ``w.du``, the border steps in
    ``w.dz`` and the unscaled tangent in ``w.ab0``. False when singular."""
    ndn = 2 * nd + 1
    kl = 2 * ndn - 1
    ku = kl
    kv = kl + ku
    n = w.g.shape[0]
    ab = w.ab
    scale = w.scale
    cmask = w.cmask
    du = w.du
    for j in range(n):
        sj = scale[j]
        for r in range(max(0, j - ku), min(n - 1, j + kl) + 1):
            ab[kv + r - j, j] *= scale[r] * sj
    for j in range(ab.shape[1]):
        for i in range(ab.shape[0]):
            w.ab0[i, j] = ab[i, j]
    for i in range(n):
        du[i] = -w.g[i] * scale[i]
    for j in range(n):
        if not cmask[j]:
            continue
        dj = w.delta[j] / scale[j]
        for r in range(max(0, j - ku), min(n - 1, j + kl) + 1):
            if not cmask[r]:
                du[r] -= ab[kv + r - j, j] * dj
    for j in range(n):
        if not cmask[j]:
            continue
        for r in range(max(0, j - ku), min(n - 1, j + kl) + 1):
            ab[kv + r - j, j] = 0.0
        for c in range(max(0, j - kl), min(n - 1, j + ku) + 1):
            ab[kv + j - c, c] = 0.0
        ab[kv, j] = 1.0
        du[j] = w.delta[j] / scale[j]
    if band_factor(ab, kl, ku, w.ipiv) != 0:
        return False
    # the step and the border columns solved together, the band read once
    # (column 0 the step y0, column 1 + j the border column Y_j)
    rhs = w.rhs
    for i in range(n):
        rhs[i, 0] = du[i]
        for j in range(nb):
            rhs[i, 1 + j] = 0.0 if cmask[i] else w.cols[j, i] * scale[i]
    band_solve_many(ab, kl, ku, w.ipiv, rhs, 1 + nb)
    for i in range(n):
        du[i] = rhs[i, 0]
    # border equations res + rows . du + d_b dz = 0 with du = y0 - Y dz; each
    # row is local (a node's, an element's, the top's): the products run
    # over its nonzero span (with 26 rollers on 645 unknowns they were half
    # of an iteration)
    for i2 in range(nb):
        lo = 0
        while lo < n and w.rows[i2, lo] == 0.0:
            lo += 1
        hi = n
        while hi > lo and w.rows[i2, hi - 1] == 0.0:
            hi -= 1
        acc = 0.0
        for k in range(lo, hi):
            acc += w.rows[i2, k] * scale[k] * du[k]
        w.rh[i2] = acc + w.res_b[i2]
        for j in range(nb):
            acc = 0.0
            for k in range(lo, hi):
                acc += w.rows[i2, k] * scale[k] * rhs[k, 1 + j]
            w.sm[i2, j] = acc - w.d_b[i2, j]
    if nb > 0 and not _solve_dense(nb, w.sm, w.rh, w.dz):
        return False
    for j in range(nb):
        for i in range(n):
            du[i] -= w.dz[j] * rhs[i, 1 + j]
    return True


@phase
def _border_steps(w, nb):
    """The bottom tension's step [N] (returned) and the boundaries' (``w.d_bnd``, m)."""
    dtb = 0.0
    w.d_bnd[:] = 0.0
    for j in range(nb):
        if w.kind[j] == 0:
            dtb = w.dz[j]
        else:
            w.d_bnd[w.kind[j] - 2] = w.dz[j]
    return dtb


@phase
def _reactions(nd, w, nb, react):
    """Phase 6: the linearised reactions on the constrained rows, R_c = G_c +
    K_cf du_f + K_cc du_c + the border columns' share, in physical units."""
    ndn = 2 * nd + 1
    kl = 2 * ndn - 1
    kv = 2 * kl
    n = w.g.shape[0]
    for i in range(n):
        react[i] = 0.0
    for i in range(n):
        if not w.cmask[i]:
            continue
        acc = 0.0
        for j in range(max(0, i - kl), min(n - 1, i + kl) + 1):
            acc += w.ab0[kv + i - j, j] * w.du[j]
        react[i] = w.g[i] + acc / w.scale[i]
        for j in range(nb):
            react[i] += w.cols[j, i] * w.dz[j]


@phase
def _step_length(nd, u, mesh, sup, w, hold, href, bstep):
    """Phase 7: the longest fraction of the step the contact boundaries allow,
    and the status that stops the call (-1: none).

    A boundary stays inside its zone (no element there shrinks below a
    tenth), moves at most ``bstep`` [m]; touchdown stays on the
    modelled laid pipe (SHORT_LAID past half way to the lower end); the span
    between re-contact and a bearing tip at most halves or doubles (it grows
    like sqrt(a - a_switch) past the change of regime: a step in its
    logarithm follows that), SPAN_CLOSED when there is no bearing solution;
    a step that would take lift-off past the tip returns PAST_TIP with the
    fraction that takes it to the tip (0 when it is there already), which
    the Newton kernel takes before it stops. Stopping half way, the approach
    halved the distance a step (a warm start across the change of regime,
    S125 2D at 2 m from a = -0.0018 to -0.00165, took 15 iterations to
    reach the tip); stopping at the tip and going on from there cost two
    iterations more than stopping at once (a held one to balance the pipe
    there, then the step past it: full 2D grid, S125 at 8 m: 1174 -> 1158
    iterations, solves above 10: 12 -> 6)."""
    ndn = 2 * nd + 1
    nn = sup.phi_r.shape[0]
    bnodes = mesh.bnodes
    s_b = mesh.s_b
    s_bd = mesh.s_bd
    s_el = mesh.s_el
    d_bnd = w.d_bnd
    nbnd = bnodes.shape[0]
    has_td = bnodes[B_TD] >= 0
    has_lo = bnodes[B_LO] >= 0
    # the tip: the first rigid point, where the stinger's curve ends
    has_tipn = nbnd > B_PT and bnodes[B_PT] >= 0
    alpha = 1.0
    if _has_boundaries(mesh):
        for e in range(nn - 1):
            rate = 0.0
            for b in range(nbnd):
                rate += (s_b[b, e + 1] - s_b[b, e]) * d_bnd[b]
            if rate < -0.9 * s_el[e]:
                alpha = min(alpha, 0.9 * s_el[e] / abs(rate))
    for b in range(nbnd):
        if abs(d_bnd[b]) * alpha > bstep:
            alpha = bstep / abs(d_bnd[b])
    if has_td and not hold and d_bnd[B_TD] < 0.0:
        if -d_bnd[B_TD] * alpha > 0.5 * (s_bd[B_TD] - mesh.s_a[0]):
            return alpha, L.SHORT_LAID
    if has_lo and has_tipn and not hold:
        gap_s = s_bd[B_LO] - s_bd[B_PT]
        d_gap_s = (d_bnd[B_LO] - d_bnd[B_PT]) * alpha
        if d_gap_s < -0.5 * gap_s:
            if gap_s < href and sup.points[0, L.PT_BEAR] != 0.0:
                # Bearing, the span's square goes like a - a_switch: from
                # d0 Newton asks d0 / 2 + (a - a_switch) / (2 k d0), so a
                # step that more than halves the span says there is no
                # bearing solution (d = 0 is then the bearing equations'
                # limit, which Newton approaches only linearly). Once the
                # span is shorter than an element the two regimes differ
                # by less than the mesh resolves: the pipe lifts off
                # above the tip.
                return alpha, L.SPAN_CLOSED
            alpha *= 0.5 * gap_s / -d_gap_s
        elif d_gap_s > gap_s:
            alpha *= gap_s / d_gap_s
    if has_lo and not hold:
        # lift-off stays above the tip (the curve continued past it is no
        # support)
        base = bnodes[B_LO] * ndn
        room = u[base + nd - 1] - sup.stinger[ST_ZL]
        dz_lo = w.du_free[base + nd - 1]  # the node's own z slides it along the curve
        if room < 1e-3 * href and dz_lo < 0.0:
            return 0.0, L.PAST_TIP
        if dz_lo * alpha < -room:
            if room > 0.0:  # from above the tip, the step would take it past
                return room / -dz_lo, L.PAST_TIP
            alpha = room / -dz_lo  # from below the tip, rising: up to it
    return alpha, -1


@phase
def _trial_merit(nd, u, mesh, sup, ends, w, settings, hold, te_top, m_td):
    """The merit at a trial state (its residual in ``w.g_trial`` from
    :func:`_evaluate`): the sum of squared weighted residuals, the top
    tension's and the boundaries' equations (unless held)."""
    bnodes = mesh.bnodes
    fref = settings.fref
    href = settings.href
    tr = 0.0
    if _solves_tb(ends):
        tr = (te_top - ends.top_target) / ends.top_target
    tdr = 0.0
    if bnodes[B_TD] >= 0 and not hold:
        tdr += (m_td / (fref * href)) ** 2
    for b in range(B_LO, bnodes.shape[0]):
        if bnodes[b] >= 0 and not hold:
            tdr += (_bnd_equation(nd, u, sup, b, bnodes[b], w.no_row)
                    / _bnd_scale(b, fref, href)) ** 2
    _to_nodal_frames(nd, w.g_trial, u, sup, w)
    _rm, rs = _weighted_max(nd, w.g_trial, w.cmask, fref, href)
    return rs + tr * tr + tdr


@phase
def _accepts(m1, merit0, alpha, tol, mesh, hold):
    """Phase 8's test: whether the line search takes the trial step.

    With the boundaries unknowns the (limited) full step is taken: the
    weighted residual rises across good steps there, as the element lengths
    move with the boundaries (cut by Armijo to 1/8 .. 1/32 on S67 and S125,
    2 to 5 times the iterations, and some cases never converged); a
    diverging step is caught by the iteration's checks. A step of the
    stinger's boundaries from equilibrium (not held) is taken as limited: the
    merit there rises by up to 1e7 across good steps (the short elements of a
    closing gap span); cut, the span crept by 6 % a step (S125 2D, full grid:
    at most 82 iterations at 4 m and 344 at 1 m; taken so, 42 and 58)."""
    has_bnd = _has_boundaries(mesh)
    has_lo = mesh.bnodes[B_LO] >= 0
    return (m1 <= (1.0 - 1e-4 * alpha) * merit0 or merit0 < tol * tol or m1 < 1e-300
            or (has_bnd and m1 <= MERIT_RISE * merit0) or (has_lo and not hold and m1 < 1e300))


@jit(by_dimension=True, _nrt=False)
def _trial(nd, alpha, u, mesh, model, sup, ends, w, settings, hold, dtb, tb_old, has_bnd):
    """The state a fraction ``alpha`` along the step (:func:`_take_step`,
    from ``w.u_old`` and the bottom tension ``tb_old``) and its merit
    (:func:`_trial_merit`). (A kernel, not a phase: called from two places,
    inlined it put :func:`_evaluate` into the Newton kernel three times;
    first S67 solve 35.2 -> 33.2 s.)"""
    _take_step(nd, alpha, u, w.u_old, w.du_free, sup.stinger, sup.st_active, ends.tb,
               tb_old, dtb, has_bnd, mesh, w)
    te_t, m_t = _evaluate(nd, u, mesh, model, sup, ends, w, w.g_trial, False)
    return _trial_merit(nd, u, mesh, sup, ends, w, settings, hold, te_t, m_t)


@phase
def _past_friction_cut(nd, u, mesh, model, sup, ends, w, settings, hold, dtb, alpha, alpha_lim):
    """Phase 7b: the step fraction, from ``alpha`` (where :func:`friction_step`
    cut the limited step ``alpha_lim`` at a spring's stick zone) doubled
    towards ``alpha_lim`` while the merit falls; the lowest-merit trial is
    returned, and if it lies past the cut, no spring is flagged as stopped
    (``w.fr_stop``). A laid pipe sliding as a whole has its whole length
    carried back past the anchors by Newton (its lateral stiffness then the
    span's alone): stopped at the first spring's zone, it moved 1 to 2 % of
    the step an iteration (random J-lay 02, 1837 m, slip 571 m: 100
    iterations a current step; the doubled trials 30 to 50). The state is
    left at the last trial (phase 8 takes the step from ``w.u_old``), the
    bottom tension restored."""
    has_bnd = _has_boundaries(mesh)
    tb_old = ends.tb[0]
    best = alpha
    m_best = np.inf
    trial = alpha
    while True:
        m1 = _trial(nd, trial, u, mesh, model, sup, ends, w, settings, hold, dtb, tb_old, has_bnd)
        if m1 < m_best:
            m_best, best = m1, trial
        elif trial > alpha:
            break
        if trial >= alpha_lim:
            break
        trial = min(2.0 * trial, alpha_lim)
    ends.tb[0] = tb_old
    if best > alpha:
        w.fr_stop[:] = 0.0
    return best


@phase
def _points_update(nd, u, mesh, sup, react, settings):
    """Phase 9: each rigid point's contact by the complementarity
    min(R, c g) = 0 (semismooth Newton: the branch that the present normal
    reaction R and gap g select): it bears when R - c g > 0, its node then
    held on it, else R = 0. Returns how many branches changed."""
    ndn = 2 * nd + 1
    changes = 0
    for b in range(B_PT, mesh.bnodes.shape[0]):
        kt = mesh.bnodes[b]
        if kt < 0:
            continue
        point = sup.points[b - B_PT]
        bearing = point[L.PT_BEAR] != 0.0
        r_n = react[kt * ndn] if bearing else 0.0
        g_n = _point_gap(nd, u, point, kt, sup.phi_r[kt])
        bears = r_n - (settings.fref / settings.href) * g_n > 0.0
        point[L.PT_BEAR] = 1.0 if bears else 0.0
        point[L.PT_R] = r_n if bears else 0.0
        if bears != bearing:
            changes += 1
    return changes


@jit(entry=True, _nrt=False)
def system_2d(s_el, u, model, torques, ab, g, ends, want_tangent, s_b, bnodes, bcols):
    """:func:`_system` in the plane, from Python (kl = ku = 9)."""
    _system(2, s_el, u, model, torques, ab, 9, 9, g, ends, want_tangent, s_b, bnodes, bcols)


@jit(entry=True, _nrt=False)
def system_3d(s_el, u, model, torques, ab, g, ends, want_tangent, s_b, bnodes, bcols):
    """:func:`_system` in space, from Python (kl = ku = 13)."""
    _system(3, s_el, u, model, torques, ab, 13, 13, g, ends, want_tangent, s_b, bnodes, bcols)


def _newton_kernel(nd):
    """The Newton kernel for dimension ``nd``: :func:`newton_2d` and
    :func:`newton_3d` are its two compilations, ``nd`` a constant in each (a
    closure's constant cell: the literal that the phases and the element
    chain are compiled for, so a planar solve never compiles the spatial
    element). Written as a closure rather than inlined into two entries:
    numba copies an inlined function's whole scope once per block, and
    inlining this one cost 5.9 s of the first compile."""

    @jit(entry=True, _nrt=True)
    def newton(u, mesh, model, sup, ends, settings, react, info):
        """Solve G(u) = reactions for one load level; see the module docstring.
        Compiled as :func:`newton_2d` and :func:`newton_3d`, ``nd`` the
        enclosing :func:`_newton_kernel`'s constant.

        Parameters (arrays are float64 unless noted; ``ndof = nn * (2 nd + 1)``)
        ----------
        nd : 2 or 3 (not an argument: the closure's constant)
        u : (ndof,) nodal unknowns, global frame; updated in place
        mesh : :data:`.types.Mesh`, s_el (nel,) element lengths [m], updated with
            the boundaries; s_a (nn,), s_b (nbnd, nn) the map onto the boundaries'
            arc lengths s_bd (nbnd,) [m], updated; bnodes (nbnd,) int64, the
            boundaries' nodes (-1: none): touchdown, lift-off, then one per rigid
            point (``B_*``), nbnd = 2 + the points
        model : :data:`.types.Model`, props (N_PROPS,), the current table, factors
            (N_FACTORS,)
        sup : :data:`.types.Supports`
            fix_mask (ndof,) int8, 1 where the unknown (nodal frame) is prescribed;
            fix_val (ndof,) its value; phi_r, phi_rp (nn,) rotation angles of the
            nodal frames of r and r' [rad]; bed_active (nn,) int8, the seabed
            contacts (the lower end to touchdown); stinger (N_STINGER,) the curve
            x = a z^2 + b z + c on [zL, zU] (``ST_*``); st_active (nn,) int8, the
            stinger contacts (lift-off, or re-contact, to the top); points
            (n_points, N_PT) the rigid points (the stinger's tip first): position
            [m], bearing (0/1), normal reaction [N] (``L.PT_*``), updated; fric (nn, N_FRIC) the
            seabed friction springs (``FR_*``), anchors moved by the return
            mapping when the call converges; y_held (nn,) bool, output, the nodes
            the stinger holds laterally (3D), the converged set on OK
        ends : :data:`.types.Ends`
            f_node (ndof,) nodal loads [N]; g_off (ndof,) residual offset (load-path
            homotopy); tb (1,) bottom tension [N], an unknown when top_target > 0,
            pulling the sliding lower end's dof slide_dof (-1: none) along -z;
            top_node, top_target: the top's node and effective tension [N] (0: not
            given)
        settings : :data:`.types.Settings`, tol, fref [N], href [m], maxit, hold
            (whether an iteration may hold the boundaries, :func:`_hold_boundaries`:
            False when the call starts from a state in balance), bstep [m] (the
            largest move of a boundary per step)
        react : (ndof,) output, reactions on the pipe in the nodal frames [N, N m]
        info : (N_INFO,) output, see ``I_*``
        """
        ndn = 2 * nd + 1
        nn = sup.phi_r.shape[0]
        n = u.shape[0]
        nbnd = mesh.bnodes.shape[0]
        w = _work(nd, n, nn, mesh.s_el.shape[0], nbnd, model.props, settings.href)
        href = settings.href
        for k in range(N_INFO):
            info[k] = 0.0
        status = L.MAX_ITERATIONS
        changed = True
        if _has_boundaries(mesh):
            mesh_lengths(mesh.s_a, mesh.s_b, mesh.s_bd, mesh.s_el)
        res_change = np.inf  # the residual when the stinger's tip last changed branch
        it = 0
        last_step = np.inf  # the last step's largest move of a position [m]
        r_max = 0.0  # the largest position [m]
        res_start = 1.0
        moved = False  # the last step moved the boundaries and lowered the merit
        # the last step's trial was converged on its own frames and constraints:
        # the next iteration evaluates the residual alone first, and the tangent
        # only if that iteration is not converged after all
        trial_converged = False
        converged = False
        for it in range(1, settings.maxit + 1):
            tol = settings.tol
            want_tangent = not trial_converged
            while True:
                # the nodes the stinger holds laterally, those over it now: each
                # iteration's, so that a converged state is in balance with its own
                # hold (kept through the call and checked at convergence, a node
                # that slid over the tip's z cost another round of iterations: 47
                # times over 18 random S-lays, 1745 -> 1617 iterations in all)
                lateral_hold(nd, mesh.s_el, u, sup.stinger, ends.top_node, sup.fix_mask,
                             sup.y_held)
                _nodal_frames(nd, u, mesh, sup, ends)
                te_top, m_td = _evaluate(nd, u, mesh, model, sup, ends, w, w.g, want_tangent)
                if want_tangent:
                    nb, nb_fixed = _to_nodal_system(nd, u, mesh, sup, ends, w, te_top, m_td)
                else:
                    _to_nodal_residual(nd, u, mesh, sup, w, m_td)
                max_delta = _constraint_set(nd, u, mesh, sup, ends, w, href)
                res_max, res_ssq, top_res, bnd_res = _imbalance(nd, mesh, ends, w, settings,
                                                                te_top)
                # Converged: residual below the tolerance, or every free row at
                # its round-off floor (:func:`_roundoff_ratio`, which reads the
                # tangent; a fine mesh far from the origin cannot reach every
                # tolerance), or the Newton step stalled. (The stall's test
                # first: the floor's is a pass over the band.)
                at_roundoff = (it > 1 and res_max > tol
                               and ((last_step <= STALL_STEP * 2.2e-16 * (r_max + href)
                                     and res_max <= 1e-4)
                                    or (want_tangent
                                        and _roundoff_ratio(nd, u, w) <= ROUNDOFF_RATIO)))
                converged = (it > 1 and (res_max <= tol or at_roundoff) and max_delta <= tol
                             and (top_res <= tol or at_roundoff)
                             and (bnd_res <= tol or at_roundoff) and not changed)
                if want_tangent or converged or not (res_max < 1e300 and res_ssq < 1e300):
                    break
                want_tangent = True
            if not (res_max < 1e300 and res_ssq < 1e300):  # max() skips NaN; the sum does not
                status = L.NOT_FINITE
                break
            if it == 1:
                res_start = max(res_max, 1.0)
            elif res_max > RUNAWAY * res_start:
                status = L.NOT_FINITE  # diverging: stop before the budget is spent on it
                break
            info[I_RES] = res_max
            info[I_DELTA] = max_delta
            info[I_TOP_RES] = top_res
            if converged:
                status = L.OK
                it -= 1
                break
            hold = (settings.hold and not moved
                    and _hold_boundaries(nd, u, mesh, sup, w, settings, bnd_res))
            if hold:
                nb = nb_fixed
            if not _condensed_solve(nd, w, nb):
                status = L.SINGULAR
                break
            dtb = _border_steps(w, nb)
            _reactions(nd, w, nb, react)
            for i in range(n):
                w.du_free[i] = w.du[i] * w.scale[i]
            _to_global(nd, w.du_free, sup.phi_r, sup.phi_rp)
            for i in range(u.shape[0]):
                w.u_old[i] = u[i]
            merit0 = res_ssq + top_res * top_res
            for b in range(nbnd):
                if mesh.bnodes[b] >= 0 and not hold:
                    merit0 += (w.res_bnd[b] / _bnd_scale(b, settings.fref, href)) ** 2
                w.bnd_old[b] = mesh.s_bd[b]
            node_arcs(mesh.s_el, w.s_old)
            alpha, stop = _step_length(nd, u, mesh, sup, w, hold, href, settings.bstep)
            if stop >= 0:
                status = stop
                if stop == L.PAST_TIP:
                    # how far past the tip the step would take lift-off
                    # (bear_on_tip estimates the gap span from it); the part of
                    # the step up to the tip is taken
                    info[I_PAST] = abs(w.d_bnd[B_LO]) * (1.0 - alpha)
                    if alpha > 0.0:
                        _take_step(nd, alpha, u, w.u_old, w.du_free, sup.stinger, sup.st_active,
                                   ends.tb, ends.tb[0], dtb, _has_boundaries(mesh), mesh, w)
                break
            alpha_lim = alpha
            alpha = friction_step(nd, u, w.du_free, w.s_nd, model, sup.bed_active, sup.fric,
                                  w.fr_stop, alpha)
            if alpha < alpha_lim:
                alpha = _past_friction_cut(nd, u, mesh, model, sup, ends, w, settings, hold, dtb,
                                           alpha, alpha_lim)
            # ---- phase 8: backtracking from the limited step; where no trial is
            # accepted the limited step is taken anyway (the merit is flat: a
            # change of constraint, a constraint correction)
            has_bnd = _has_boundaries(mesh)
            tb_old = ends.tb[0]
            alpha0 = alpha
            accepted = False
            for _ls in range(12):
                m1 = _trial(nd, alpha, u, mesh, model, sup, ends, w, settings, hold, dtb, tb_old,
                            has_bnd)
                if _accepts(m1, merit0, alpha, settings.tol, mesh, hold):
                    accepted = True
                    break
                if not (m1 < 1e300) and alpha < 1e-3:
                    break
                alpha *= 0.5
            if not accepted:
                _take_step(nd, alpha0, u, w.u_old, w.du_free, sup.stinger, sup.st_active, ends.tb,
                           tb_old, dtb, has_bnd, mesh, w)
            # an unheld step that lowered the merit: the next one moves them too
            moved = not hold and accepted and m1 < merit0
            last_step = 0.0
            r_max = 0.0
            for i in range(n):
                if i % ndn < nd:
                    last_step = max(last_step, abs(u[i] - w.u_old[i]))
                    r_max = max(r_max, abs(u[i]))
            node_arcs(mesh.s_el, w.s_nd)
            friction_track(nd, u, react, model.props, sup.bed_active, sup.fric, w.s_nd)
            n_changed = _points_update(nd, u, mesh, sup, react, settings)
            changed = n_changed > 0
            trial_converged = accepted and not changed and m1 <= tol * tol
            if changed and sup.stinger[ST_ON] != 0.0:
                # the tip (the quadratic stinger's one point) changes branch
                # again with the residual no lower than at its last change:
                # the branches cycle with no bearing solution (warm from
                # bearing on the tip to lifting off above it, the branch
                # flipped every 3 iterations: S67 2D at 4 m, a = -0.0012 from
                # -0.00105, 48 iterations to 16 changes, the cap there was;
                # now 9, the whole solve 54 -> 14; quick bench warm 1026 ->
                # 898, the rest and the 2D grid's iterations, the S-lay
                # references at 0.25 m graded to 0.05 m, unchanged; the cap
                # no longer bound). A roller has no such other regime: its
                # branch settles as the pipe finds its balance (S67 2D,
                # rollers on the paper's curve every 1.5 to 12 m, 1 to 8 m
                # elements: 135 iterations over 16 solves; stopped at the
                # cycle, 173, the homotopy taking over)
                if res_max >= res_change:
                    status = L.TIP_CYCLE
                    break
                res_change = res_max
        if status == L.OK:
            # the friction forces join the reactions; slipping springs' anchors follow
            w.fr_out[:] = 0.0
            node_arcs(mesh.s_el, w.s_nd)
            for node in range(nn):  # the normal forces of the answer, for the results
                sup.fric[node, L.FR_W] = normal_force(nd, w.g, sup.bed_active, sup.fric, node)
            friction_forces(nd, u, w.g, w.no_ab, 0, model, sup.bed_active, sup.fric,
                            w.fr_out, w.s_nd)
            for i in range(n):
                react[i] += w.fr_out[i]
            friction_commit(nd, u, model, sup.bed_active, sup.fric, w.s_nd)
        if sup.stinger[ST_ON] != 0.0:
            _curve_reactions(nd, u, sup.stinger, sup.st_active, sup.phi_r, sup.phi_rp, react)
        info[I_STATUS] = status
        info[I_ITER] = it
        return status

    return newton


newton_2d = _newton_kernel(2)
newton_3d = _newton_kernel(3)

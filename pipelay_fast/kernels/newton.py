"""The Newton kernel: the iteration for one load level, with contact by
condensation (the paper's Sec. 3.2).

One kernel runs the whole iteration, so a solve crosses the Python/numba
boundary once per load step. Each iteration runs the phases of its modules
in order:

1. evaluate (:mod:`.system`): the residual G and tangent K in the nodal
   frames (stinger contacts in curve coordinates), the rows and columns of
   the bordered unknowns; the constraint set (:mod:`.constraints`); the
   test: converged when the weighted residual is below the tolerance (or at
   its round-off floor), the constraints and the
   boundaries' equations hold and no rigid point changed branch;
2. condense and solve (:mod:`.condensation`): every constrained unknown
   gets its increment prescribed, the free ones are solved from the band
   system, the bordered unknowns by a Schur complement, and the reactions
   are read back from the constrained rows;
3. step (:mod:`.step`): its limits, then a line search on the merit;
4. update the contacts: the friction springs' normal forces, the rigid
   points' branches by their complementarity (:mod:`.constraints`).

The bordered unknowns: the bottom tension T_b when the top tension is given
(its equation Te(top) = R_top . t_top - T_top = 0), and each contact
boundary that is an unknown (``mesh.bnodes[b] >= 0``: touchdown, lift-off,
the material point over each rigid point, :mod:`.layout` ``B_*``), closed by
its continuum condition (:mod:`.constraints`). The mesh follows the
boundaries (:func:`.constraints.mesh_lengths`): the contact stretches are
fixed sets of nodes, no node walks on or off a contact.

The boundaries move only from equilibrium: while the pipe is further from
balance, with the boundaries where they are, than the boundaries from
theirs, an iteration holds them (:func:`.step._hold_boundaries`).

The call stops early with a status code (:mod:`.layout`) that the caller
acts on: PAST_TIP (lift-off would pass the stinger's tip: the caller
switches to bearing on it), SPAN_CLOSED or TIP_CYCLE (bearing on the tip has
no solution: the caller switches to lifting off above it), SHORT_LAID
(touchdown would pass half way to the modelled lower end: the caller
prepends laid pipe), SINGULAR, NOT_FINITE. The kernel never raises.

Arguments of :func:`newton_2d` and :func:`newton_3d` (float64 arrays but
where noted; ``ndof = nn (2 nd + 1)``, nn nodes, nel = nn - 1 elements,
nbnd = 2 + the rigid points):

u : (ndof,) the nodal unknowns (:mod:`.layout`), global frame; updated.
mesh : :data:`.types.Mesh`: s_el (nel,) element lengths [m], updated with the
    boundaries; s_a (nn,) [m], s_b (nbnd, nn) [-], the map onto the
    boundaries' arc lengths s_bd (nbnd,) [m], updated; bnodes (nbnd,) int64,
    the boundaries' nodes (-1: not an unknown).
model : :data:`.types.Model`: props (N_PROPS,), the current table, factors
    (N_FACTORS,), section (nel, N_SECTION).
sup : :data:`.types.Supports`: fix_mask (ndof,) int8, 1 where the unknown
    (nodal frame) is prescribed, fix_val (ndof,) its value; phi_r, phi_rp (nn,)
    the nodal frames' angles for r and r' [rad], rewritten each iteration;
    the supports' table, row b boundary b's support (:mod:`.layout`
    ``SUP_*``, ``ROW_*``): kind (n_sup,) int64, geom (n_sup, N_GEOM) their
    parameters (the rigid points' branch and reaction updated), active
    (n_sup, nn) int8 the nodes each holds (the seabed's and the curve's
    contacts); fric (nn, N_FRIC) the friction springs (``FR_*``), anchors moved
    by the return mapping when the call converges; y_held (nn,) bool,
    output: the nodes the stinger holds laterally (3D), the converged set on
    OK.
ends : :data:`.types.Ends`: f_node (ndof,) nodal loads [N]; g_off (ndof,)
    the load path's residual offset; tb (1,) the bottom tension [N] pulling
    the sliding lower end's dof slide_dof (-1: none) back along the seabed
    (-z turned up by slide_angle [rad]), an unknown when top_target [N] > 0;
    top_node.
settings : :data:`.types.Settings`: tol [-], fref [N], href [m], maxit (0: no
    iteration, the residual alone: :func:`_free_residual` into ``react``), hold
    (whether an iteration may hold the boundaries: False when the call
    starts from a state in balance), bstep [m] (a boundary's largest move
    per step).
react : (ndof,) output: the reactions on the pipe in the nodal frames [N, N m]
    (with ``maxit`` 0: the residual, global frame [N, N m, m]).
info : (N_INFO,) output: ``I_*`` of :mod:`.layout`.

Returns the status code (also ``info[I_STATUS]``).
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from . import layout as L
from ._jit import jit, phase
from .assembly import element_work
from .condensation import _border_steps, _condensed_solve, _curve_reactions, _reactions
from .constraints import (
    _bnd_scale,
    _constraint_set,
    _has_boundaries,
    _nodal_frames,
    _points_update,
    mesh_lengths,
)
from .contact import (
    friction_commit,
    friction_forces,
    friction_track,
    lateral_hold,
    node_arcs,
    normal_force,
)
from .layout import (
    B_LO,
    I_DELTA,
    I_ITER,
    I_PAST,
    I_RES,
    I_STATUS,
    I_TOP_RES,
    I_TOP_TE,
    N_INFO,
    ROW_BED,
    ROW_CURVE,
    SUP_NONE,
)
from .scene import FRICTION, STINGER
from .step import _hold_boundaries, _line_search, _start_step, _take_step, at_tolerance
from .supports import in_curve_coords
from .system import (
    _evaluate,
    _from_nodal_frames,
    _rotate_all,
    _roundoff_ratio,
    _solves_tb,
    _to_nodal_residual,
    _to_nodal_system,
    _weighted_max,
)
from .tuning import ROUNDOFF_RATIO, RUNAWAY

Work = namedtuple("Work", [
    "ab", "ab0", "ipiv", "g", "g_trial", "d", "delta", "cmask", "du", "du_free", "u_old",
    "scale", "torques", "rows", "cols", "res_b", "d_b", "kind", "dz", "sm", "rh",
    "bcols", "res_bnd", "d_top", "d_bnd", "bnd_old", "s_nd", "fr_out",
    "no_row", "no_ab", "row_td", "own_td", "s_old", "at", "at_rate", "at_scratch", "sh",
    "fr_stop", "rhs", "ew"])
Work.__doc__ = """The Newton kernel's work arrays, allocated once per call (:func:`_work`).

Sizes: ndof unknowns, nn nodes, nel elements, nbnd boundaries, nbr = 1 + nbnd
bordered unknowns at most, kl = 4 nd + 1 the band's half-width, rows = 3 kl +
1 its storage (LAPACK's, room for the factors' fill-in). G's rows are forces
[N] (positions), moments [N m] (slopes) and lengths [m] (multipliers); the
bordered unknowns are the bottom tension [N] and the boundaries' arc
lengths [m]. "Nodal frames": after :func:`.system._to_nodal_system`.

ab : (rows, ndof) the tangent K in band storage: global frame from
    :func:`.system._evaluate` (the element chain, friction springs, read by
    ``_top_tension_row``), nodal frames from ``_to_nodal_system``; read by
    ``_roundoff_ratio``; scaled, condensed and factored in place by
    :func:`.condensation._condensed_solve`.
ab0 : (rows, ndof) the scaled tangent before condensation; ``_condensed_solve``
    writes it, :func:`.condensation._reactions` reads it.
ipiv : (ndof,) int64, the band factors' pivots (``_condensed_solve``).
g : (ndof,) the residual G, global frame then nodal frames: ``_evaluate``,
    ``_to_nodal_system`` or ``_to_nodal_residual`` write it; :func:`_test`,
    ``_hold_boundaries``, ``_roundoff_ratio``, ``_condensed_solve``,
    ``_reactions`` and the friction's commit on convergence read it.
g_trial : (ndof,) the residual at a trial state: :func:`.step._trial` writes
    it, ``_trial_merit`` reads it.
d : (ndof,) the top tension's row dTe/du [N/m, N, -], global frame:
    ``_evaluate`` writes it, :func:`.system._border` reads it.
delta : (ndof,) the constrained unknowns' prescribed increments, nodal frames
    [m, -, N]: :func:`.constraints._constraint_set` (and ``_hold_boundaries``,
    lift-off's slope) write them, ``_condensed_solve`` reads them.
cmask : (ndof,) bool, the constrained unknowns: ``_constraint_set`` (and
    ``_hold_boundaries``) write it; the residual's norms, ``_condensed_solve``
    and ``_reactions`` read it.
du : (ndof,) the scaled Newton step, nodal frames [-] (``_condensed_solve``);
    ``_reactions`` reads it.
du_free : (ndof,) the Newton step, global frame [m, -, N]: ``_condensed_solve``
    writes it; ``_start_step``, ``friction_step`` and ``_take_step`` read it.
u_old : (ndof,) the state the step starts from (:func:`.step._start_step`);
    read by ``_take_step`` and ``_line_search``.
scale : (ndof,) the unknowns' scales: 1 (positions), href [m] (slopes), EI /
    href^2 [N] (multipliers); constant (:func:`_work`), read by
    ``_condensed_solve`` and ``_reactions``.
torques : (nel,) the torque in each element [N m]: the case's, redistributed
    by ``_system`` under distributed moments; read by the element chain.
rows : (nbr, ndof) the bordered equations' gradients, nodal frames
    (``_border``); read by ``_condensed_solve``.
cols : (nbr, ndof) the bordered unknowns' columns dG/dz, nodal frames
    (``_border``); read by ``_condensed_solve`` and ``_reactions``.
res_b : (nbr,) the bordered equations' residuals (``_border``), read by the solve.
d_b : (nbr, nbr) the bordered equations' derivatives by the bordered
    unknowns at fixed u (``_border``), read by the solve.
kind : (nbr,) int64, each bordered unknown: 0 the bottom tension, 2 + b
    boundary b (``_border``); read by :func:`.condensation._border_steps`.
dz : (nbr,) the bordered unknowns' steps [N, m] (``_condensed_solve``); read
    by ``_border_steps`` and ``_reactions``.
sm, rh : (nbr, nbr), (nbr,) the Schur complement and its right-hand side,
    scratch of ``_condensed_solve``.
rhs : (ndof, 1 + nbr) the step and the border columns solved together,
    scratch of ``_condensed_solve``.
bcols : (nbnd, ndof) each boundary's column dG/ds_b, global frame
    [N/m, N, -]: ``_evaluate`` writes it, ``_border`` reads it.
res_bnd : (nbnd,) the boundaries' equations [N m, -, m] (touchdown's moment,
    lift-off's slope, a point's distance): ``_to_nodal_system``,
    ``_to_nodal_residual`` and ``_border`` write them; ``_test`` and
    ``_start_step`` (the merit) read them.
d_top : (nbnd,) dTe_top/ds_b at fixed u [N/m]: ``_evaluate`` writes it,
    ``_border`` reads it.
d_bnd : (nbnd,) the boundaries' steps [m] (``_border_steps``); read by
    ``_start_step`` and ``_take_step``, and the loop at PAST_TIP.
bnd_old : (nbnd,) the boundaries' arc lengths where the step starts [m]
    (``_start_step``); read by ``_take_step``.
s_nd : (nn,) the nodes' arc lengths [m] on the present mesh: ``_evaluate``,
    the loop after each step and on convergence write them; the
    friction kernels read them.
s_old : (nn,) the nodes' arc lengths where the step starts [m]
    (``_start_step``); read by ``_take_step``.
fr_out : (ndof,) the friction springs' forces on the pipe [N]
    (``friction_forces``); on convergence the loop adds them to the reactions.
fr_stop : (nn,) the spring a step stopped at its stick zone's edge (1 + the
    component; 0 none): ``friction_step`` writes and reads it,
    ``_line_search`` clears it.
row_td, own_td : (ndof,), (nbnd,) touchdown's equation's gradient dM/du [N, N m,
    m] and its derivatives by each boundary's arc length at fixed u [N]:
    ``_evaluate`` writes them, ``_border`` reads them.
at, at_rate, at_scratch, sh : (2 nd + 1,) x 3, (3, 4) the pipe at a material
    point, its derivative along the pipe and the Hermite shape functions:
    scratch of :func:`.step._take_step`.
no_row, no_ab : (0,), (1, 1) stand-ins for "no gradient" and "no tangent".
ew : :data:`.assembly.ElementWork`, the element kernel's outputs and scratch
    (:func:`.system._evaluate` gives it to the element chain), so that an
    evaluation allocates nothing.
"""


@phase
def _work(nd, n, nn, nel, nbnd, props, href):
    """The iteration's work arrays (:data:`Work`) for ``n`` unknowns, ``nn``
    nodes, ``nel`` elements and ``nbnd`` boundaries. The border's rows and
    columns, the boundaries' columns and the multi-RHS block are written
    before they are read, so they are left unzeroed."""
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
            scale[i] = props[L.EI_REF] / (href * href)
    return Work(
        np.zeros((n, rows_ab)).T, np.zeros((n, rows_ab)).T, np.zeros(n, dtype=np.int64),
        np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n, dtype=np.bool_),
        np.zeros(n), np.zeros(n), np.zeros(n), scale, np.full(nel, props[L.TORQUE]),
        np.empty((n_border, n)), np.empty((n_border, n)),
        np.zeros(n_border), np.zeros((n_border, n_border)), np.zeros(n_border, dtype=np.int64),
        np.zeros(n_border), np.zeros((n_border, n_border)), np.zeros(n_border),
        np.empty((nbnd, n)), np.zeros(nbnd), np.zeros(nbnd),
        np.zeros(nbnd), np.zeros(nbnd), np.zeros(nn), np.zeros(n), np.zeros(0),
        np.zeros((1, 1)).T, np.zeros(n), np.zeros(nbnd), np.zeros(nn), np.zeros(ndn),
        np.zeros(ndn), np.zeros(ndn), np.zeros((3, 4)), np.zeros(nn),
        np.empty((n, 1 + n_border)), element_work(nd))


@jit(by_dimension=True, _nrt=False)
def _test(nd, u, mesh, ends, w, settings, te_top, max_delta, want_tangent, changed):
    """The residuals the test reads and the test. Returns (the free rows'
    largest weighted residual and sum of squares, the top tension's relative
    residual, the boundaries' largest scaled residual, whether converged).

    Converged: the residuals below the tolerance, or every free row at its
    round-off floor (:func:`.system._roundoff_ratio`, which reads the
    tangent: a fine mesh far from the origin cannot reach every tolerance);
    the constraints held (``max_delta``); no rigid point changed branch
    (``changed``: True at a call's first evaluation, so that every call
    takes a step, whose solve gives the reactions)."""
    res_max, res_ssq = _weighted_max(nd, w.g, w.cmask, settings.fref, settings.href)
    top_res = 0.0
    if _solves_tb(ends):
        top_res = abs(te_top - ends.top_target) / ends.top_target
    bnd_res = 0.0
    for b in range(mesh.bnodes.shape[0]):
        if mesh.bnodes[b] >= 0:
            bnd_res = max(bnd_res, abs(w.res_bnd[b]) / _bnd_scale(b, settings.fref,
                                                                  settings.href))
    tol = settings.tol
    at_roundoff = (res_max > tol and want_tangent
                   and _roundoff_ratio(nd, u, w.ab, w.g, w.cmask) <= ROUNDOFF_RATIO)
    converged = ((res_max <= tol or at_roundoff) and max_delta <= tol
                 and (top_res <= tol or at_roundoff)
                 and (bnd_res <= tol or at_roundoff) and not changed)
    return res_max, res_ssq, top_res, bnd_res, converged


@jit(by_dimension=True, _nrt=False)
def _free_residual(nd, u, sup, w, out):
    """The residual G of an iteration's evaluation (``w.g``, nodal frames)
    with its constrained rows (``w.cmask``) zeroed, back in the global frame
    (:func:`.system._from_nodal_frames`), into ``out`` [N, N m, m]: the
    load path's offset from the first guess, whose constrained rows would
    enter the reactions (a rigid point's complementarity, the seabed's
    friction). But the rows c, c' of the contacts held in curve coordinates
    keep G (at those nodes ``out`` is G, the held ends' rows excepted): there
    the offset carries the guess's contact force and the curve's reaction
    grows from zero with the load; zeroed, the curve takes the guess's force
    from the start (up to 9e7 N at a kink of the guess), and the first load
    steps can diverge (measured: ``bench_contact``'s random 3D case 08)."""
    ndn = 2 * nd + 1
    for i in range(out.shape[0]):
        out[i] = 0.0 if w.cmask[i] else w.g[i]
    if STINGER:
        for k in range(sup.kind.shape[0]):
            if not in_curve_coords(sup.kind[k]):
                continue
            for node in range(sup.active.shape[1]):
                if sup.active[k, node] != 0:
                    for i in (node * ndn, node * ndn + nd):
                        if sup.fix_mask[i] == 0:
                            out[i] = w.g[i]
    _from_nodal_frames(nd, out, u, sup)


@phase
def _friction_answer(nd, u, mesh, model, sup, w, react):
    """The answer's friction: the springs' normal forces (``w.g`` in the nodal
    frames), their forces turned into the nodal frames (a sloped seabed's
    axial force has x and z parts) and joined to the reactions ``react``;
    then the slipping springs' anchors follow (:func:`.contact.friction_commit`).
    Nothing without friction in the scene (:mod:`.scene`)."""
    if not FRICTION:
        return
    w.fr_out[:] = 0.0
    node_arcs(mesh.s_el, w.s_nd)
    bed = sup.active[ROW_BED]
    for node in range(sup.phi_r.shape[0]):
        sup.fric[node, L.FR_W] = normal_force(nd, w.g, model.props, bed, sup.fric, node, True)
    friction_forces(nd, u, w.g, w.no_ab, 0, model, bed, sup.fric, w.fr_out, w.s_nd, True)
    _rotate_all(nd, w.no_ab, 4 * nd + 1, 4 * nd + 1, w.fr_out, sup.phi_r, sup.phi_rp, False)
    for i in range(u.shape[0]):
        react[i] += w.fr_out[i]
    friction_commit(nd, u, model, bed, sup.fric, w.s_nd)


def _newton_kernel(nd):
    """The Newton kernel for dimension ``nd``: :func:`newton_2d` and
    :func:`newton_3d` are its two compilations, ``nd`` a constant in each (a
    closure's constant cell: the literal that the phases and the element
    chain are compiled for). A closure, not a phase inlined into two entries:
    numba copies an inlined function's whole scope once per block."""

    @jit(entry=True, _nrt=True)
    def newton(u, mesh, model, sup, ends, settings, react, info):
        """Solve G(u) = reactions for one load level (the module docstring)."""
        w = _work(nd, u.shape[0], sup.phi_r.shape[0], mesh.s_el.shape[0], mesh.bnodes.shape[0],
                  model.props, settings.href)
        href = settings.href
        for k in range(N_INFO):
            info[k] = 0.0
        if _has_boundaries(mesh):
            mesh_lengths(mesh.s_a, mesh.s_b, mesh.s_bd, mesh.s_el)
        status = L.MAX_ITERATIONS
        changed = True  # a rigid point changed branch in the last iteration
        res_change = np.inf  # the residual when the stinger's tip last changed branch
        it = 0
        res_start = 1.0
        moved = False  # the last step moved the boundaries and lowered the merit
        trial_converged = False  # the last trial passed the test on its own constraints
        residual_only = settings.maxit == 0  # (the module docstring)
        for it in range(1, max(settings.maxit, 1) + 1):
            # ---- evaluate (after a converged trial, the residual alone first)
            want_tangent = not (trial_converged or residual_only)
            while True:
                if STINGER:  # the nodes the stinger holds laterally: those over it now
                    lateral_hold(nd, mesh.s_el, u, sup, ends.top_node, sup.y_held)
                _nodal_frames(nd, u, mesh, sup, ends)
                te_top, m_td = _evaluate(nd, u, mesh, model, sup, ends, w, w.g, want_tangent)
                if want_tangent:
                    nb, nb_fixed = _to_nodal_system(nd, u, mesh, sup, ends, w, te_top, m_td)
                else:
                    _to_nodal_residual(nd, u, mesh, sup, w, m_td)
                max_delta = _constraint_set(nd, u, mesh, sup, ends, w, href)
                res_max, res_ssq, top_res, bnd_res, converged = _test(
                    nd, u, mesh, ends, w, settings, te_top, max_delta, want_tangent, changed)
                finite = math.isfinite(res_ssq)  # (max() skips NaN; the sum does not)
                if want_tangent or converged or not finite or residual_only:
                    break
                want_tangent = True
            if residual_only:
                info[I_TOP_TE] = te_top
                _free_residual(nd, u, sup, w, react)
                return L.OK
            # ---- test
            if not finite or (it > 1 and res_max > RUNAWAY * res_start):
                status = L.NOT_FINITE
                break
            if it == 1:  # at least one reference force (1: the weighted residual's unit)
                res_start = max(res_max, 1.0)
            info[I_RES] = res_max
            info[I_DELTA] = max_delta
            info[I_TOP_RES] = top_res
            if converged:
                status = L.OK
                it -= 1
                break
            # ---- condense and solve
            hold = (settings.hold and not moved
                    and _hold_boundaries(nd, u, mesh, sup, w, settings, bnd_res))
            if hold:
                nb = nb_fixed
            if not _condensed_solve(nd, w, nb, sup.phi_r, sup.phi_rp):
                status = L.SINGULAR
                break
            dtb = _border_steps(w, nb)
            _reactions(nd, w, nb, react)
            # ---- step
            merit0, alpha, stop = _start_step(nd, u, mesh, sup, w, settings, hold, res_ssq,
                                              top_res)
            if stop >= 0:
                status = stop
                if stop == L.PAST_TIP:  # how far past the tip; the step taken up to it
                    info[I_PAST] = abs(w.d_bnd[B_LO]) * (1.0 - alpha)
                    if alpha > 0.0:
                        _take_step(nd, alpha, u, w.u_old, w.du_free, sup, ends.tb, ends.tb[0],
                                   dtb, _has_boundaries(mesh), mesh, w)
                break
            accepted, m1 = _line_search(nd, u, mesh, model, sup, ends, w,
                                                          settings, hold, dtb, alpha, merit0)
            moved = not hold and accepted and m1 < merit0
            # ---- the contacts at the new state
            node_arcs(mesh.s_el, w.s_nd)
            if FRICTION:
                friction_track(nd, u, react, model.props, model.bed, sup.active[ROW_BED],
                               sup.fric, w.s_nd)
            changed = False
            if STINGER:
                changed = _points_update(nd, u, mesh, sup, react, settings) > 0
            trial_converged = accepted and not changed and at_tolerance(m1, settings.tol)
            if changed and sup.kind[ROW_CURVE] != SUP_NONE:
                # the stinger's tip changes branch again with the residual no
                # lower than at its last change: the branches cycle, there is
                # no bearing solution (a roller has no other regime: its
                # branch settles as the pipe finds its balance)
                if res_max >= res_change:
                    status = L.TIP_CYCLE
                    break
                res_change = res_max
        if status == L.OK:
            _friction_answer(nd, u, mesh, model, sup, w, react)
        if STINGER:
            _curve_reactions(nd, u, sup, react)
        info[I_STATUS] = status
        info[I_ITER] = it
        return status

    return newton


newton_2d = _newton_kernel(2)
newton_3d = _newton_kernel(3)

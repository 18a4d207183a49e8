"""Step control of the Newton kernel: whether a step holds the contact
boundaries, where it starts, how far it may go, its trial states and their
merit, and the line search.

The merit of a state is the sum of squares of its weighted residuals (the
free rows in the nodal frames, each divided by fref, fref href or href as it
is a force, a moment or a length), plus the top tension's relative residual
and the boundaries' scaled equations (:func:`.constraints._bnd_scale`)
squared, those left out while the boundaries are held.
"""

from __future__ import annotations

import numpy as np

from . import layout as L
from ._jit import jit, phase
from .constraints import (
    _bnd_equation,
    _bnd_scale,
    _element_at,
    _has_boundaries,
    _onto_curves,
    _pipe_at,
    mesh_lengths,
)
from .contact import friction_step, node_arcs
from .layout import B_LO, B_PT, B_TD, ROW_BED
from .scene import FRICTION, STINGER
from .supports import support_span
from .system import _evaluate, _solves_tb, _to_nodal_frames, _weighted_max
from .tuning import (
    ARMIJO,
    BACKTRACK,
    LINE_SEARCH_TRIALS,
    MERIT_RISE,
    MIN_ELEMENT_SHARE,
    SHORT_LAID_SHARE,
    SPAN_GROWTH,
)


@phase
def _hold_boundaries(nd, u, mesh, sup, w, settings, bnd_res):
    """Whether this iteration holds the boundaries where they are: held, the
    step keeps lift-off's node tangent to the stinger (its slope then
    constrained, ``w.cmask`` and ``w.delta``) and the bordered step moves
    no boundary. Held while the weighted residual of the pipe with
    lift-off's slope held exceeds the boundaries' own imbalance ``bnd_res``
    (their equations' scaled residuals, and the moment on lift-off's slope
    that its tangency would hold): both are measured in their own scaled
    equations, so they compare directly.

    A step of the boundaries from a state out of equilibrium follows a
    linearisation that may point the wrong way; from equilibrium the
    bordered step is the reduced Newton step of the boundaries' own
    equations. Without lift-off among the unknowns nothing is held:
    touchdown alone moves with the pipe. The Newton kernel does not ask
    after a step that moved the boundaries and lowered the merit (held and
    unheld steps alternating near equilibrium would make the convergence
    linear), nor in a call that starts from a state in balance
    (``settings.hold`` False)."""
    if not STINGER:
        return False
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
    if res_eq > own:
        w.delta[j_lo] = -_bnd_equation(nd, u, sup, B_LO, mesh.bnodes[B_LO], w.no_row)
        return True
    w.cmask[j_lo] = keep
    return False


@jit(by_dimension=True, _nrt=False)
def _start_step(nd, u, mesh, sup, w, settings, hold, res_ssq, top_res):
    """Where the step starts and how far it may go. Saves the state, the
    boundaries' and the nodes' arc lengths (``w.u_old``, ``w.bnd_old``,
    ``w.s_old`` [m]); returns (the merit there, the longest fraction of the
    step the contact boundaries allow, the status that stops the call, -1
    none). The merit: the free rows' sum of squares ``res_ssq``, the top
    tension's ``top_res`` and the boundaries' equations ``w.res_bnd``
    (unless ``hold``).

    A boundary stays inside its zone (no element there shrinks below a
    tenth) and moves at most ``settings.bstep`` [m]; touchdown stays on the
    modelled laid pipe (SHORT_LAID past half way to the lower end); the span
    between re-contact and a bearing tip at most halves or doubles (it grows
    like sqrt(a - a_switch) past the change of regime: a step in its
    logarithm follows that), SPAN_CLOSED when there is no bearing solution;
    a step that would take lift-off past the tip returns PAST_TIP with the
    fraction that takes it to the tip (0 when it is at or past the tip
    already), which the Newton kernel takes before it stops (stopped short
    of the tip instead, the approach would only halve the distance a
    step)."""
    for i in range(u.shape[0]):
        w.u_old[i] = u[i]
    merit0 = res_ssq + top_res * top_res
    for b in range(mesh.bnodes.shape[0]):
        if mesh.bnodes[b] >= 0 and not hold:
            merit0 += (w.res_bnd[b] / _bnd_scale(b, settings.fref, settings.href)) ** 2
        w.bnd_old[b] = mesh.s_bd[b]
    node_arcs(mesh.s_el, w.s_old)
    href = settings.href
    bstep = settings.bstep
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
            if rate < -(1.0 - MIN_ELEMENT_SHARE) * s_el[e]:
                alpha = min(alpha, (1.0 - MIN_ELEMENT_SHARE) * s_el[e] / abs(rate))
    for b in range(nbnd):
        if abs(d_bnd[b]) * alpha > bstep:
            alpha = bstep / abs(d_bnd[b])
    if has_td and not hold and d_bnd[B_TD] < 0.0:
        if -d_bnd[B_TD] * alpha > SHORT_LAID_SHARE * (s_bd[B_TD] - mesh.s_a[0]):
            return merit0, alpha, L.SHORT_LAID
    if not STINGER:  # (no lift-off, no rigid point)
        return merit0, alpha, -1
    if has_lo and has_tipn and not hold:
        gap_s = s_bd[B_LO] - s_bd[B_PT]
        d_gap_s = (d_bnd[B_LO] - d_bnd[B_PT]) * alpha
        if d_gap_s < -gap_s / SPAN_GROWTH:
            if gap_s < href and sup.geom[B_PT, L.PT_BEAR] != 0.0:
                # Bearing, the span's square goes like a - a_switch: from
                # d0 Newton asks d0 / 2 + (a - a_switch) / (2 k d0), so a
                # step that more than halves the span says there is no
                # bearing solution (d = 0 is then the bearing equations'
                # limit, which Newton approaches only linearly). Once the
                # span is shorter than an element the two regimes differ
                # by less than the mesh resolves: the pipe lifts off
                # above the tip.
                return merit0, alpha, L.SPAN_CLOSED
            alpha *= gap_s / (SPAN_GROWTH * -d_gap_s)
        elif d_gap_s > (SPAN_GROWTH - 1.0) * gap_s:
            alpha *= (SPAN_GROWTH - 1.0) * gap_s / d_gap_s
    if has_lo and not hold:
        # lift-off stays above the tip, its support's lower end (the curve
        # continued past it is no support)
        base = bnodes[B_LO] * ndn
        z_tip, _z_top = support_span(sup.kind[B_LO], sup.geom[B_LO])
        room = u[base + nd - 1] - z_tip
        dz_lo = w.du_free[base + nd - 1]  # the node's own z slides it along the curve
        if room <= 0.0 and dz_lo < 0.0:  # at the tip or past it, moving down
            return merit0, 0.0, L.PAST_TIP
        if dz_lo * alpha < -room:
            if room > 0.0:  # from above the tip, the step would take it past
                return merit0, room / -dz_lo, L.PAST_TIP
            alpha = room / -dz_lo  # from below the tip, rising: up to it
    return merit0, alpha, -1


@jit(by_dimension=True, _nrt=False)
def _line_search(nd, u, mesh, model, sup, ends, w, settings, hold, dtb, alpha, merit0):
    """The step taken from ``w.u_old``; returns (accepted, the last trial's
    merit); u, the bottom tension and the mesh left at
    the step taken.

    The limited step ``alpha`` is cut where a sliding friction spring would
    cross its stick zone (:func:`.contact.friction_step`), then grown by
    1 / BACKTRACK back towards the limited step while the merit falls, the lowest-merit
    trial kept (past the cut, no spring stays flagged as stopped,
    ``w.fr_stop``): a laid pipe sliding as a whole has its whole length
    carried back past the anchors by Newton (its lateral stiffness then the
    span's alone), and stopped at the first spring's zone it would move a
    small part of the step an iteration. From there the step is halved until
    :func:`_accepts` takes the trial, tuning.LINE_SEARCH_TRIALS at most; where none is
    accepted the first is taken anyway (the merit is flat there: a change of
    constraint, a constraint's correction)."""
    has_bnd = _has_boundaries(mesh)
    tb_old = ends.tb[0]
    alpha_lim = alpha
    if FRICTION:
        alpha = friction_step(nd, u, w.du_free, w.s_nd, model, sup.active[ROW_BED], sup.fric,
                              w.fr_stop, alpha)
    if alpha < alpha_lim:
        best = alpha
        m_best = np.inf
        trial = alpha
        while True:
            m1 = _trial(nd, trial, u, mesh, model, sup, ends, w, settings, hold, dtb, tb_old,
                        has_bnd)
            if m1 < m_best:
                m_best, best = m1, trial
            elif trial > alpha:
                break
            if trial >= alpha_lim:
                break
            trial = min(trial / BACKTRACK, alpha_lim)
        ends.tb[0] = tb_old
        if best > alpha:
            w.fr_stop[:] = 0.0
        alpha = best
    alpha0 = alpha
    accepted = False
    for _ls in range(LINE_SEARCH_TRIALS):
        m1 = _trial(nd, alpha, u, mesh, model, sup, ends, w, settings, hold, dtb, tb_old,
                    has_bnd)
        if _accepts(m1, merit0, alpha, settings.tol, mesh, hold):
            accepted = True
            break
        alpha *= BACKTRACK
    if not accepted:
        _take_step(nd, alpha0, u, w.u_old, w.du_free, sup, ends.tb, tb_old, dtb, has_bnd,
                   mesh, w)
    return accepted, m1


@jit(by_dimension=True, _nrt=False)
def _trial(nd, alpha, u, mesh, model, sup, ends, w, settings, hold, dtb, tb_old, has_bnd):
    """The state a fraction ``alpha`` along the step (:func:`_take_step`,
    from ``w.u_old`` and the bottom tension ``tb_old``) and its merit
    (:func:`_trial_merit`). A kernel, not a phase: it has two callers, and
    inlined it would compile :func:`.system._evaluate` into the Newton
    kernel three times (``benchmarks/bench_compile.py``)."""
    _take_step(nd, alpha, u, w.u_old, w.du_free, sup, ends.tb, tb_old, dtb, has_bnd, mesh,
               w)
    te_t, m_t = _evaluate(nd, u, mesh, model, sup, ends, w, w.g_trial, False)
    return _trial_merit(nd, u, mesh, sup, ends, w, settings, hold, te_t, m_t)


@phase
def _trial_merit(nd, u, mesh, sup, ends, w, settings, hold, te_top, m_td):
    """The merit at a trial state (its residual in ``w.g_trial`` from
    :func:`.system._evaluate`): the sum of squared weighted residuals, the
    top tension's and the boundaries' equations (unless held)."""
    bnodes = mesh.bnodes
    fref = settings.fref
    href = settings.href
    tr = 0.0
    if _solves_tb(ends):
        tr = (te_top - ends.top_target) / ends.top_target
    tdr = 0.0
    if bnodes[B_TD] >= 0 and not hold:
        tdr += (m_td / (fref * href)) ** 2
    if STINGER:  # the boundaries above touchdown
        for b in range(B_LO, bnodes.shape[0]):
            if bnodes[b] >= 0 and not hold:
                tdr += (_bnd_equation(nd, u, sup, b, bnodes[b], w.no_row)
                        / _bnd_scale(b, fref, href)) ** 2
    _to_nodal_frames(nd, w.g_trial, u, sup, w)
    _rm, rs = _weighted_max(nd, w.g_trial, w.cmask, fref, href)
    return rs + tr * tr + tdr


@phase
def at_tolerance(merit, tol):
    """Whether ``merit`` (a sum of squared weighted residuals [-]) is at the
    tolerance's floor: tol^2, the square of a weighted residual of tol."""
    return merit <= tol * tol


@phase
def _accepts(m1, merit0, alpha, tol, mesh, hold):
    """Whether the line search takes the trial step of merit ``m1``: Armijo's
    decrease from ``merit0``, or a merit at the tolerance's floor, or:

    with the boundaries unknowns, any rise up to MERIT_RISE times: the
    weighted residual rises across good steps there, as the element lengths
    move with the boundaries, and Armijo's cuts slowed the iteration or
    stalled it (a diverging step is caught by the iteration's tests); a
    step of the stinger's boundaries from equilibrium (not held), any finite
    merit: the short elements of a closing gap span raise it by orders of
    magnitude across good steps, and cut, the span crept."""
    has_bnd = _has_boundaries(mesh)
    has_lo = mesh.bnodes[B_LO] >= 0
    return (m1 <= (1.0 - ARMIJO * alpha) * merit0 or at_tolerance(merit0, tol)
            or (has_bnd and m1 <= MERIT_RISE * merit0)
            or (has_lo and not hold and np.isfinite(m1)))


@jit(_nrt=False)
def _take_step(nd, alpha, u, u_old, du, sup, tb, tb_old, dtb, has_bnd, mesh, w):
    """The state a fraction ``alpha`` along the Newton step: nodal unknowns
    (the contacts of supports in curve coordinates along their curve), bottom
    tension and boundary arc lengths (from ``w.bnd_old`` by ``w.d_bnd``) with
    the element lengths they give.

    A node that the stinger's boundaries (lift-off or re-contact, the tip's
    point) move along the pipe by sigma is carried along the pipe's present
    curve: it takes the curve's values at its new material point
    (:func:`.constraints._pipe_at`), plus the Newton step's increment less
    the part of it that this transport makes to first order (the curve's
    derivative at the node, on the side it moves to, times sigma). To first
    order this is the Newton step; beyond it the pipe keeps its strains
    where the mesh slides along it, instead of being stretched between nodes
    held in place (against its axial stiffness EA, orders of magnitude above
    the tension). Touchdown's zone is not carried: where touchdown moves,
    suspended pipe comes to lie on the seabed."""
    ndn = 2 * nd + 1
    nn = sup.phi_r.shape[0]
    for i in range(u.shape[0]):
        u[i] = u_old[i] + alpha * du[i]
    if STINGER and has_bnd:  # (the boundaries above touchdown: the stinger's)
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
    if STINGER:
        _onto_curves(nd, u, u_old, du, alpha, sup)
    tb[0] = tb_old + alpha * dtb
    if has_bnd:
        for b in range(mesh.s_bd.shape[0]):
            mesh.s_bd[b] = w.bnd_old[b] + alpha * w.d_bnd[b]
        mesh_lengths(mesh.s_a, mesh.s_b, mesh.s_bd, mesh.s_el)

"""The linear response of a converged state: the implicit function theorem
on the Newton kernel's system.

At a converged state U* of the problem at p, the neighbouring problem at
p + h (its loads, supports, ends and mesh sizes moved, its contact and
regime sets those of U*) has the residual R(U*, p + h) = h dR/dp + O(h^2);
its solution is U* + dU with K dU = -R (K the tangent at U*, p) to O(h^2).
:func:`residual_2d` (``residual_3d``) evaluates a neighbour's residual and
constraint increments at U*, as the Newton kernel's first iteration does
(:mod:`.newton`); :func:`responses_2d` evaluates and factors the tangent at
U* once and solves the steps of any number of neighbours' residuals by
condensation and the bordered solve (:mod:`.condensation`: the constrained
unknowns' increments prescribed, the bottom tension and the boundaries' arc
lengths by the Schur complement), with their linearised reactions;
:func:`finish_2d` completes a neighbour's stepped state as the Newton
kernel completes a converged one (the rigid points' branches by their
complementarity, the friction springs' answer, the curve contacts'
reactions).

Arguments as :func:`.newton.newton_2d`'s; per neighbour k (m of them): ``g``
(m, ndof) its residual in its nodal frames, ``delta`` (m, ndof) its
constrained unknowns' increments, ``res_b`` (m, 1 + nbnd) its bordered
equations' residuals (the first ``nb`` used); outputs ``du`` (m, ndof) the
steps in the global frame [m, -, N], ``dz`` (m, 1 + nbnd) the bordered
unknowns' steps (``kind``: 0 the bottom tension [N], 2 + b boundary b's arc
length [m]), ``react`` (m, ndof) the linearised reactions in the nodal
frames [N, N m].
"""

from __future__ import annotations

import numpy as np

from ._jit import jit, phase
from .banded import band_solve_many
from .condensation import (
    _border_columns,
    _border_solve,
    _condense_factor,
    _condensed_rhs,
    _curve_reactions,
    _reactions,
)
from .constraints import (
    _constraint_set,
    _has_boundaries,
    _nodal_frames,
    _onto_curves,
    _points_update,
    mesh_lengths,
)
from .contact import lateral_hold
from .newton import _friction_answer, _work
from .scene import STINGER
from .system import _border_residuals, _evaluate, _to_nodal_residual, _to_nodal_system


@phase
def _evaluated(nd, u, mesh, model, sup, ends, settings, want_tangent):
    """The Newton kernel's evaluation at ``u`` (its work arrays,
    :data:`.newton.Work`): residual, with ``want_tangent`` the tangent, and
    the border in the nodal frames (without the tangent, the border's
    residuals ``w.res_b`` and unknowns ``w.kind`` alone, in
    :func:`.system._border`'s order, from :func:`.system._to_nodal_residual`),
    the constraint set. Returns (the work arrays, the bordered unknowns' count)."""
    w = _work(nd, u.shape[0], sup.phi_r.shape[0], mesh.s_el.shape[0], mesh.bnodes.shape[0],
              model.props, settings.href)
    if _has_boundaries(mesh):
        mesh_lengths(mesh.s_a, mesh.s_b, mesh.s_bd, mesh.s_el)
    if STINGER:
        lateral_hold(nd, mesh.s_el, u, sup, ends.top_node, sup.y_held)
    _nodal_frames(nd, u, mesh, sup, ends)
    te_top, m_td = _evaluate(nd, u, mesh, model, sup, ends, w, w.g, want_tangent)
    if want_tangent:
        nb, _nb_fixed = _to_nodal_system(nd, u, mesh, sup, ends, w, te_top, m_td)
    else:
        _to_nodal_residual(nd, u, mesh, sup, w, m_td)
        nb = _border_residuals(mesh, ends, w, te_top)
    _constraint_set(nd, u, mesh, sup, ends, w, settings.href)
    return w, nb


def _response_kernels(nd):
    """The three entries for dimension ``nd`` (a closure's constant, as
    :func:`.newton._newton_kernel`)."""

    @jit(entry=True, _nrt=True)
    def residual(u, mesh, model, sup, ends, settings, g, delta, res_b, cmask, kind):
        """A neighbour's residual ``g``, constrained unknowns' increments
        ``delta`` (and which they are, ``cmask``) and bordered residuals
        ``res_b`` (their unknowns' ``kind``, in :func:`.system._border`'s
        order) at ``u``, without the tangent (the residual of
        :func:`.system._to_nodal_residual`). Returns their count."""
        w, nb = _evaluated(nd, u, mesh, model, sup, ends, settings, False)
        for i in range(u.shape[0]):
            g[i] = w.g[i]
            delta[i] = w.delta[i]
            cmask[i] = w.cmask[i]
        for j in range(nb):
            res_b[j] = w.res_b[j]
            kind[j] = w.kind[j]
        return nb

    @jit(entry=True, _nrt=True)
    def responses(u, mesh, model, sup, ends, settings, g, delta, res_b, du, dz, react):
        """The steps ``du``, ``dz`` and linearised reactions ``react`` of
        each neighbour's residual (module docstring), one factorisation of
        the tangent at ``u``. Returns the bordered unknowns' count, -1 when
        the tangent or a Schur complement is singular."""
        w, nb = _evaluated(nd, u, mesh, model, sup, ends, settings, True)
        n, m = u.shape[0], g.shape[0]
        kl = 4 * nd + 1
        if not _condense_factor(nd, w):
            return -1
        rhs = np.empty((n, m + nb))
        for k in range(m):
            _condensed_rhs(nd, w, g[k], delta[k], w.du)
            for i in range(n):
                rhs[i, k] = w.du[i]
        _border_columns(w, nb, rhs, m)
        band_solve_many(w.ab, kl, kl, w.ipiv, rhs, m + nb)
        for j in range(nb):
            for i in range(n):
                w.rhs[i, 1 + j] = rhs[i, m + j]
        for k in range(m):
            for i in range(n):
                w.rhs[i, 0] = rhs[i, k]
                w.g[i] = g[k, i]
            for j in range(nb):
                w.res_b[j] = res_b[k, j]
            if not _border_solve(nd, w, nb, w.rhs, sup.phi_r, sup.phi_rp):
                return -1
            _reactions(nd, w, nb, react[k])
            for i in range(n):
                du[k, i] = w.du_free[i]
            for j in range(nb):
                dz[k, j] = w.dz[j]
        return nb

    @jit(entry=True, _nrt=True)
    def finish(u, du, mesh, model, sup, settings, react):
        """A neighbour's state ``u`` stepped by ``du`` (its curve contacts'
        increments in curve coordinates, followed along the curve as the
        Newton kernel's step does, :func:`.constraints._onto_curves`; its
        boundaries already in ``mesh``) and completed as a converged one
        (module docstring): the rigid points' branches and reactions, the
        friction springs' forces joined to ``react`` and their anchors, the
        curve contacts' reactions in their frames. Returns how many rigid
        points changed branch."""
        w = _work(nd, u.shape[0], sup.phi_r.shape[0], mesh.s_el.shape[0], mesh.bnodes.shape[0],
                  model.props, settings.href)
        for i in range(u.shape[0]):
            w.u_old[i] = u[i]
            u[i] += du[i]
        if STINGER:
            _onto_curves(nd, u, w.u_old, du, 1.0, sup)
        if _has_boundaries(mesh):
            mesh_lengths(mesh.s_a, mesh.s_b, mesh.s_bd, mesh.s_el)
        changes = 0
        if STINGER:
            changes = _points_update(nd, u, mesh, sup, react, settings)
        for i in range(u.shape[0]):
            w.g[i] = react[i]
        _friction_answer(nd, u, mesh, model, sup, w, react)
        if STINGER:
            _curve_reactions(nd, u, sup, react)
        return changes

    return residual, responses, finish


residual_2d, responses_2d, finish_2d = _response_kernels(2)
residual_3d, responses_3d, finish_3d = _response_kernels(3)

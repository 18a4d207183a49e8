"""The tangent (Euler) predictor of a load path's step.

At the converged state U of a load path at level l, the state at l + h on
the same branch, its contact set, slip set and regime held, is U + dU with
K dU = -h dR/dl to O(h^2): K the tangent at U and h dR/dl = R(U, l + h) -
R(U, l) the change of the residual with the level (the homotopy's offset
and top target, the current's factor). At a converged state R(U, l) = 0
and the step is the first Newton step at the new level taken in full, the
boundaries free; at the path's start, the first guess, the pipe's
equations hold but not the boundaries', and the difference leaves that
imbalance to Newton. The step is the linear response of
:mod:`pipelay_fast.kernels.response` (one factorisation, the constrained
unknowns' increments prescribed, the bottom tension and the boundaries'
arc lengths by the bordered solve).
"""

from __future__ import annotations

import numpy as np

from ..kernels.response import (
    finish_2d,
    finish_3d,
    residual_2d,
    residual_3d,
    responses_2d,
    responses_3d,
)
from ..kernels.scene import in_scene
from ..kernels.tuning import MIN_ELEMENT_SHARE
from .state import Problem


def level_residual(pb: Problem, mesh, settings, g_off) -> tuple:
    """The residual of ``pb``'s problem as it is set (its load level, the
    residual's offset ``g_off`` (ndof,) [N, N m]) at its state, as the
    response kernels take it: (g, delta, res_b, cmask, kind, their bordered
    count) (:func:`.kernels.response.residual_2d`, one row each)."""
    residual = response_kernels(pb)[0]
    n, nbr = pb.u.size, pb.bnodes.size + 1
    g, delta, res_b = np.zeros((1, n)), np.zeros((1, n)), np.zeros((1, nbr))
    cmask, kind = np.zeros((1, n), dtype=np.bool_), np.zeros((1, nbr), dtype=np.int64)
    nb = residual(pb.u, mesh, pb.model(), copied(pb.kernel_supports()), pb.kernel_ends(g_off),
                  settings, g[0], delta[0], res_b[0], cmask[0], kind[0])
    return g, delta, res_b, cmask, kind, nb


def tangent_start(pb: Problem, mesh, settings, g_off, before: tuple) -> bool:
    """Move ``pb``'s state, at the path's last level (whose residual there
    is ``before``, :func:`level_residual`) and its problem now set at the
    next one (the load's factors, the residual's offset ``g_off`` (ndof,)
    [N, N m], the top's target), by the linear response to the change of
    its residual between the two levels, h dR/dl (the module docstring;
    at a converged state, the residual at the next level; at a state out
    of balance, its imbalance is not corrected): the state, the bottom
    tension and the boundaries (the mesh carried with them); the friction
    springs' anchors and the rigid points' branches stay. ``mesh`` and
    ``settings``: the Newton kernel's, as :func:`.continuation.run_newton`
    builds them. Returns whether it moved (then ``in_balance``: the step's
    Newton solve does not hold the boundaries); not when the tangent is
    singular or the two levels' constraint sets differ. Where the
    boundaries' moves would fold the mesh, the step is shortened
    (:func:`_share`)."""
    _residual, responses, finish = response_kernels(pb)
    g, delta, res_b, cmask, kind, nb = level_residual(pb, mesh, settings, g_off)
    if nb != before[5] or (cmask != before[3]).any() or (kind != before[4]).any():
        return False
    g, delta, res_b = g - before[0], delta - before[1], res_b - before[2]
    model, ends = pb.model(), pb.kernel_ends(g_off)
    n, nbr = pb.u.size, pb.bnodes.size + 1
    du, dz, react = np.zeros((1, n)), np.zeros((1, nbr)), np.zeros((1, n))
    if responses(pb.u.copy(), mesh, model, copied(pb.kernel_supports()), ends, settings,
                 g, delta, res_b, du, dz, react) < 0:
        return False
    d_tb, d_bd = np.zeros_like(pb.tb), np.zeros_like(pb.mesh.s_bd)
    for j, unknown in enumerate(kind[0][:nb]):
        if unknown == 0:
            d_tb += dz[0, j]
        else:
            d_bd[unknown - 2] += dz[0, j]
    share = _share(pb, d_bd)
    pb.tb += share * d_tb
    pb.mesh.s_bd[:] += share * d_bd
    pb.mesh.update_nodes()
    # the step, the curve contacts followed along the curve (the supports'
    # rigid points and friction springs that ``finish`` completes: a copy's)
    finish(pb.u, share * du[0], mesh, model, copied(pb.kernel_supports()), settings, react[0])
    pb.settings.in_balance = True
    return True


def _share(pb: Problem, d_bd) -> float:
    """The share [-] of the predictor's step taken: 1, or less where its
    boundaries' moves ``d_bd`` [m] would shrink an element below
    MIN_ELEMENT_SHARE of its length (the Newton step's rule: the mesh does
    not fold)."""
    if pb.mesh.s_a is None:
        return 1.0
    shrink = -np.diff(d_bd @ pb.mesh.s_b)  # each element's shortening per unit step [m]
    length = np.diff(pb.mesh.s)
    short = shrink > 0.0
    if not short.any():
        return 1.0
    return float(min(1.0, np.min((1.0 - MIN_ELEMENT_SHARE) * length[short] / shrink[short])))


def response_kernels(pb: Problem):
    """The linear response's kernels (residual, responses, finish) for
    ``pb``'s dimension and scene (:attr:`.state.Problem.scene`)."""
    kernels = (residual_2d, responses_2d, finish_2d) if pb.nd == 2 else (
        residual_3d, responses_3d, finish_3d)
    return tuple(in_scene(kernel, pb.scene) for kernel in kernels)


def copied(sup):
    """A copy of the kernel's supports ``sup`` (an evaluation rewrites the
    nodal frames and the lateral hold, a completion the rigid points' and
    the springs' states)."""
    return type(sup)(*(part.copy() for part in sup))

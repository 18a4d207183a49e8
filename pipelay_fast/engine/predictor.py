"""The tangent (Euler) predictor of a load path's step.

At the converged state U of a load path at level l, the state at l + h on
the same branch, its contact set, slip set and regime held, is U + dU with
K dU = -R(U, l + h) to O(h^2): K the tangent at U and R the residual of the
problem at the new level (the residual's offset of the homotopy, the
current's factor), which at U is h dR/dl. The step is the linear response
of :mod:`pipelay_fast.kernels.response` (one factorisation, the constrained
unknowns' increments prescribed, the bottom tension and the boundaries'
arc lengths by the bordered solve): the first Newton step at the new level
taken in full, with the boundaries free (a converged state is in balance).
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
from .state import Problem


def tangent_start(pb: Problem, mesh, settings, g_off) -> bool:
    """Move ``pb``'s state, converged at the path's last level and its
    problem now set at the next one (the load's factors, the residual's
    offset ``g_off`` (ndof,) [N, N m], the top's target), by the linear
    response to its residual there (the module docstring): the state, the
    bottom tension and the boundaries (the mesh carried with them); the
    friction springs' anchors and the rigid points' branches stay. ``mesh``
    and ``settings``: the Newton kernel's, as :func:`.continuation.run_newton`
    builds them. Returns whether it moved (then ``in_balance``: the step's
    Newton solve does not hold the boundaries); not when the tangent is
    singular or the moved boundaries would fold the mesh."""
    residual, responses, finish = response_kernels(pb.nd)
    n, nbr = pb.u.size, pb.bnodes.size + 1
    g, delta, res_b = np.zeros((1, n)), np.zeros((1, n)), np.zeros((1, nbr))
    cmask, kind = np.zeros((1, n), dtype=np.bool_), np.zeros((1, nbr), dtype=np.int64)
    model, ends = pb.model(), pb.kernel_ends(g_off)
    nb = residual(pb.u, mesh, model, copied(pb.kernel_supports()), ends, settings,
                  g[0], delta[0], res_b[0], cmask[0], kind[0])
    du, dz, react = np.zeros((1, n)), np.zeros((1, nbr)), np.zeros((1, n))
    if responses(pb.u.copy(), mesh, model, copied(pb.kernel_supports()), ends, settings,
                 g, delta, res_b, du, dz, react) < 0:
        return False
    tb, s_bd = pb.tb.copy(), pb.mesh.s_bd.copy()
    for j, unknown in enumerate(kind[0][:nb]):
        if unknown == 0:
            pb.tb += dz[0, j]
        else:
            pb.mesh.s_bd[unknown - 2] += dz[0, j]
    pb.mesh.update_nodes()
    if not (np.diff(pb.mesh.s) > 0.0).all():  # a move beyond this mesh's map
        pb.tb[:], pb.mesh.s_bd[:] = tb, s_bd
        pb.mesh.update_nodes()
        return False
    # the step, the curve contacts followed along the curve (the supports'
    # rigid points and friction springs that ``finish`` completes: a copy's)
    finish(pb.u, du[0], mesh, model, copied(pb.kernel_supports()), settings, react[0])
    pb.settings.in_balance = True
    return True


def response_kernels(nd: int):
    """The linear response's kernels (residual, responses, finish) for ``nd``."""
    return (residual_2d, responses_2d, finish_2d) if nd == 2 else (residual_3d, responses_3d,
                                                                  finish_3d)


def copied(sup):
    """A copy of the kernel's supports ``sup`` (an evaluation rewrites the
    nodal frames and the lateral hold, a completion the rigid points' and
    the springs' states)."""
    return type(sup)(*(part.copy() for part in sup))

"""The tangent predictor of a load path (:func:`.predictor.tangent_start`).

Along the homotopy from the first guess, the converged state U(alpha) (the
nodal unknowns, the bottom tension and the boundaries' arc lengths, which
the mesh follows) is a smooth function of the load factor while the
contact set holds. The predictor's state from U(alpha) to alpha + h is the
Euler step U + h dU/dalpha, so its distance from U(alpha + h) is O(h^2),
while the last converged state's is O(h): halving h divides the first by
4 and the second by 2. U(alpha + h) is Newton's answer from U(alpha) at
a tolerance far below both distances.
"""

from __future__ import annotations

import numpy as np
import pytest

import pipelay_fast as pf
from pipelay_fast.engine.continuation import _kernel_args, homotopy, run_newton
from pipelay_fast.engine.predictor import level_residual, tangent_start
from pipelay_fast.engine.problem import build_problem
from pipelay_fast.engine.state import restore, snapshot
from pipelay_fast.kernels import layout as L
from tests.helpers import EXAMPLES

TOL = 1e-11  # Newton's weighted residual for the converged states


def _unknowns(pb):
    """The path's unknowns: the nodal state, the bottom tension, the boundaries' arc lengths."""
    return np.concatenate([pb.u, pb.tb, pb.mesh.s_bd])


def _converged(pb, load, alpha):
    """``pb`` solved at the homotopy's factor ``alpha`` from its present state."""
    g_off, _ = load(alpha, False)
    status, _react, _info = run_newton(pb, g_off, TOL, 100)
    assert status == L.OK
    return _unknowns(pb)


@pytest.mark.parametrize(("name", "steps"), [("j125_2d.toml", (0.02, 0.01, 0.005)),
                                             ("j125_3d.toml", (0.02, 0.01, 0.005)),
                                             ("s67.toml", (0.0005, 0.00025, 0.000125))])
def test_tangent_predictor_is_second_order(name, steps):
    case = pf.load_case(EXAMPLES / name)
    pb = build_problem(case)
    load = homotopy(pb)
    base = 0.5
    u_base = _converged(pb, load, base)
    start = snapshot(pb)
    errors, distances = [], []
    for h in steps:
        restore(pb, start)
        before = level_residual(pb, *_kernel_args(pb, 1.0, 1), load(base, False)[0])
        g_off, _ = load(base + h, False)
        assert tangent_start(pb, *_kernel_args(pb, 1.0, 1), g_off, before)
        predicted = _unknowns(pb)
        restore(pb, start)
        answer = _converged(pb, load, base + h)
        errors.append(np.linalg.norm(predicted - answer))
        distances.append(np.linalg.norm(u_base - answer))
    errors, distances = np.array(errors), np.array(distances)
    assert (errors < 0.5 * distances).all()
    # halving h: the predictor's error by 4 (second order), the last converged state's by 2
    np.testing.assert_allclose(errors[1:] / errors[:-1], 0.25, atol=0.05)
    np.testing.assert_allclose(distances[1:] / distances[:-1], 0.5, atol=0.1)

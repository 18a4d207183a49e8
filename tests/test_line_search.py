"""The line search's merit (kernels/condensation.py, kernels/step.py): the
condensed, bordered Newton step against a dense numpy solve of the same
system, and the simplified Newton correction at a trial state of a linear
system, which is (1 - alpha) times the step (so the error-oriented merit
falls like the step taken: Armijo's slope -1 per unit of alpha)."""

from __future__ import annotations

import numpy as np
import pytest

from pipelay_fast.kernels import layout as L
from pipelay_fast.kernels.condensation import _condensed_solve, simplified_norm, step_norm
from pipelay_fast.kernels.newton import _work

ND, NN, NBND, NB = 2, 7, 2, 3  # the bottom tension, touchdown and lift-off bordered
HREF, EI = 2.5, 4.0e5
NDN = 2 * ND + 1
KL = 2 * NDN - 1


def _system(seed):
    """A random banded tangent K (band KL, diagonally dominant), residual G, a
    few constrained unknowns with prescribed increments, and three bordered
    unknowns (kinds: the bottom tension, touchdown, lift-off) with rows B,
    columns C, residuals res and derivatives D."""
    rng = np.random.default_rng(seed)
    n = NN * NDN
    k = np.zeros((n, n))
    for i in range(n):
        for j in range(max(0, i - KL), min(n, i + KL + 1)):
            k[i, j] = rng.normal()
        k[i, i] += 4.0 * KL
    cmask = np.zeros(n, dtype=bool)
    cmask[[0, 1, 12, 23]] = True
    delta = np.where(cmask, rng.normal(size=n), 0.0)
    sys = dict(k=k, g=rng.normal(size=n), cmask=cmask, delta=delta,
               rows=rng.normal(size=(NB, n)), cols=rng.normal(size=(NB, n)),
               res=rng.normal(size=NB), d=rng.normal(size=(NB, NB)) + 3.0 * np.eye(NB),
               kind=np.array([0, 2 + L.B_TD, 2 + L.B_LO]))
    return sys


def _work_for(sys):
    """The Newton kernel's work arrays holding ``sys`` (nodal frames, unscaled)."""
    n = sys["g"].size
    props = np.zeros(L.N_PROPS)
    props[L.EI_REF] = EI
    w = _work(ND, n, NN, NN - 1, NBND, props, HREF)
    kv = 2 * KL
    for j in range(n):
        for i in range(max(0, j - KL), min(n, j + KL + 1)):
            w.ab[kv + i - j, j] = sys["k"][i, j]
    w.g[:] = sys["g"]
    w.cmask[:] = sys["cmask"]
    w.delta[:] = sys["delta"]
    w.rows[:NB] = sys["rows"]
    w.cols[:NB] = sys["cols"]
    w.res_b[:NB] = sys["res"]
    w.d_b[:NB, :NB] = sys["d"]
    w.kind[:NB] = sys["kind"]
    return w


def _dense_step(sys, g, res, share):
    """The bordered step by numpy: K_ff du_f + K_fc du_c + C_f dz = -G_f,
    du_c = share delta_c, B du + D dz = -res."""
    k, cm = sys["k"], sys["cmask"]
    n = g.size
    a = np.zeros((n + NB, n + NB))
    b = np.zeros(n + NB)
    free = ~cm
    a[:n, :n][free] = k[free]
    a[:n, n:][free] = sys["cols"].T[free]
    b[:n][free] = -g[free]
    a[np.flatnonzero(cm), np.flatnonzero(cm)] = 1.0
    b[:n][cm] = share * sys["delta"][cm]
    a[n:, :n] = sys["rows"]
    a[n:, n:] = sys["d"]
    b[n:] = -res
    x = np.linalg.solve(a, b)
    return x[:n], x[n:]


def _norm(du, dz):
    """The step's size as documented (step_norm), written out: lengths and
    slopes times href over href, multipliers and the bottom tension over
    EI / href^2, arc lengths over href."""
    slot = np.arange(du.size) % NDN
    v = np.where(slot < ND, du / HREF, np.where(slot < 2 * ND, du, du * HREF**2 / EI))
    vz = np.where(np.arange(NB) == 0, dz * HREF**2 / EI, dz / HREF)
    return float(np.sqrt(np.sum(v * v) + np.sum(vz * vz)))


@pytest.mark.parametrize("seed", [1, 2])
def test_condensed_step_is_the_bordered_solution(seed):
    sys = _system(seed)
    w = _work_for(sys)
    phi = np.zeros(NN)
    assert _condensed_solve(ND, w, NB, phi, phi)
    du, dz = _dense_step(sys, sys["g"], sys["res"], 1.0)
    np.testing.assert_allclose(w.du * w.scale, du, rtol=1e-10, atol=1e-12 * np.abs(du).max())
    np.testing.assert_allclose(w.dz[:NB], dz, rtol=1e-10)
    assert step_norm(ND, w, NB, HREF) == pytest.approx(_norm(du, dz), rel=1e-12)


@pytest.mark.parametrize("alpha", [1.0, 0.5, 0.125])
def test_simplified_correction_of_a_linear_system(alpha):
    """G(u + a du, z + a dz) = G + a (K du + C dz) for a linear system: the
    correction there is (1 - a) times the step, constraints included."""
    sys = _system(3)
    w = _work_for(sys)
    phi = np.zeros(NN)
    assert _condensed_solve(ND, w, NB, phi, phi)
    du, dz = _dense_step(sys, sys["g"], sys["res"], 1.0)
    norm0 = step_norm(ND, w, NB, HREF)
    w.g_trial[:] = sys["g"] + alpha * (sys["k"] @ du + sys["cols"].T @ dz)
    w.res_b[:NB] = sys["res"] + alpha * (sys["rows"] @ du + sys["d"] @ dz)
    n1 = simplified_norm(ND, w, NB, 1.0 - alpha, HREF)
    assert n1 == pytest.approx((1.0 - alpha) * norm0, rel=1e-9, abs=1e-12 * norm0)


def test_simplified_correction_of_a_residual_is_its_step():
    """At any residual G1 (the trial's, constraints done), the correction is
    the bordered step that G1 asks for, by numpy."""
    sys = _system(4)
    w = _work_for(sys)
    phi = np.zeros(NN)
    assert _condensed_solve(ND, w, NB, phi, phi)
    rng = np.random.default_rng(5)
    g1, res1 = rng.normal(size=sys["g"].size), rng.normal(size=NB)
    w.g_trial[:] = g1
    w.res_b[:NB] = res1
    du1, dz1 = _dense_step(sys, g1, res1, 0.0)
    assert simplified_norm(ND, w, NB, 0.0, HREF) == pytest.approx(_norm(du1, dz1), rel=1e-10)

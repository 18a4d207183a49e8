"""The line search's watchdog (kernels/watchdog.py): a pair that fails is
undone to the state saved before its tentative step, the mesh's element
lengths recomputed from the restored boundaries; Armijo's test on the pair."""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from pipelay_fast.kernels.watchdog import pair_passes, watch_step, watch_work

Mesh = namedtuple("Mesh", "s_a s_b s_bd s_el bnodes")
Sup = namedtuple("Sup", "fric geom")
Work = namedtuple("Work", "u_old bnd_old")
Ends = namedtuple("Ends", "tb")


def _state(rng):
    s_a = np.linspace(0.0, 60.0, 7)
    s_b = np.zeros((2, 7))
    s_b[0, 1:] = 1.0  # every node but the first follows boundary 0
    mesh = Mesh(s_a, s_b, np.array([10.0, 40.0]), np.zeros(6), np.array([2, 5]))
    sup = Sup(rng.normal(size=(7, 4)), rng.normal(size=(3, 5)))
    return mesh, sup


def test_failed_pair_restores_the_state_before_its_tentative_step():
    rng = np.random.default_rng(3)
    mesh, sup = _state(rng)
    u = rng.normal(size=35)
    ends = Ends(np.array([7.5e4]))
    before = (u.copy(), mesh.s_bd.copy(), sup.fric.copy(), sup.geom.copy())
    w = Work(u.copy(), mesh.s_bd.copy())
    wd = watch_work(u, mesh, sup)
    # a tentative step from merit 1.0 (alpha 1), a point had changed branch
    watch, watching, changed = watch_step(wd, w, u, mesh, sup, ends, False, True, True, 50.0,
                                          1.0, 1.0, 7.5e4, True, 1e-6)
    assert (watch, watching, changed) == (True, True, True)
    # the step and the contacts' update move everything
    u += 1.0
    mesh.s_bd[:] = [12.0, 41.0]
    sup.fric[:] = 0.0
    sup.geom[:] = 0.0
    ends.tb[0] = 8e4
    # the second step ends above (1 - 1e-4) of the merit before the pair
    watch, watching, changed = watch_step(wd, w, u, mesh, sup, ends, True, False, True,
                                          0.99999, 50.0, 1.0, 8e4, False, 1e-6)
    assert (watch, watching, changed) == (False, False, True)
    for got, want in zip((u, mesh.s_bd, sup.fric, sup.geom), before, strict=True):
        np.testing.assert_array_equal(got, want)
    assert ends.tb[0] == 7.5e4
    # element lengths: 10 m apart, plus the first element's share of s_bd[0] = 10
    np.testing.assert_allclose(mesh.s_el, [20.0, 10.0, 10.0, 10.0, 10.0, 10.0])


def test_pair_passes_armijo_against_the_merit_before_both():
    rng = np.random.default_rng(4)
    mesh, sup = _state(rng)
    u = np.zeros(35)
    wd = watch_work(u, mesh, sup)
    w = Work(u.copy(), mesh.s_bd.copy())
    watch_step(wd, w, u, mesh, sup, Ends(np.zeros(1)), False, True, True, 9.0, 2.0, 0.5, 0.0,
               False, 1e-6)
    # merit before 2.0, alpha 0.5: the bound is (1 - 0.5e-4) * 2.0
    assert pair_passes(wd, True, 2.0 * (1.0 - 0.5e-4), 1e-6)
    assert not pair_passes(wd, True, 2.0 * (1.0 - 0.4e-4), 1e-6)
    assert not pair_passes(wd, False, 1.0, 1e-6)  # the second step's search failed
    assert pair_passes(wd, True, 1e-12, 1e-6)  # at the tolerance's floor (tol^2)
    assert not pair_passes(wd, True, 3.0, 1e-6)

"""The line search's watchdog (kernels/watchdog.py): a window that fails
Armijo's test at a state that moves the boundaries is undone to the state
saved before its tentative step, the mesh's element lengths recomputed
from the restored boundaries; one that fails while the iteration holds the
boundaries goes on untouched; Armijo's bound on the window."""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from pipelay_fast.kernels.watchdog import (
    NONE,
    RESTORED,
    watch_judge,
    watch_step,
    watch_work,
    window_passes,
)

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


def _moved(u, mesh, sup, ends):
    """The window's steps and the contacts' updates move everything."""
    u += 1.0
    mesh.s_bd[:] = [12.0, 41.0]
    sup.fric[:] = 0.0
    sup.geom[:] = 0.0
    ends.tb[0] = 8e4


def test_failed_window_restores_the_state_before_its_tentative_step():
    rng = np.random.default_rng(3)
    mesh, sup = _state(rng)
    u = rng.normal(size=35)
    ends = Ends(np.array([7.5e4]))
    before = (u.copy(), mesh.s_bd.copy(), sup.fric.copy(), sup.geom.copy())
    w = Work(u.copy(), mesh.s_bd.copy())
    wd = watch_work(u, mesh, sup)
    # a tentative step from merit 1.0 (alpha 1), a point had changed branch
    window = watch_step(wd, w, sup, NONE, True, 1.0, 1.0, 7.5e4, True)
    assert window == 0
    _moved(u, mesh, sup, ends)
    # right after the tentative step the window is not judged
    assert watch_judge(wd, u, mesh, sup, ends, 0, 50.0, False, False, 1e-6) == (0, False)
    window = watch_step(wd, w, sup, window, False, 50.0, 1.0, 8e4, False)
    assert window == 1
    # above (1 - 1e-4) of the merit before the tentative step, not held: undone
    window, changed = watch_judge(wd, u, mesh, sup, ends, window, 0.99999, False, False, 1e-6)
    assert (window, changed) == (RESTORED, True)
    for got, want in zip((u, mesh.s_bd, sup.fric, sup.geom), before, strict=True):
        np.testing.assert_array_equal(got, want)
    assert ends.tb[0] == 7.5e4
    # element lengths: 10 m apart, plus the first element's share of s_bd[0] = 10
    np.testing.assert_allclose(mesh.s_el, [20.0, 10.0, 10.0, 10.0, 10.0, 10.0])
    # the step searched again is counted outside any window
    assert watch_step(wd, w, sup, RESTORED, False, 1.0, 1.0, 7.5e4, False) == NONE


def test_window_goes_on_while_the_boundaries_are_held_and_closes_when_it_passes():
    rng = np.random.default_rng(5)
    mesh, sup = _state(rng)
    u = rng.normal(size=35)
    ends = Ends(np.array([7.5e4]))
    w = Work(u.copy(), mesh.s_bd.copy())
    wd = watch_work(u, mesh, sup)
    window = watch_step(wd, w, sup, NONE, True, 2.0, 0.5, 7.5e4, False)
    window = watch_step(wd, w, sup, window, False, 9.0, 1.0, 7.5e4, False)
    _moved(u, mesh, sup, ends)
    after = (u.copy(), mesh.s_bd.copy(), sup.fric.copy(), sup.geom.copy(), ends.tb.copy())
    # failing, held (the pipe's correction on the moved mesh goes on): untouched
    assert watch_judge(wd, u, mesh, sup, ends, window, 3.0, True, True, 1e-6) == (1, True)
    window = watch_step(wd, w, sup, window, False, 3.0, 1.0, 8e4, True)
    assert window == 2
    # passing: closed, untouched
    assert watch_judge(wd, u, mesh, sup, ends, window, 1.0, False, False, 1e-6) == (NONE, False)
    for got, want in zip((u, mesh.s_bd, sup.fric, sup.geom, ends.tb), after, strict=True):
        np.testing.assert_array_equal(got, want)


def test_window_passes_armijo_against_the_merit_before_the_tentative_step():
    rng = np.random.default_rng(4)
    mesh, sup = _state(rng)
    u = np.zeros(35)
    wd = watch_work(u, mesh, sup)
    w = Work(u.copy(), mesh.s_bd.copy())
    watch_step(wd, w, sup, NONE, True, 2.0, 0.5, 0.0, False)
    # merit before 2.0, alpha 0.5: the bound is (1 - 0.5e-4) * 2.0
    assert window_passes(wd, 2.0 * (1.0 - 0.5e-4), 1e-6)
    assert not window_passes(wd, 2.0 * (1.0 - 0.4e-4), 1e-6)
    assert window_passes(wd, 1e-12, 1e-6)  # at the tolerance's floor (tol^2)
    assert not window_passes(wd, 3.0, 1e-6)

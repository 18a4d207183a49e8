"""The line search's watchdog (kernels/watchdog.py): a window one of whose
steps its own line search does not accept is undone to the state saved
before its tentative step, the mesh's element lengths recomputed from the
restored boundaries; one whose steps are accepted but stay above Armijo's
bound goes on untouched, held or not, and closes at the first below it;
Armijo's bound on the window."""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from pipelay_fast.kernels.watchdog import (
    NONE,
    RESTORED,
    tentative_held,
    watch_step,
    watch_work,
    window_passes,
)

Mesh = namedtuple("Mesh", "s_a s_b s_bd s_el bnodes")
Sup = namedtuple("Sup", "fric geom")
Work = namedtuple("Work", "u_old bnd_old")
Ends = namedtuple("Ends", "tb")
TOL = 1e-6


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


def _step(wd, w, u, mesh, sup, ends, window, hold, accepted, m1, changed=False):
    """A step of the window (not tentative): ``watch_step``'s verdict."""
    return watch_step(wd, w, u, mesh, sup, ends, window, False, hold, accepted, m1, 5.0, 1.0,
                      8e4, changed, TOL)


def test_failed_window_restores_the_state_before_its_tentative_step():
    rng = np.random.default_rng(3)
    mesh, sup = _state(rng)
    u = rng.normal(size=35)
    ends = Ends(np.array([7.5e4]))
    before = (u.copy(), mesh.s_bd.copy(), sup.fric.copy(), sup.geom.copy())
    w = Work(u.copy(), mesh.s_bd.copy())
    wd = watch_work(u, mesh, sup)
    # a tentative step from merit 1.0 (alpha 1), a point had changed branch
    window, changed = watch_step(wd, w, u, mesh, sup, ends, NONE, True, False, True, 50.0, 1.0,
                                 1.0, 7.5e4, True, TOL)
    assert (window, changed) == (0, True)
    _moved(u, mesh, sup, ends)
    # a step accepted by its own search but above (1 - 1e-4) of the merit
    # before the tentative one: the window goes on
    window, changed = _step(wd, w, u, mesh, sup, ends, window, False, True, 0.99999)
    assert (window, changed) == (1, False)
    # a step its own line search did not accept undoes the window
    window, changed = _step(wd, w, u, mesh, sup, ends, window, False, False, 0.5)
    assert (window, changed) == (RESTORED, True)
    assert not tentative_held(wd)
    for got, want in zip((u, mesh.s_bd, sup.fric, sup.geom), before, strict=True):
        np.testing.assert_array_equal(got, want)
    assert ends.tb[0] == 7.5e4
    # element lengths: 10 m apart, plus the first element's share of s_bd[0] = 10
    np.testing.assert_allclose(mesh.s_el, [20.0, 10.0, 10.0, 10.0, 10.0, 10.0])
    # the step searched again is outside any window
    assert _step(wd, w, u, mesh, sup, ends, RESTORED, False, False, 9.0) == (NONE, False)


def test_window_goes_on_through_converging_steps_and_closes_when_one_passes():
    rng = np.random.default_rng(5)
    mesh, sup = _state(rng)
    u = rng.normal(size=35)
    ends = Ends(np.array([7.5e4]))
    w = Work(u.copy(), mesh.s_bd.copy())
    wd = watch_work(u, mesh, sup)
    # a held tentative step
    window, _ = watch_step(wd, w, u, mesh, sup, ends, NONE, True, True, True, 9.0, 2.0, 0.5,
                           7.5e4, False, TOL)
    assert tentative_held(wd)
    _moved(u, mesh, sup, ends)
    after = (u.copy(), mesh.s_bd.copy(), sup.fric.copy(), sup.geom.copy(), ends.tb.copy())
    # steps above the bound, held or not: the window goes on, the state untouched
    assert _step(wd, w, u, mesh, sup, ends, window, True, True, 3.0, True) == (1, True)
    assert _step(wd, w, u, mesh, sup, ends, 1, False, True, 2.5) == (2, False)
    # a step of the window taken whole (tentative) from merit 2.5: the
    # window goes on, its reference still the merit 2.0 before the first
    assert watch_step(wd, w, u, mesh, sup, ends, 2, True, False, True, 40.0, 2.5, 1.0, 8e4,
                      False, TOL) == (3, False)
    assert not window_passes(wd, True, 2.4, TOL) and window_passes(wd, True, 1.9, TOL)
    window = 2
    # a held step that passes closes the window, untouched
    assert _step(wd, w, u, mesh, sup, ends, window, True, True, 1.0) == (NONE, False)
    for got, want in zip((u, mesh.s_bd, sup.fric, sup.geom, ends.tb), after, strict=True):
        np.testing.assert_array_equal(got, want)
    # a held step its own line search did not accept undoes the window
    assert _step(wd, w, u, mesh, sup, ends, 2, True, False, 3.0)[0] == RESTORED
    assert tentative_held(wd)


def test_window_passes_armijo_against_the_merit_before_the_tentative_step():
    rng = np.random.default_rng(4)
    mesh, sup = _state(rng)
    u = np.zeros(35)
    wd = watch_work(u, mesh, sup)
    w = Work(u.copy(), mesh.s_bd.copy())
    watch_step(wd, w, u, mesh, sup, Ends(np.zeros(1)), NONE, True, False, True, 9.0, 2.0, 0.5,
               0.0, False, TOL)
    # merit before 2.0, alpha 0.5: the bound is (1 - 0.5e-4) * 2.0
    assert window_passes(wd, True, 2.0 * (1.0 - 0.5e-4), TOL)
    assert not window_passes(wd, True, 2.0 * (1.0 - 0.4e-4), TOL)
    assert not window_passes(wd, False, 1.0, TOL)  # the step's own search failed
    assert window_passes(wd, True, 1e-12, TOL)  # at the tolerance's floor (tol^2)
    assert not window_passes(wd, True, 3.0, TOL)

"""The watchdog of the line search (Nocedal and Wright, Numerical
Optimization, 2006, Sec. 15.5): a step on a mesh whose boundaries are
unknowns that fails Armijo's test at its full length is taken whole,
tentatively, the state before it saved. Its window is the iteration after
it, each step searched as any other (one that fails at its full length again
taken whole, the window's reference kept): the first step whose merit passes
Armijo's test against the merit before the tentative step (or is at the
tolerance's floor) closes the window, the tentative step kept; a step no
trial of whose search is accepted (not even a finite full step) undoes it:
the state is restored and the tentative step searched again by
backtracking, without the watchdog. A window whose iteration runs away ends
the call as any iteration that runs away (tuning.RUNAWAY: the load path's
step is then cut and solved again from its start).

Why: a step that moves the boundaries moves the mesh under the pipe, and the
weighted residual rises across it in the stiff rows of the boundaries'
zones although the steps after it (the held ones with the boundaries where
the step put them) bring the pipe back to balance: the residual after the
step is not a distance to the answer there, the iteration's return below
where it started is. A Newton step from so far out of balance leaves a
residual of the order of the one before the tentative step (the square of
its start, times the problem's curvature), and the correction's own steps
may rise again, so the window ends by the iteration's own outcome, not by a
count.

The window's state, ``window`` in the Newton kernel: NONE (no window open);
k >= 0 the number of steps taken after the tentative one; RESTORED the
state just restored (the next step is searched without the watchdog).
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from ._jit import jit
from .constraints import mesh_lengths
from .step import at_tolerance
from .tuning import ARMIJO

# u (ndof,) the state before the tentative step; s_bd (nbnd,) its boundaries'
# arc lengths [m]; fric, geom copies of ``sup.fric`` and ``sup.geom``
# (friction springs, rigid points' branches); x (5,) the merit before the
# tentative step, its fraction alpha, the bottom tension [N] before it,
# whether a rigid point had changed branch before it and whether it held
# the boundaries (1.0 or 0.0 each).
Watch = namedtuple("Watch", "u s_bd fric geom x")

NONE = -1
RESTORED = -2


@jit(_nrt=True)
def watch_work(u, mesh, sup):
    """The watchdog's saved state, allocated (contents undefined)."""
    return Watch(np.empty_like(u), mesh.s_bd.copy(), sup.fric.copy(), sup.geom.copy(),
                 np.zeros(5))


@jit(_nrt=False)
def watch_save(wd, w, sup, merit0, alpha, tb0, changed, hold):
    """Save the state before a tentative step (``w.u_old``, ``w.bnd_old``,
    the bottom tension ``tb0`` [N]; friction springs and points' branches as
    they are before the contacts' update) and the step's ``merit0``,
    ``alpha``, ``hold``."""
    _copy(w.u_old, wd.u)
    _copy(w.bnd_old, wd.s_bd)
    _copy2(sup.fric, wd.fric)
    _copy2(sup.geom, wd.geom)
    wd.x[0] = merit0
    wd.x[1] = alpha
    wd.x[2] = tb0
    wd.x[3] = 1.0 if changed else 0.0
    wd.x[4] = 1.0 if hold else 0.0


@jit(_nrt=False)
def window_passes(wd, accepted, m1, tol):
    """Whether a step of the window, ``accepted`` by its own line search
    and ending at merit ``m1``, passes Armijo's test against the merit
    before the tentative step, at its fraction alpha, or ends at the
    tolerance's floor."""
    return accepted and (m1 <= (1.0 - ARMIJO * wd.x[1]) * wd.x[0] or at_tolerance(m1, tol))


@jit(_nrt=False)
def watch_restore(wd, u, mesh, sup, ends):
    """Restore the state saved by :func:`watch_save`; returns whether a
    rigid point had changed branch before the tentative step (whether it
    held the boundaries: :func:`tentative_held`)."""
    _copy(wd.u, u)
    _copy(wd.s_bd, mesh.s_bd)
    mesh_lengths(mesh.s_a, mesh.s_b, mesh.s_bd, mesh.s_el)
    _copy2(wd.fric, sup.fric)
    _copy2(wd.geom, sup.geom)
    ends.tb[0] = wd.x[2]
    return wd.x[3] != 0.0


@jit(_nrt=False)
def tentative_held(wd):
    """Whether the tentative step saved in ``wd`` held the boundaries (its
    search again holds them too)."""
    return wd.x[4] != 0.0


@jit(_nrt=False)
def watch_step(wd, w, u, mesh, sup, ends, window, tentative, hold, accepted, m1, merit0, alpha,
               tb0, changed, tol):
    """After a line search (its step ``hold`` or not, ``accepted``, ending at
    merit ``m1``): a ``tentative`` step's state before it saved (``merit0``,
    ``alpha``, the bottom tension ``tb0`` [N] before it, ``changed``,
    ``hold``), or a step of an open window judged. Returns (the window's
    state: NONE, the steps taken after the tentative one, RESTORED; whether
    a rigid point changed branch, restored with the state)."""
    if window < 0:  # no window open (or the step searched again)
        if tentative:
            watch_save(wd, w, sup, merit0, alpha, tb0, changed, hold)
            return 0, changed
        return NONE, changed
    if window_passes(wd, accepted, m1, tol):
        return NONE, changed
    if accepted:  # (a step of the window taken whole is accepted too)
        return window + 1, changed
    return RESTORED, watch_restore(wd, u, mesh, sup, ends)


@jit(_nrt=False)
def _copy(src, dst):
    """``dst`` = ``src`` (1-D)."""
    for i in range(src.shape[0]):
        dst[i] = src[i]


@jit(_nrt=False)
def _copy2(src, dst):
    """``dst`` = ``src`` (2-D)."""
    for i in range(src.shape[0]):
        for j in range(src.shape[1]):
            dst[i, j] = src[i, j]

"""The watchdog of the line search (Nocedal and Wright, Numerical
Optimization, 2006, Sec. 15.5): a step that moves the contact boundaries
and fails Armijo's test is taken tentatively, the state before it saved.
Its window is the step after it and, while they do not pass, the held
steps that follow (the pipe brought back to balance on the mesh the
boundaries moved, as a second-order correction restores the constraints
after a step). Each step of the window is judged by Armijo's test of the
merit its line search ends at against the merit before the tentative
step: passed (and accepted by its own line search), the window closes;
failed, a held step's correction goes on; failed otherwise (an unheld
step, or a step its own line search did not accept), the state is
restored and the tentative step searched again without the watchdog.

Why: a step that moves the boundaries moves the mesh under the pipe, and the
weighted residual rises across it in the stiff rows of the boundaries'
zones although the held steps after it, with the boundaries where the step
put them, bring the pipe back to balance: the residual after the step is
not a distance to the answer there, after its correction it is. A Newton
step from so far out of balance leaves a residual of the order of the one
before the tentative step (the square of its start, times the problem's
curvature), so the correction may take more than one step.

The window's state, ``window`` in the Newton kernel: NONE (the next step
may be tentative); k >= 0 the number of steps taken after the tentative
one; RESTORED the state just restored (the next step is searched without
the watchdog).
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
# (friction springs, rigid points' branches); x (4,) the merit before the
# tentative step, its fraction alpha, the bottom tension [N] before it, and
# whether a rigid point had changed branch before it (1.0 or 0.0).
Watch = namedtuple("Watch", "u s_bd fric geom x")

NONE = -1
RESTORED = -2


@jit(_nrt=True)
def watch_work(u, mesh, sup):
    """The watchdog's saved state, allocated (contents undefined)."""
    return Watch(np.empty_like(u), mesh.s_bd.copy(), sup.fric.copy(), sup.geom.copy(),
                 np.zeros(4))


@jit(_nrt=False)
def watch_save(wd, w, sup, merit0, alpha, tb0, changed):
    """Save the state before a tentative step (``w.u_old``, ``w.bnd_old``,
    the bottom tension ``tb0`` [N]; friction springs and points' branches as
    they are before the contacts' update) and the step's ``merit0``, ``alpha``."""
    _copy(w.u_old, wd.u)
    _copy(w.bnd_old, wd.s_bd)
    _copy2(sup.fric, wd.fric)
    _copy2(sup.geom, wd.geom)
    wd.x[0] = merit0
    wd.x[1] = alpha
    wd.x[2] = tb0
    wd.x[3] = 1.0 if changed else 0.0


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
    rigid point had changed branch before the tentative step."""
    _copy(wd.u, u)
    _copy(wd.s_bd, mesh.s_bd)
    mesh_lengths(mesh.s_a, mesh.s_b, mesh.s_bd, mesh.s_el)
    _copy2(wd.fric, sup.fric)
    _copy2(wd.geom, sup.geom)
    ends.tb[0] = wd.x[2]
    return wd.x[3] != 0.0


@jit(_nrt=False)
def watch_step(wd, w, u, mesh, sup, ends, window, tentative, hold, accepted, m1, merit0, alpha,
               tb0, changed, tol):
    """After a line search (its step ``hold`` or not, ``accepted``, ending at
    merit ``m1``): a ``tentative`` step's state before it saved (``merit0``,
    ``alpha``, the bottom tension ``tb0`` [N] before it, ``changed``), or a
    step of an open window judged. Returns (the window's state: NONE, the
    steps taken after the tentative one, RESTORED; whether a rigid point
    changed branch, restored with the state)."""
    if tentative:
        watch_save(wd, w, sup, merit0, alpha, tb0, changed)
        return 0, changed
    if window < 0 or window_passes(wd, accepted, m1, tol):
        return NONE, changed
    if hold and accepted:
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

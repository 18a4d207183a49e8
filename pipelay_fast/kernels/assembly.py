"""Global assembly into band storage, nodal frames, and torque distribution."""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba.core import types
from numba.extending import overload

from . import layout as L
from ._jit import jit, phase
from .banded import band_add_block
from .element import element_force_ws
from .element2d import element_2d
from .element_shapes import WORK_SIZE
from .types import Model, load_factors


def element_forces(nd, le, ue, model, sec, torque, fe, ke, want_tangent, dfe, want_dle, ws, wm):
    """One element's G, dG/du and dG/dle: the planar kernel in 2D
    (:func:`.element2d.element_2d`), the spatial one in 3D
    (:func:`.element.element_force_ws`), with the same arguments.

    In a kernel compiled for its dimension (``nd`` a literal, see
    :func:`pipelay_fast.kernels._jit.plain_calls`) the choice is made when it is
    typed, so only that dimension's element kernel is compiled
    (:func:`_element_forces_impl`). numba compiles the ``overload``'s
    implementation once for each set of argument types it is typed with,
    literals included, and each caller's settings: so the arguments but
    ``nd`` are to be plain values at every call (a flag set to False, then
    maybe True, is typed as the literal False once: one compilation more),
    and one kernel calls it (:func:`.system._system`), since each compiled
    function up the element's call chain optimises and compiles the
    element's machine code again in its own module
    (``benchmarks/bench_compile.py``). From Python, or with ``nd`` a plain
    integer, it branches at run time (called from Python, it runs
    :func:`element_forces_py`)."""
    element_forces_py(nd, le, ue, model, sec, torque, fe, ke, want_tangent, dfe, want_dle, ws, wm)


@overload(element_forces, prefer_literal=True, jit_options={"_nrt": False})
def _element_forces_impl(nd, le, ue, model, sec, torque, fe, ke, want_tangent, dfe, want_dle,
                         ws, wm):
    if isinstance(nd, types.IntegerLiteral) and nd.literal_value == 2:
        def planar(nd, le, ue, model, sec, torque, fe, ke, want_tangent, dfe, want_dle, ws, wm):
            element_2d(nd, le, ue, model, sec, torque, fe, ke, want_tangent, dfe, want_dle, ws, wm)
        return planar
    if isinstance(nd, types.IntegerLiteral):
        def spatial(nd, le, ue, model, sec, torque, fe, ke, want_tangent, dfe, want_dle, ws, wm):
            element_force_ws(nd, le, ue, model, sec, torque, fe, ke, want_tangent, dfe, want_dle,
                             ws, wm)
        return spatial

    def either(nd, le, ue, model, sec, torque, fe, ke, want_tangent, dfe, want_dle, ws, wm):
        element_forces_py(nd, le, ue, model, sec, torque, fe, ke, want_tangent, dfe, want_dle,
                          ws, wm)  # (the branch on nd at run time)
    return either


ElementWork = namedtuple("ElementWork", ["fe", "ke", "dfe", "ws", "wm"])
ElementWork.__doc__ = """One element's outputs and scratch, given to the kernels that loop
over elements (:func:`element_work`): ``fe`` (ne,) its G, ``ke`` (ne, ne)
dG/due, ``dfe`` (ne,) dG/dle, ``ws`` (WORK_SIZE,) and ``wm`` (3, 3) the
element kernel's scratch (ne = 2 (2 nd + 1) unknowns)."""


@phase
def element_work(nd):
    """Allocate an :data:`ElementWork` for dimension ``nd`` (left unset)."""
    ne = 2 * (2 * nd + 1)
    return ElementWork(np.empty(ne), np.empty((ne, ne)), np.empty(ne), np.empty(WORK_SIZE),
                       np.empty((3, 3)))


@phase
def assemble(nd, s_el, u, model, torques, ab, kl, ku, g, want_tangent, s_b, bnodes, bcols, ew):
    """Global residual ``g`` (= internal - distributed external forces) and tangent.

    ``u`` holds the nodal unknowns node by node, so element ``e`` owns the
    contiguous slice ``u[e*ndn : e*ndn + 2*ndn]`` and its block lands inside the
    band. Nodal loads, rotations and constraints are applied afterwards.

    With the tangent, each contact boundary b that is an unknown
    (``bnodes[b] >= 0``) gets its column dG/ds_b at fixed ``u`` in ``bcols[b]``,
    in the same pass: the mesh maps node i to s_a[i] + sum_b s_b[b, i] s_bd[b],
    so s_b changes element e's length at the rate s_b[b, e+1] - s_b[b, e], and
    the column is the sum of the elements' dG/dle times those rates.

    ``ew`` (:data:`ElementWork`) is the element's scratch. (Inlined into a
    kernel compiled without numba's reference counting, as the element
    kernels are: the counts on each element's slice of ``u`` and on the
    arrays passed down cost more than the element's residual.)
    """
    ndn = 2 * nd + 1
    ne = 2 * ndn
    nel = s_el.shape[0]
    nbnd = bnodes.shape[0]
    fe, ke, dfe = ew.fe, ew.ke, ew.dfe
    g[:] = 0.0
    any_bnd = False
    if want_tangent:
        ab[:, :] = 0.0
        for b in range(nbnd):
            if bnodes[b] >= 0:
                any_bnd = True
                bcols[b, :] = 0.0
    for e in range(nel):
        g0 = e * ndn
        moving = 0  # the boundaries that move the element's length
        if any_bnd:
            for b in range(nbnd):
                if bnodes[b] >= 0 and s_b[b, e + 1] != s_b[b, e]:
                    moving += 1
        want_dle = moving > 0  # (a bool, never a literal: see element_forces)
        element_forces(nd, s_el[e], u[g0:g0 + ne], model, model.section[e], torques[e], fe, ke,
                       want_tangent, dfe, want_dle, ew.ws, ew.wm)
        for a in range(ne):
            g[g0 + a] += fe[a]
        if want_tangent:
            band_add_block(ab, kl, ku, g0, ke)
        if want_dle:
            for b in range(nbnd):
                rate = s_b[b, e + 1] - s_b[b, e]
                if bnodes[b] >= 0 and rate != 0.0:
                    for a in range(ne):
                        bcols[b, g0 + a] += rate * dfe[a]


@jit(_nrt=False)
def distribute_torque(nd, s_el, u, props, torques):
    """Torque per element from H' + t.m = 0 with H(top) given.

    Evaluated on the current shape (chord tangents) and lagged in the Newton
    iteration: the tangent omits dH/du, which only matters when the distributed
    moment has a component along the pipe.
    """
    nel = s_el.shape[0]
    h_top = props[L.TORQUE]
    if nd != 3:
        torques[:] = 0.0
        return
    m = (props[L.MOM_X], props[L.MOM_Y], props[L.MOM_Z])
    if m[0] == 0.0 and m[1] == 0.0 and m[2] == 0.0:
        torques[:] = h_top
        return
    ndn = 2 * nd + 1
    acc = h_top
    for e in range(nel - 1, -1, -1):
        a = e * ndn
        b = a + ndn
        dx = u[b] - u[a]
        dy = u[b + 1] - u[a + 1]
        dz = u[b + 2] - u[a + 2]
        c = math.sqrt(dx * dx + dy * dy + dz * dz)
        tm = (dx * m[0] + dy * m[1] + dz * m[2]) / c if c > 0.0 else 0.0
        torques[e] = acc + 0.5 * tm * s_el[e]
        acc += tm * s_el[e]


@jit(_nrt=False)
def rotate_pair_vec(v, p, q, c, s):
    """(v_p, v_q) <- R (v_p, v_q) with R = [[c, -s], [s, c]]."""
    a = v[p]
    b = v[q]
    v[p] = c * a - s * b
    v[q] = s * a + c * b


@jit(_nrt=False)
def rotate_pair_band(ab, kl, ku, n, p, q, c, s, lo, hi):
    """K <- R K R^T on the dof pair (p, q); rows/cols coupled to it lie in [lo, hi]."""
    kv = kl + ku
    for j in range(lo, hi + 1):
        a = ab[kv + p - j, j]
        b = ab[kv + q - j, j]
        ab[kv + p - j, j] = c * a - s * b
        ab[kv + q - j, j] = s * a + c * b
    for i in range(lo, hi + 1):
        a = ab[kv + i - p, p]
        b = ab[kv + i - q, q]
        ab[kv + i - p, p] = c * a - s * b
        ab[kv + i - q, q] = s * a + c * b


@jit(_nrt=False)
def node_coupling_range(nd, node, n):
    """First and last global dof coupled to ``node`` (its two elements)."""
    ndn = 2 * nd + 1
    lo = max(0, (node - 1) * ndn)
    hi = min(n - 1, (node + 2) * ndn - 1)
    return lo, hi


@jit(_nrt=False)
def rotate_node(nd, ab, kl, ku, g, node, phi_r, phi_rp, want_tangent):
    """Express node ``node``'s (x, z) pairs of r and r' in its rotated frame.

    Local slot x becomes the normal (x cos phi - z sin phi), slot z the tangent
    (x sin phi + z cos phi): a support whose tangent makes the angle phi with the
    z axis (towards +x) constrains slot x alone.
    """
    ndn = 2 * nd + 1
    n = g.shape[0]
    base = node * ndn
    lo, hi = node_coupling_range(nd, node, n)
    for blk in range(2):
        phi = phi_r if blk == 0 else phi_rp
        if phi == 0.0:
            continue
        p = base + blk * nd
        q = p + nd - 1
        c = math.cos(phi)
        s = math.sin(phi)
        rotate_pair_vec(g, p, q, c, s)
        if want_tangent:
            rotate_pair_band(ab, kl, ku, n, p, q, c, s, lo, hi)


@jit(_nrt=False)
def curve_node(nd, ab, kl, ku, g, node, fp, fpp, zp, want_tangent):
    """Express node ``node`` in coordinates attached to a support curve x = f(z).

    The node's unknowns become (c, z, c', z') with x = f(z) + c and
    x' = f'(z) z' + c' (y, y' and lam unchanged): c = 0 puts the node on the
    curve, c' = 0 makes it tangent to it, exactly, and z, z' slide along it.
    With u = Phi(v) and J = dPhi/dv, the residual becomes J^T g and the
    tangent J^T K J + g_x f'' E_zz + g_x' f'' (E_zz' + E_z'z): the second
    derivatives of the map (x'' = f'' and d2x'/dz dz' = f'', f''' = 0 for a
    parabola) weighted by the residual there, the support's reaction, whose
    direction turns as the node slides (the term a rotated frame fixed
    during the step leaves out). ``fp``, ``fpp``: f'(z), f''(z) at the node;
    ``zp``: its z'.
    """
    ndn = 2 * nd + 1
    n = g.shape[0]
    base = node * ndn
    p = base
    q = base + nd - 1
    p2 = base + nd
    q2 = base + 2 * nd - 1
    kv = kl + ku
    cz = fpp * zp  # d x' / d z
    if want_tangent:
        lo, hi = node_coupling_range(nd, node, n)
        for i in range(lo, hi + 1):  # columns: K J
            ab[kv + i - q, q] += fp * ab[kv + i - p, p] + cz * ab[kv + i - p2, p2]
            ab[kv + i - q2, q2] += fp * ab[kv + i - p2, p2]
        for j in range(lo, hi + 1):  # rows: J^T (K J)
            ab[kv + q - j, j] += fp * ab[kv + p - j, j] + cz * ab[kv + p2 - j, j]
            ab[kv + q2 - j, j] += fp * ab[kv + p2 - j, j]
        ab[kv, q] += fpp * g[p]
        ab[kv + q - q2, q2] += fpp * g[p2]
        ab[kv + q2 - q, q] += fpp * g[p2]
    g[q] += fp * g[p] + cz * g[p2]
    g[q2] += fp * g[p2]


@jit(_nrt=False)
def element_forces_py(nd, le, ue, model, sec, torque, fe, ke, want_tangent, dfe, want_dle, ws, wm):
    """:func:`element_forces` callable from Python (tests, one-off calls): the
    branch on ``nd`` at run time (also under NUMBA_DISABLE_JIT, where calling
    :func:`element_forces` would come back here)."""
    if nd == 2:
        element_2d(nd, le, ue, model, sec, torque, fe, ke, want_tangent, dfe, want_dle, ws, wm)
    else:
        element_force_ws(nd, le, ue, model, sec, torque, fe, ke, want_tangent, dfe, want_dle,
                         ws, wm)


def element_force(nd, le, ue, props, sec, table, torque, fe, ke, want_tangent, dfe=None,
                  current_factor=1.0, bed=None):
    """Force vector ``fe`` (= G), tangent ``ke`` = dG/due and, if ``dfe`` is
    given, ``dfe`` = dG/dle of one element of section ``sec`` (N_SECTION,),
    with the current's drag times ``current_factor``, on the seabed profile
    with knots ``bed`` ((n, 3), :mod:`.bed`; None: flat).

    Allocating Python wrapper of the kernel the solves run (in 2D the planar
    one, :func:`.element2d.element_2d`; in 3D :func:`.element.element_force_ws`) for
    tests and one-off calls; it always calls it with the same argument types.
    """
    want_dle = dfe is not None
    section = np.ascontiguousarray(np.asarray(sec, dtype=np.float64).reshape(1, L.N_SECTION))
    knots = np.zeros((0, 3)) if bed is None else np.ascontiguousarray(bed, dtype=np.float64)
    model = Model(props, table, load_factors(current_factor, False), section, knots)
    element_forces_py(nd, le, ue, model, section[0], torque, fe, ke, want_tangent,
                      dfe if want_dle else np.zeros(ue.size), want_dle,
                      np.empty(WORK_SIZE), np.empty((3, 3)))

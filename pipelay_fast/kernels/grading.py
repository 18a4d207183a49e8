"""The graded mesh's arithmetic (:mod:`pipelay_fast.mesh`): its stretches
between anchors, each stretch's element count phi(t) = int 1/h ds, the
nodes at equal steps of it and their rates with the foci; and the mesh's
map onto its contact boundaries (:func:`boundary_map`,
:meth:`pipelay_fast.problem.Problem.follow`).

Kernels, not NumPy, because a solve builds and differentiates its graded mesh
several times (the cold start's mesh, the meshes graded at the boundaries
found, and each focus's rate by central differences): over such small arrays
NumPy's call overhead would cost more than a coarse mesh's Newton iterations.
"""

from __future__ import annotations

import math

import numpy as np

from ._jit import jit, phase
from .tuning import ROUNDOFF


@jit(_nrt=False)
def span_tables(a, b, focus, h_max, h_min, growth, t, phi):
    """For each stretch j from a[j] to b[j] [m], the foci ``focus`` [m]
    (at least one): samples t[j] [m] (numpy's linspace(a, b, n), sample by
    sample) and phi[j] = int_a^t 1/h ds [-] (trapezoidal), with h = min(h_max,
    h_min + (growth - 1) distance to the nearest focus)."""
    n = t.shape[1]
    rate = growth - 1.0
    for j in range(a.shape[0]):
        step = (b[j] - a[j]) / (n - 1)
        prev_t = 0.0
        prev_inv = 0.0
        for i in range(n):
            ti = i * step + a[j] if i < n - 1 else b[j]
            dist = abs(ti - focus[0])
            for k in range(1, focus.shape[0]):
                dist = min(dist, abs(ti - focus[k]))
            inv = 1.0 / min(h_max, h_min + rate * dist)
            t[j, i] = ti
            phi[j, i] = 0.0 if i == 0 else phi[j, i - 1] + 0.5 * (inv + prev_inv) * (ti - prev_t)
            prev_t = ti
            prev_inv = inv


@jit(entry=True, _nrt=False)
def place_nodes(t, phi, b, counts, nodes):
    """Node positions [m] into ``nodes`` (1 + sum(counts)): 0, then
    ``counts[j]`` elements in stretch j at equal steps of phi[j] (linear
    interpolation in the table t[j], phi[j]), its last node on b[j]."""
    nodes[0] = 0.0
    out = 1
    n = t.shape[1]
    for j in range(counts.shape[0]):
        count = counts[j]
        end = phi[j, n - 1]
        seg = 0
        for m in range(1, count + 1):
            target = m * (end / count)
            if m == count:
                nodes[out] = b[j]
            else:
                while seg < n - 2 and phi[j, seg + 1] < target:
                    seg += 1
                p0 = phi[j, seg]
                p1 = phi[j, seg + 1]
                nodes[out] = t[j, seg] + (target - p0) * (t[j, seg + 1] - t[j, seg]) / (p1 - p0)
            out += 1


NOT_ANCHOR = -2  # (boundary_map's kind: -1 a fixed material point, b >= 0 boundary b)


@jit(_nrt=False)
def _first_not_below(s, value):
    """The first index i of the ascending ``s`` with s[i] >= value (s.size
    when none): numpy's searchsorted(s, value), side "left"."""
    lo, hi = 0, s.shape[0]
    while lo < hi:
        mid = (lo + hi) // 2
        if s[mid] < value:
            lo = mid + 1
        else:
            hi = mid
    return lo


@jit(entry=True, _nrt=False)
def boundary_map(s, nodes, zones, kind, anchors, s_a, s_b, s_bd):
    """The map of a mesh onto its contact boundaries
    (:meth:`pipelay_fast.problem.Problem.follow`): each node's arc length is
    s_a[i] + sum_b s_b[b, i] s_bd[b], with s_bd the boundaries' arc lengths.

    ``s`` (nn,) the nodes' arc lengths [m]; ``nodes`` (nb,) int64 each
    boundary's node (-1: none); ``zones`` (nb, 2) [m] how far below and above
    its node boundary b's zone reaches. Anchors: the ends, the boundary nodes
    and each zone's edges (the first node beyond it), unless another boundary
    lies nearer; every node keeps its share of the span between its two
    anchors, mapped onto them (a boundary anchor moves with its boundary, the
    others stay). Work: ``kind`` (nn,) int64, ``anchors`` (nn,) int64.
    Outputs: ``s_a`` (nn,), ``s_b`` (nb, nn), ``s_bd`` (nb,) at the boundary
    nodes [m] (the other entries left as they were)."""
    nn = s.shape[0]
    nb = nodes.shape[0]
    for i in range(nn):
        kind[i] = NOT_ANCHOR
    kind[0] = -1
    kind[nn - 1] = -1
    for b in range(nb):
        if nodes[b] >= 0:
            kind[nodes[b]] = b
    for b in range(nb):
        k = nodes[b]
        if k < 0:
            continue
        # the nearest other boundary nodes below and above (a second boundary
        # on the same node bounds it above), else the ends
        lower = 0
        upper = nn - 1
        same = 0
        for c in range(nb):
            kc = nodes[c]
            if kc < 0:
                continue
            if kc < k:
                lower = max(lower, kc)
            elif kc > k:
                upper = min(upper, kc)
            else:
                same += 1
        if same > 1:
            upper = k
        lo = _first_not_below(s, s[k] - zones[b, 0]) - 1
        hi = _first_not_below(s, s[k] + zones[b, 1])
        if lower < lo < k and kind[lo] == NOT_ANCHOR:
            kind[lo] = -1
        if k < hi < upper and kind[hi] == NOT_ANCHOR:
            kind[hi] = -1
    na = 0
    for i in range(nn):
        if kind[i] != NOT_ANCHOR:
            anchors[na] = i
            na += 1
    seg = 0
    for i in range(nn):
        while seg < na - 2 and anchors[seg + 1] <= i:
            seg += 1
        a0 = anchors[seg]
        a1 = anchors[seg + 1]
        b0 = kind[a0]
        b1 = kind[a1]
        for b in range(nb):
            s_b[b, i] = 0.0
        if i == a0 or i == a1:  # an anchor: exactly its own
            if kind[i] < 0:
                s_a[i] = s[i]
            else:
                s_a[i] = 0.0
                s_b[kind[i], i] = 1.0
                s_bd[kind[i]] = s[i]
            continue
        f = (s[i] - s[a0]) / (s[a1] - s[a0])
        s_a[i] = ((1.0 - f) * s[a0] if b0 < 0 else 0.0) + (f * s[a1] if b1 < 0 else 0.0)
        if b0 >= 0:
            s_b[b0, i] = 1.0 - f
        if b1 >= 0:
            s_b[b1, i] = f


SAMPLES = 129  # samples of each stretch's element count phi(t)


@phase
def _inside(foci, length):
    """The foci inside (0, length] (one 0 when none is: those a stretch's
    element sizes grow from, :func:`span_tables`) and how many there are."""
    inside = 0
    for f in foci:
        if 0.0 < f <= length:
            inside += 1
    focus = np.zeros(max(inside, 1))
    k = 0
    for f in foci:
        if 0.0 < f <= length:
            focus[k] = f
            k += 1
    return focus, inside


@jit(entry=True, _nrt=True)
def graded_tables(length, foci, plain, h_max, h_min, growth):
    """The stretches of a graded mesh of ``length`` [m] and their tables
    (:func:`pipelay_fast.mesh.graded_nodes`): anchors at the ends, at the
    foci inside (0, length] and at the ``plain`` nodes inside it, stretches
    between successive distinct anchors more than ROUNDOFF m apart; each
    stretch's samples t and element count phi(t) (:func:`span_tables`, the
    foci inside, or 0 when none is), and its element count ceil(phi - ROUNDOFF)
    (at least 1).

    Returns (the stretches' starts a and ends b [m], t, phi (stretches,
    SAMPLES), counts (int64))."""
    focus, inside = _inside(foci, length)
    points = np.empty(2 + inside + plain.shape[0])
    points[0] = 0.0
    points[1] = length
    n = 2
    for k in range(inside):
        points[n] = focus[k]
        n += 1
    for f in plain:
        if 0.0 < f <= length:
            points[n] = f
            n += 1
    anchors = points[:n]
    for j in range(1, n):  # (insertion sort: a handful of anchors)
        v = anchors[j]
        i = j - 1
        while i >= 0 and anchors[i] > v:
            anchors[i + 1] = anchors[i]
            i -= 1
        anchors[i + 1] = v
    a = np.empty(n - 1)
    b = np.empty(n - 1)
    ns = 0
    last = anchors[0]
    for j in range(1, n):
        if anchors[j] == last:  # (distinct anchors)
            continue
        if anchors[j] - last > ROUNDOFF:
            a[ns] = last
            b[ns] = anchors[j]
            ns += 1
        last = anchors[j]
    t = np.empty((ns, SAMPLES))
    phi = np.empty((ns, SAMPLES))
    span_tables(a[:ns], b[:ns], focus, h_max, h_min, growth, t, phi)
    counts = np.empty(ns, dtype=np.int64)
    for j in range(ns):
        counts[j] = max(1, int(math.ceil(phi[j, SAMPLES - 1] - ROUNDOFF)))
    return a[:ns].copy(), b[:ns].copy(), t, phi, counts


@phase
def _base_mesh(length, points, nf, n_moving, h_max, h_min, growth):
    """The graded mesh of the foci ``points[:nf]`` and plain nodes
    ``points[nf:]``: its stretches' tables (:func:`graded_tables`), its nodes
    and a zero row of rates for each of ``n_moving`` points. Returns (a, b,
    t, phi, counts, nodes, rates)."""
    a, b, t, phi, counts = graded_tables(length, points[:nf], points[nf:], h_max, h_min, growth)
    base = np.empty(1 + counts.sum())
    place_nodes(t, phi, b, counts, base)
    return a, b, t, phi, counts, base, np.zeros((n_moving, base.shape[0]))


@jit(entry=True, _nrt=True)
def grading_rates_of(length, points, nf, moving, h_max, h_min, growth, step):
    """ds_i/df_j [-] of the graded mesh's nodes (foci ``points[:nf]``, plain
    nodes ``points[nf:]``) for each j in ``moving`` (int64), at the mesh's
    element counts: central differences over ``step`` [m], the whole mesh
    placed anew for each (:func:`_whole_mesh_moves`); in each row 0 at the
    anchors (the ends, the foci, the plain nodes) and 1 at the moved point's
    own node. Returns the rates (moving, nodes); 0 rows when a move changes
    the mesh's stretches."""
    _a, _b, _t, _phi, counts, base, rates = _base_mesh(length, points, nf, moving.shape[0],
                                                       h_max, h_min, growth)
    for r in range(moving.shape[0]):
        if not _whole_mesh_moves(length, points, nf, moving[r], h_max, h_min, growth, step,
                                 counts, rates[r]):
            return np.zeros((0, base.shape[0]))
    _pin_anchors(rates, base, points, moving, length)
    return rates


@jit(entry=True, _nrt=True)
def plain_rates_of(length, points, nf, moving, h_max, h_min, growth, step):
    """:func:`grading_rates_of` for a mesh with plain nodes, the same
    numbers: a plain node (j at least ``nf``) moves only the two stretches
    it ends, so only their tables are built anew and their nodes placed
    (:func:`_plain_node_moves`); a focus, or a plain node without two
    stretches of its own, moves the whole mesh (:func:`_whole_mesh_moves`).
    A kernel of its own so that a mesh without plain nodes never compiles
    it."""
    a, b, t, phi, counts, base, rates = _base_mesh(length, points, nf, moving.shape[0], h_max,
                                                   h_min, growth)
    focus, _count = _inside(points[:nf], length)
    for r in range(moving.shape[0]):
        j = moving[r]
        if j >= nf and _plain_node_moves(points, j, a, b, t, phi, counts, focus, h_max, h_min,
                                         growth, step, rates[r]):
            continue
        if not _whole_mesh_moves(length, points, nf, j, h_max, h_min, growth, step, counts,
                                 rates[r]):
            return np.zeros((0, base.shape[0]))
    _pin_anchors(rates, base, points, moving, length)
    return rates


@phase
def _whole_mesh_moves(length, points, nf, j, h_max, h_min, growth, step, counts, row):
    """Point j's rates into ``row`` (one value per node): the whole mesh
    built anew and placed (at the element ``counts``) with point j moved by
    +- ``step``. False when a move changes the mesh's stretches."""
    moved = points.copy()
    up = np.empty(row.shape[0])
    down = np.empty(row.shape[0])
    for sign in (1.0, -1.0):
        moved[j] = points[j] + sign * step
        _a, bm, tm, phim, own_counts = graded_tables(length, moved[:nf], moved[nf:], h_max,
                                                     h_min, growth)
        if own_counts.shape[0] != counts.shape[0]:  # another set of stretches
            return False
        place_nodes(tm, phim, bm, counts, up if sign > 0.0 else down)
    for i in range(row.shape[0]):
        row[i] = (up[i] - down[i]) / (2.0 * step)
    return True


@phase
def _pin_anchors(rates, base, points, moving, length):
    """The rates' rows (one per ``moving`` point) at the mesh's nodes
    ``base``: 0 at every anchor (the ends, ``points``), 1 at the moved
    point's own node (the nearest)."""
    nn = base.shape[0]
    for i in range(nn):
        anchor = base[i] == 0.0 or base[i] == length
        for p in points:
            anchor = anchor or base[i] == p
        if anchor:
            for r in range(moving.shape[0]):
                rates[r, i] = 0.0
    for r in range(moving.shape[0]):
        best = np.inf
        own = 0
        for i in range(nn):
            d = abs(base[i] - points[moving[r]])
            if d < best:
                best = d
                own = i
        rates[r, own] = 1.0


@jit(_nrt=True)
def _plain_node_moves(points, j, a, b, t, phi, counts, focus, h_max, h_min, growth, step, row):
    """The rates of plain node ``points[j]`` into ``row`` when it is an anchor
    of its own between two stretches longer than 2 ``step``: moved, only
    those two stretches change (their ends; the foci are the same), so only
    their tables are built anew and their nodes placed, with the numbers
    that building and placing the whole mesh would give. False (``row``
    untouched) otherwise."""
    p = points[j]
    for i in range(points.shape[0]):
        if i != j and points[i] == p:
            return False
    k = -1
    for s in range(b.shape[0] - 1):
        if b[s] == p and a[s + 1] == p:
            k = s
    if k < 0 or b[k] - a[k] <= 2.0 * step or b[k + 1] - a[k + 1] <= 2.0 * step:
        return False
    first = 0  # the index of stretch k's first node
    for s in range(k):
        first += counts[s]
    size = counts[k] + counts[k + 1]
    two_a = np.empty(2)
    two_b = np.empty(2)
    two_t = np.empty((2, t.shape[1]))
    two_phi = np.empty((2, t.shape[1]))
    up = np.empty(1 + size)
    down = np.empty(1 + size)
    for sign in (1.0, -1.0):
        two_a[0], two_b[1] = a[k], b[k + 1]
        two_b[0] = two_a[1] = p + sign * step
        span_tables(two_a, two_b, focus, h_max, h_min, growth, two_t, two_phi)
        place_nodes(two_t, two_phi, two_b, counts[k:k + 2], up if sign > 0.0 else down)
    for m in range(1, 1 + size):
        row[first + m] = (up[m] - down[m]) / (2.0 * step)
    return True

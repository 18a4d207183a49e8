"""Graded meshes in unstretched arc length.

Element size grows linearly with the distance from the nearest focus point
(touchdown, lift-off, a held top) from ``h_min`` at the focus to ``h_max``:
h(s) = min(h_max, h_min + (growth - 1) * distance), i.e. a geometric growth of
ratio ``growth`` between neighbouring elements. Each focus point is a node.

A mesh graded at contact boundaries moves with them while Newton finds them:
:func:`grading_rates` gives each node's rate of change with each focus at
fixed element counts, so the mesh a solve ends on is, to second order in the
last pass's moves, the graded mesh of the boundaries it found.
"""

from __future__ import annotations

import numpy as np

from .kernels.grading import place_nodes, span_tables

GROWTH = 1.2


_SAMPLES = 129  # samples of each span's element count phi(t)


def _anchors(length, foci, nodes=()):
    """The stretches between anchors (the ends, the foci and the plain
    ``nodes`` inside): their ends a, b [m] (stretches shorter than 1e-9 m
    dropped) and the foci [m]."""
    inside = [float(f) for f in foci if 0.0 < f <= length]
    plain_nodes = [float(f) for f in nodes if 0.0 < f <= length]
    anchors = sorted({0.0, float(length), *inside, *plain_nodes})
    pairs = [(a, b) for a, b in zip(anchors[:-1], anchors[1:], strict=True) if b - a > 1e-9]
    focus = inside or [0.0]
    return np.array([p[0] for p in pairs]), np.array([p[1] for p in pairs]), focus


def _span_tables(a, b, focus, h_max, h_min, growth):
    """For each stretch (rows of ``a``, ``b`` [m], its foci the row of
    ``focus`` [m], padded with inf): samples t [m] and the element count
    phi(t) = int 1/h ds [-] from a, both (rows, _SAMPLES)
    (:func:`.kernels.grading.span_tables`)."""
    t = np.empty((a.size, _SAMPLES))
    phi = np.empty((a.size, _SAMPLES))
    nfocus = np.isfinite(focus).sum(axis=1)
    span_tables(a, b, np.ascontiguousarray(focus, dtype=float), nfocus.astype(np.int64),
                float(h_max), float(h_min), float(growth), t, phi)
    return t, phi


def _uniform_count(length, h_max):
    return max(2, int(np.ceil(length / h_max)))


def _span_count(phi):
    return max(1, int(np.ceil(phi[-1] - 1e-9)))


def graded_nodes(length, foci, h_max, h_min, growth=GROWTH, grading=True, check=None,
                 nodes=()):
    """Node positions s in [0, length] [m], graded towards each focus point.

    Parameters
    ----------
    length : float
        Total unstretched length [m].
    foci : sequence of float
        Arc lengths [m] where the mesh is finest; kept as nodes.
    h_max, h_min : float
        Largest and smallest element length [m].
    growth : float
        Ratio between neighbouring element lengths.
    grading : bool
        False gives a uniform mesh of about ``h_max`` (foci ignored).
    check : callable or None
        Called with the element count before any node is placed (it may
        raise to refuse a mesh too large).
    nodes : sequence of float
        Arc lengths [m] kept as nodes without grading there (the material
        points over a roller stinger's rollers); ungraded, each stretch
        between them is uniform.
    """
    if not grading:  # uniform between the plain nodes
        a, b, _focus = _anchors(length, (), nodes)
        counts = ([_uniform_count(length, h_max)] if a.size == 1 else
                  [max(1, int(np.ceil((hi - lo) / h_max - 1e-9)))
                   for lo, hi in zip(a, b, strict=True)])
        if check is not None:
            check(sum(counts))
        return np.concatenate([[0.0], *[np.linspace(lo, hi, n + 1)[1:]
                                         for lo, hi, n in zip(a, b, counts, strict=True)]])
    a, b, focus = _anchors(length, foci, nodes)
    t, phi = _span_tables(a, b, np.tile(focus, (a.size, 1)), h_max, h_min, growth)
    counts = [_span_count(row) for row in phi]
    if check is not None:
        check(sum(counts))
    return _place(t, phi, b, counts)


def _place(t, phi, b, counts):
    """Node positions [m]: ``counts[j]`` elements in stretch j (row j of the
    tables ``t``, ``phi`` and of its ends ``b``), at equal steps of phi
    (:func:`.kernels.grading.place_nodes`)."""
    counts = np.asarray(counts, dtype=np.int64)
    nodes = np.empty(1 + int(counts.sum()))
    place_nodes(t, phi, np.ascontiguousarray(b, dtype=float), counts, nodes)
    return nodes


def grading_rates(length, foci, moving, h_max, h_min, growth=GROWTH, step=1e-4, nodes=()):
    """ds_i/df [-] of the nodes of :func:`graded_nodes` (graded) with respect
    to the foci ``foci[j]`` for j in ``moving``, at fixed element counts per
    span: central differences over ``step`` [m] (the nodes are smooth in the
    foci between changes of count). One row per entry of ``moving``; a
    focus's own node moves with it at rate 1, the other anchors at 0. The
    stretches of the mesh and of every moved set of foci are tabulated in
    one pass (:func:`_span_tables`). ``nodes``: the plain nodes of
    :func:`graded_nodes`; an entry j of ``moving`` past the foci moves
    nodes[j - len(foci)]."""
    points = [*foci, *nodes]
    nf = len(foci)
    variants = [points]
    variants.extend([f + sign * step if i == j else f for i, f in enumerate(points)]
                    for j in moving for sign in (1.0, -1.0))
    parts = [_anchors(length, v[:nf], v[nf:]) for v in variants]
    if any(p[0].size != parts[0][0].size for p in parts):
        raise ValueError(f"grading_rates: moving foci {list(moving)} by {step} m changes the "
                         f"mesh's stretches (foci {list(foci)} on a length of {length} m)")
    width = max(len(p[2]) for p in parts)
    a = np.concatenate([p[0] for p in parts])
    b = np.concatenate([p[1] for p in parts])
    focus = np.full((a.size, width), np.inf)
    row = 0
    for pa, _pb, pf in parts:
        focus[row:row + pa.size, :len(pf)] = pf
        row += pa.size
    t, phi = _span_tables(a, b, focus, h_max, h_min, growth)
    meshes = []
    counts = None
    row = 0
    for pa, _pb, _pf in parts:
        rows = slice(row, row + pa.size)
        if counts is None:
            counts = [_span_count(p) for p in phi[rows]]
        meshes.append(_place(t[rows], phi[rows], b[rows], counts))
        row += pa.size
    base = meshes[0]
    rates = np.zeros((len(moving), base.size))
    anchors = np.isin(base, [0.0, length, *points])
    for r, j in enumerate(moving):
        rates[r] = (meshes[1 + 2 * r] - meshes[2 + 2 * r]) / (2.0 * step)
        own = int(np.argmin(np.abs(base - points[j])))
        rates[r, anchors] = 0.0
        rates[r, own] = 1.0
    return rates

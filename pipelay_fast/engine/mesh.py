"""Graded meshes in unstretched arc length (engine layer; the arithmetic is
:mod:`pipelay_fast.kernels.grading`'s).

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

from ..kernels.grading import graded_tables, grading_rates_of, place_nodes, plain_rates_of
from . import tuning as T


def graded_nodes(length, foci, h_max, h_min, growth=T.GROWTH, grading=True, check=None,
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

    Returns
    -------
    numpy.ndarray
        The node positions [m], ascending from 0 to ``length``.
    """
    if not grading:  # uniform between the plain nodes
        a, b, _t, _phi, _counts = _tables(length, (), nodes, h_max, h_max, growth)
        counts = [max(1, int(np.ceil((hi - lo) / h_max - T.REL_ROUNDOFF)))
                  for lo, hi in zip(a, b, strict=True)]
        if check is not None:
            check(sum(counts))
        return np.concatenate([[0.0], *[np.linspace(lo, hi, n + 1)[1:]
                                         for lo, hi, n in zip(a, b, counts, strict=True)]])
    _a, b, t, phi, counts = _tables(length, foci, nodes, h_max, h_min, growth)
    if check is not None:
        check(int(counts.sum()))
    return _place(t, phi, b, counts)


def _tables(length, foci, nodes, h_max, h_min, growth):
    """The mesh's stretches between its anchors, and their tables
    (:func:`pipelay_fast.kernels.grading.graded_tables`)."""
    return graded_tables(float(length), np.asarray(foci, dtype=float).reshape(-1),
                         np.asarray(nodes, dtype=float).reshape(-1), float(h_max), float(h_min),
                         float(growth))


def _place(t, phi, b, counts):
    """Node positions [m]: ``counts[j]`` elements in stretch j (row j of the
    tables ``t``, ``phi`` and of its ends ``b``), at equal steps of phi
    (:func:`pipelay_fast.kernels.grading.place_nodes`)."""
    counts = np.asarray(counts, dtype=np.int64)
    nodes = np.empty(1 + int(counts.sum()))
    place_nodes(t, phi, np.ascontiguousarray(b, dtype=float), counts, nodes)
    return nodes


def grading_rates(length, foci, moving, h_max, h_min, growth=T.GROWTH, step=1e-4, nodes=()):
    """ds_i/df [-] of the nodes of :func:`graded_nodes` (graded) with respect
    to the foci ``foci[j]`` for j in ``moving``, at fixed element counts per
    span: central differences over ``step`` [m] (the nodes are smooth in the
    foci between changes of count). One row per entry of ``moving``; a
    focus's own node moves with it at rate 1, the other anchors at 0; every
    moved mesh has the element counts of the mesh itself. ``nodes``: the plain nodes of
    :func:`graded_nodes`; an entry j of ``moving`` past the foci moves
    nodes[j - len(foci)] (its rates from the two stretches it ends where it
    is an anchor of its own, :func:`pipelay_fast.kernels.grading.plain_rates_of`).
    Returns an array (len(moving), number of nodes). ValueError when a move
    of ``step`` changes the mesh's stretches."""
    points = np.array([*foci, *nodes], dtype=float)
    moving = np.asarray(moving, dtype=np.int64).reshape(-1)
    kernel = plain_rates_of if (moving >= len(foci)).any() else grading_rates_of
    rates = kernel(float(length), points, len(foci), moving, float(h_max), float(h_min),
                   float(growth), float(step))
    if rates.shape[0] != moving.size:
        raise ValueError(f"grading_rates: moving foci {moving.tolist()} by {step} m changes "
                         f"the mesh's stretches (foci {list(foci)} on a length of {length} m)")
    return rates

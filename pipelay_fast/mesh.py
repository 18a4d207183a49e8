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

GROWTH = 1.2


def _spans(length, foci, h_max, h_min, growth):
    """Per stretch between anchors (the ends and the foci): its ends a, b [m],
    129 samples t [m] and the element count phi(t) = int 1/h ds [-] from a."""
    inside = [float(f) for f in foci if 0.0 < f <= length]
    anchors = sorted({0.0, float(length), *inside})
    focus = np.array(inside or [0.0])
    rate = growth - 1.0
    for a, b in zip(anchors[:-1], anchors[1:], strict=True):
        if b - a <= 1e-9:
            continue
        t = np.linspace(a, b, 129)
        dist = np.min(np.abs(t[:, None] - focus[None, :]), axis=1)
        inv = 1.0 / np.minimum(h_max, h_min + rate * dist)
        phi = np.concatenate(([0.0], np.cumsum(0.5 * (inv[1:] + inv[:-1]) * np.diff(t))))
        yield a, b, t, phi


def _uniform_count(length, h_max):
    return max(2, int(np.ceil(length / h_max)))


def _span_count(phi):
    return max(1, int(np.ceil(phi[-1] - 1e-9)))


def graded_nodes(length, foci, h_max, h_min, growth=GROWTH, grading=True, check=None):
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
    """
    if not grading:
        n = _uniform_count(length, h_max)
        if check is not None:
            check(n)
        return np.linspace(0.0, length, n + 1)
    spans = list(_spans(length, foci, h_max, h_min, growth))
    counts = [_span_count(phi) for *_, phi in spans]
    if check is not None:
        check(sum(counts))
    return _place(spans, counts)


def _place(spans, counts):
    """Node positions [m]: ``counts[j]`` elements in span j, equal steps of phi."""
    nodes = [0.0]
    for (_a, b, t, phi), count in zip(spans, counts, strict=True):
        targets = np.linspace(0.0, phi[-1], count + 1)[1:]
        nodes.extend(np.interp(targets, phi, t))
        nodes[-1] = b
    return np.asarray(nodes)


def grading_rates(length, foci, moving, h_max, h_min, growth=GROWTH, step=1e-4):
    """ds_i/df [-] of the nodes of :func:`graded_nodes` (graded) with respect
    to the foci ``foci[j]`` for j in ``moving``, at fixed element counts per
    span: central differences over ``step`` [m] (the nodes are smooth in the
    foci between changes of count). One row per entry of ``moving``; a
    focus's own node moves with it at rate 1, the other anchors at 0."""
    spans = list(_spans(length, foci, h_max, h_min, growth))
    counts = [_span_count(phi) for *_, phi in spans]
    base = _place(spans, counts)
    rates = np.zeros((len(moving), base.size))
    anchors = np.isin(base, [0.0, length, *foci])
    for row, j in enumerate(moving):
        ends = []
        for sign in (1.0, -1.0):
            moved = [f + sign * step if i == j else f for i, f in enumerate(foci)]
            ends.append(_place(list(_spans(length, moved, h_max, h_min, growth)), counts))
        rates[row] = (ends[0] - ends[1]) / (2.0 * step)
        own = int(np.argmin(np.abs(base - foci[j])))
        rates[row, anchors] = 0.0
        rates[row, own] = 1.0
    return rates

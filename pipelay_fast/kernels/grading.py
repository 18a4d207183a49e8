"""The graded mesh's arithmetic (:mod:`pipelay_fast.mesh`): each stretch's
element count phi(t) = int 1/h ds, and the nodes at equal steps of it.

Kernels, not NumPy, because a solve builds and differentiates its graded mesh
several times (the cold start's mesh, the meshes graded at the boundaries
found, and each focus's rate by central differences): over small arrays the
NumPy version spent some 0.4 ms a solve in call overhead, more than Newton on
a J125 mesh of 8 m elements.
"""

from __future__ import annotations

from .._jit import jit


@jit(_nrt=False)
def span_tables(a, b, focus, nfocus, h_max, h_min, growth, t, phi):
    """For each stretch j from a[j] to b[j] [m] with its foci ``focus[j,
    :nfocus[j]]`` [m]: samples t[j] [m] (numpy's linspace(a, b, n), sample by
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
            dist = abs(ti - focus[j, 0])
            for k in range(1, nfocus[j]):
                dist = min(dist, abs(ti - focus[j, k]))
            inv = 1.0 / min(h_max, h_min + rate * dist)
            t[j, i] = ti
            phi[j, i] = 0.0 if i == 0 else phi[j, i - 1] + 0.5 * (inv + prev_inv) * (ti - prev_t)
            prev_t = ti
            prev_inv = inv


@jit(_nrt=False)
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

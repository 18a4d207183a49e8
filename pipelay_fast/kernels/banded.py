"""Banded storage, assembly, and an LU factor/solve with partial pivoting.

Storage follows LAPACK's general band format (``dgbtrf``): a matrix ``A`` of order
``n`` with ``kl`` sub- and ``ku`` super-diagonals lives in ``ab`` of shape
``(2*kl + ku + 1, n)`` with

    A[i, j] = ab[kl + ku + i - j, j]      for max(0, j - ku) <= i <= min(n - 1, j + kl)

The top ``kl`` rows hold the fill-in created by row interchanges. The rod's saddle
structure (displacements coupled to the tension multiplier, whose own diagonal is
zero for an inextensible pipe) needs pivoting, so a Cholesky or an unpivoted LU
would not do. Cost: O(n * kl * (kl + ku)); memory O(n * (2 kl + ku)).
"""

from __future__ import annotations

import numpy as np

from ._jit import jit


@jit(_nrt=False)
def band_add_block(ab, kl, ku, g0, ke):
    """Scatter the dense square block ``ke`` into ``ab`` at global rows/cols ``g0...``.

    The block must fit in the band: ``ke.shape[0] - 1 <= min(kl, ku)``.
    """
    kv = kl + ku
    m = ke.shape[0]
    for a in range(m):
        i = g0 + a
        for b in range(m):
            j = g0 + b
            ab[kv + i - j, j] += ke[a, b]


@jit(_nrt=False)
def band_matvec(ab, kl, ku, x, out):
    """out = A @ x for ``A`` in band storage (before factorisation)."""
    kv = kl + ku
    n = x.shape[0]
    for i in range(n):
        out[i] = 0.0
    for j in range(n):
        xj = x[j]
        if xj == 0.0:
            continue
        i0 = max(0, j - ku)
        i1 = min(n - 1, j + kl)
        for i in range(i0, i1 + 1):
            out[i] += ab[kv + i - j, j] * xj


@jit(_nrt=False)
def band_factor(ab, kl, ku, ipiv):
    """In-place LU factorisation with partial pivoting (the ``dgbtf2`` algorithm).

    Returns 0 on success, or ``j + 1`` when the pivot of column ``j`` is exactly
    zero (the matrix is singular; the factors are then unusable).
    """
    n = ab.shape[1]
    kv = kl + ku
    # Zero the fill-in rows: columns ku+1 .. kv-1 may hold stale entries.
    for j in range(ku + 1, min(kv, n)):
        for i in range(kv - j, kl):
            ab[i, j] = 0.0
    info = 0
    ju = 0
    for j in range(n):
        if j + kv < n:
            for i in range(kl):
                ab[i, j + kv] = 0.0
        km = min(kl, n - 1 - j)
        jp = 0
        best = abs(ab[kv, j])
        for i in range(1, km + 1):
            v = abs(ab[kv + i, j])
            if v > best:
                best = v
                jp = i
        ipiv[j] = j + jp
        if ab[kv + jp, j] == 0.0:
            if info == 0:
                info = j + 1
            continue
        ju = max(ju, min(j + ku + jp, n - 1))
        if jp != 0:
            for c in range(j, ju + 1):
                r_a = kv + jp - (c - j)
                r_b = kv - (c - j)
                tmp = ab[r_a, c]
                ab[r_a, c] = ab[r_b, c]
                ab[r_b, c] = tmp
        inv = 1.0 / ab[kv, j]
        for i in range(1, km + 1):
            ab[kv + i, j] *= inv
        for c in range(j + 1, ju + 1):
            ujc = ab[kv + j - c, c]
            if ujc != 0.0:
                for i in range(1, km + 1):
                    ab[kv + j + i - c, c] -= ab[kv + i, j] * ujc
    return info


@jit(_nrt=False)
def band_solve_many(ab, kl, ku, ipiv, b, m):
    """Solve ``A X = B`` in place for the first ``m`` columns of ``b`` (n, >= m),
    with the factors of :func:`band_factor` (``dgbtrs``'s forward and back
    substitution), the band read once for all columns (the Newton step and
    its border columns) instead of once a column."""
    n = ab.shape[1]
    kv = kl + ku
    for j in range(n - 1):
        lm = min(kl, n - 1 - j)
        p = ipiv[j]
        if p != j:
            for c in range(m):
                tmp = b[p, c]
                b[p, c] = b[j, c]
                b[j, c] = tmp
        for i in range(1, lm + 1):
            lij = ab[kv + i, j]
            for c in range(m):
                b[j + i, c] -= lij * b[j, c]
    for j in range(n - 1, -1, -1):
        d = ab[kv, j]
        for c in range(m):
            b[j, c] /= d
        for i in range(max(0, j - kv), j):
            aij = ab[kv + i - j, j]
            for c in range(m):
                b[i, c] -= aij * b[j, c]


def dense_to_band(a, kl, ku):
    """Pack a dense matrix into band storage (a test and debugging helper)."""
    n = a.shape[0]
    ab = np.zeros((2 * kl + ku + 1, n))
    kv = kl + ku
    for j in range(n):
        for i in range(max(0, j - ku), min(n - 1, j + kl) + 1):
            ab[kv + i - j, j] = a[i, j]
    return ab

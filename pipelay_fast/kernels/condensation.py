"""Condensation: the Newton step of the bordered system with the
constrained unknowns prescribed, and the reactions read back from their rows.

With the unknowns split into free (f) and constrained (c, their increments
delta_c prescribed by :func:`.constraints._constraint_set`), the step solves

    K_ff du_f = -G_f - K_fc delta_c,   du_c = delta_c,

and the constrained rows give the reactions, R_c = G_c + K_cf du_f + K_cc du_c.
The bordered unknowns z (the bottom tension, the boundaries' arc lengths:
:func:`.system._border`) add columns C = dG/dz and equations res + B du +
D dz = 0; with y0 the step at dz = 0 and Y = K^-1 C (one band factorisation,
the right-hand sides solved together) du = y0 - Y dz, and dz solves the
dense nb x nb Schur complement (B Y - D) dz = B y0 + res. The unknowns are
scaled first (``w.scale``: K -> S K S, G -> S G) so that positions, slopes
and multipliers weigh alike in the pivoting.
"""

from __future__ import annotations

import math

from ._jit import jit, phase
from .banded import band_factor, band_solve_many
from .supports import in_curve_coords, support_angle
from .system import _to_global


@jit(by_dimension=True, _nrt=False)
def _condensed_solve(nd, w, nb, phi_r, phi_rp):
    """The Newton step by condensation and the bordered solve (module
    docstring), ``nb`` bordered unknowns.

    The system is scaled (``w.scale``: lengths, slopes, multipliers), every
    constrained unknown gets its prescribed increment (K_ff du_f = -G_f - K_fc
    du_c), the band is factored once, and the nb border unknowns are
    eliminated by a dense Schur complement: du = y0 - sum_j dz_j Y_j with S dz
    = rows . y0 + res. Leaves the scaled step in ``w.du``, the border steps in
    ``w.dz``, the scaled tangent in ``w.ab0`` and the step in the global
    frame (the nodal frames' angles ``phi_r``, ``phi_rp`` [rad]) in
    ``w.du_free`` [m, -, N]. False when singular."""
    ndn = 2 * nd + 1
    kl = 2 * ndn - 1
    n = w.g.shape[0]
    if not _condense_factor(nd, w):
        return False
    # the step and the border columns solved together, the band read once
    # (column 0 the step y0, column 1 + j the border column Y_j)
    rhs = w.rhs
    _condensed_rhs(nd, w, w.g, w.delta, w.du)
    _border_columns(w, nb, rhs, 1)
    for i in range(n):
        rhs[i, 0] = w.du[i]
    band_solve_many(w.ab, kl, kl, w.ipiv, rhs, 1 + nb)
    return _border_solve(nd, w, nb, rhs, phi_r, phi_rp)


@phase
def _condense_factor(nd, w):
    """The tangent ``w.ab`` scaled (``w.scale``), kept in ``w.ab0``, its
    constrained rows and columns (``w.cmask``) made identity, factored in
    place (pivots ``w.ipiv``). False when singular."""
    ndn = 2 * nd + 1
    kl = 2 * ndn - 1
    ku = kl
    kv = kl + ku
    n = w.g.shape[0]
    ab = w.ab
    scale = w.scale
    cmask = w.cmask
    for j in range(n):
        sj = scale[j]
        for r in range(max(0, j - ku), min(n - 1, j + kl) + 1):
            ab[kv + r - j, j] *= scale[r] * sj
    for j in range(ab.shape[1]):
        for i in range(ab.shape[0]):
            w.ab0[i, j] = ab[i, j]
    for j in range(n):
        if not cmask[j]:
            continue
        for r in range(max(0, j - ku), min(n - 1, j + kl) + 1):
            ab[kv + r - j, j] = 0.0
        for c in range(max(0, j - kl), min(n - 1, j + ku) + 1):
            ab[kv + j - c, c] = 0.0
        ab[kv, j] = 1.0
    return band_factor(ab, kl, ku, w.ipiv) == 0


@phase
def _condensed_rhs(nd, w, g, delta, du):
    """The condensed right-hand side of residual ``g`` with the constrained
    unknowns' increments ``delta`` (nodal frames) into ``du`` (scaled):
    -G_f - K_fc delta_c on the free rows, delta_c on the constrained
    (K the scaled tangent ``w.ab0``)."""
    ndn = 2 * nd + 1
    kl = 2 * ndn - 1
    kv = 2 * kl
    n = g.shape[0]
    scale = w.scale
    cmask = w.cmask
    for i in range(n):
        du[i] = -g[i] * scale[i]
    for j in range(n):
        if not cmask[j]:
            continue
        dj = delta[j] / scale[j]
        for r in range(max(0, j - kl), min(n - 1, j + kl) + 1):
            if not cmask[r]:
                du[r] -= w.ab0[kv + r - j, j] * dj
    for j in range(n):
        if cmask[j]:
            du[j] = delta[j] / scale[j]


@phase
def _border_columns(w, nb, rhs, first):
    """The border columns dG/dz, scaled and 0 on the constrained rows, into
    columns ``first`` .. ``first + nb - 1`` of ``rhs``."""
    for i in range(w.g.shape[0]):
        for j in range(nb):
            rhs[i, first + j] = 0.0 if w.cmask[i] else w.cols[j, i] * w.scale[i]


@phase
def _border_solve(nd, w, nb, rhs, phi_r, phi_rp):
    """From the solved step y0 (``rhs`` column 0) and border columns Y_j
    (columns 1 + j): the border steps ``w.dz`` by the Schur complement of
    the border equations res + rows . du + d_b dz = 0 (``w.res_b``), the
    scaled step ``w.du`` = y0 - Y dz and the step in the global frame
    ``w.du_free``. False when the Schur complement is singular."""
    n = w.g.shape[0]
    du = w.du
    scale = w.scale
    for i in range(n):
        du[i] = rhs[i, 0]
    # border equations res + rows . du + d_b dz = 0 with du = y0 - Y dz; each
    # row is local (a node's, an element's, the top's): the products run
    # over its nonzero span (a roller stinger has a bordered unknown a roller)
    for i2 in range(nb):
        lo = 0
        while lo < n and w.rows[i2, lo] == 0.0:
            lo += 1
        hi = n
        while hi > lo and w.rows[i2, hi - 1] == 0.0:
            hi -= 1
        acc = 0.0
        for k in range(lo, hi):
            acc += w.rows[i2, k] * scale[k] * du[k]
        w.rh[i2] = acc + w.res_b[i2]
        for j in range(nb):
            acc = 0.0
            for k in range(lo, hi):
                acc += w.rows[i2, k] * scale[k] * rhs[k, 1 + j]
            w.sm[i2, j] = acc - w.d_b[i2, j]
    if nb > 0 and not _solve_dense(nb, w.sm, w.rh, w.dz):
        return False
    for j in range(nb):
        for i in range(n):
            du[i] -= w.dz[j] * rhs[i, 1 + j]
    for i in range(n):
        w.du_free[i] = du[i] * scale[i]
    _to_global(nd, w.du_free, phi_r, phi_rp)
    return True


@jit(_nrt=False)
def _solve_dense(nb, sm, rh, dz):
    """Solve the nb x nb border system ``sm dz = rh`` (Gaussian elimination with
    partial pivoting; sm and rh are overwritten). Returns False when singular."""
    for k in range(nb):
        p = k
        for i in range(k + 1, nb):
            if abs(sm[i, k]) > abs(sm[p, k]):
                p = i
        if sm[p, k] == 0.0:
            return False
        if p != k:
            for j in range(nb):
                tmp = sm[k, j]
                sm[k, j] = sm[p, j]
                sm[p, j] = tmp
            tmp = rh[k]
            rh[k] = rh[p]
            rh[p] = tmp
        for i in range(k + 1, nb):
            f = sm[i, k] / sm[k, k]
            for j in range(k, nb):
                sm[i, j] -= f * sm[k, j]
            rh[i] -= f * rh[k]
    for k in range(nb - 1, -1, -1):
        acc = rh[k]
        for j in range(k + 1, nb):
            acc -= sm[k, j] * dz[j]
        dz[k] = acc / sm[k, k]
    return True


@phase
def _border_steps(w, nb):
    """The bottom tension's step [N] (returned) and the boundaries' (``w.d_bnd``, m)."""
    dtb = 0.0
    w.d_bnd[:] = 0.0
    for j in range(nb):
        if w.kind[j] == 0:
            dtb = w.dz[j]
        else:
            w.d_bnd[w.kind[j] - 2] = w.dz[j]
    return dtb


@phase
def _reactions(nd, w, nb, react):
    """The linearised reactions on the constrained rows into ``react``, R_c
    = G_c + K_cf du_f + K_cc du_c + the border columns' share C dz, in the
    nodal frames [N, N m] (0 on the free rows)."""
    ndn = 2 * nd + 1
    kl = 2 * ndn - 1
    kv = 2 * kl
    n = w.g.shape[0]
    for i in range(n):
        react[i] = 0.0
    for i in range(n):
        if not w.cmask[i]:
            continue
        acc = 0.0
        for j in range(max(0, i - kl), min(n - 1, i + kl) + 1):
            acc += w.ab0[kv + i - j, j] * w.du[j]
        react[i] = w.g[i] + acc / w.scale[i]
        for j in range(nb):
            react[i] += w.cols[j, i] * w.dz[j]


@jit(_nrt=False)
def _curve_reactions(nd, u, sup, react):
    """Reactions of the contacts of the supports in curve coordinates, in the
    rotated frame the results read: in curve coordinates the support's force
    is G_x (1, -f'), so its normal component is G_x / cos(psi), psi the
    support's angle (:func:`.supports.support_angle`; and likewise for the
    slope's); the frames are set to psi."""
    ndn = 2 * nd + 1
    for k in range(sup.kind.shape[0]):
        if not in_curve_coords(sup.kind[k]):
            continue
        for node in range(sup.active.shape[1]):
            if sup.active[k, node] == 0:
                continue
            base = node * ndn
            psi = support_angle(sup.kind[k], sup.geom[k], u[base + nd - 1])
            sup.phi_r[node] = psi
            sup.phi_rp[node] = psi
            c = math.cos(psi)
            react[base] /= c
            react[base + nd] /= c

"""Finite-difference check of the Newton kernel's full linear system.

    python benchmarks/check_tangent.py [--case s67 j125_2d s67_3d 1:2d-85 ...]
                                       [--partway] [--history] [--first-steps]
                                       [--rel 1e-3] [--step 1e-6] [--detail] [--no-fd]

Cases: examples by name, or bench_random's ``SEED:2d-INDEX`` / ``SEED:3d-INDEX``.
At the engine's answer (:func:`pipelay_fast.engine.solver.solve_problem`),
and with ``--partway`` at the answer regraded for the case with its
stinger's ``a`` (J-lay: its top or bottom tension) changed by ``--rel``
(the start of the sensitivities' Newton, :func:`regraded`) and one Newton
step into that, the system the kernel assembles and solves with
(:func:`_kernels`' ``linearise``: the tangent K in the nodal frames and
curve coordinates, the bordered unknowns' columns dG/dz, their equations'
rows and their derivatives d_b: the bottom tension and the top tension's
equation, the contact boundaries' arc lengths and their equations) is
compared with central differences of the residual (``residual``: the same
phases without the tangent), the contact set held (the constraint set, the
rigid points' branches, the friction springs' states and anchors, the nodal
frames' unknown map as the step applies it: :func:`.system._to_global`,
:func:`.constraints._onto_curves`).

An unknown (nodal frames) is perturbed by +-h times its scale (positions and
slopes 1, multipliers and the bottom tension max(|value|, fref), a boundary's
arc length 10 href). Reported (:func:`report`): per group of columns
(positions, slopes, multipliers, the bottom tension, each boundary) the
largest difference over the free rows (those the condensed solve uses,
weighted as the kernel's test weighs them) and the bordered rows, relative
to the column's largest weighted entry; per bordered row the same over the
columns, each weighted by its unknown's size; the bordered block d_b entry
by entry. A prescribed unknown's column (it enters the step as K_fc
delta_c) is compared with the central or a one-sided difference, whichever
is closer: the state may sit on a kink there (a laid node's x: a power-law
current starts at the seabed). A seabed friction spring that slips sits at
its stick zone's edge after the friction's commit (|d| = d_slip): the
central difference there averages the two sides (3D with friction).

``--first-steps``: the first Newton step's move of the boundaries against
the converged move on the same mesh, for relative changes 1e-3, 1e-4, 1e-5
(with an exact tangent the miss falls like the change). ``--history``: the
weighted residual after each iteration from the regraded start, and the
ratios r_k+1 / r_k^2 (bounded: quadratic convergence).
"""

from __future__ import annotations

import argparse
import copy
import sys

import numpy as np

import pipelay_fast as pf
from pipelay_fast.engine import continuation as C
from pipelay_fast.engine.solver import solve_problem
from pipelay_fast.kernels import layout as L
from pipelay_fast.kernels._jit import jit
from pipelay_fast.kernels.constraints import (
    _has_boundaries,
    _nodal_frames,
    _onto_curves,
    mesh_lengths,
)
from pipelay_fast.kernels.newton import _work
from pipelay_fast.kernels.response import _evaluated
from pipelay_fast.kernels.system import (
    _evaluate,
    _to_global,
    _to_nodal_residual,
)
from pipelay_fast.kernels.types import Ends, Mesh, Settings, Supports

BOUNDARY_NAMES = {L.B_TD: "s_TD", L.B_LO: "s_LO"}


def _kernels(nd):
    """The linearisation and the residual of the Newton kernel's first phases
    (:mod:`pipelay_fast.kernels.newton`), for dimension ``nd``. Not cached:
    numba checks a cached kernel against its own file only, and these
    inline the kernels' phases (``kernels/_jit.py`` expires the kernels'
    caches, not this file's)."""

    @jit(entry=True, _nrt=True, cache=False)
    def linearise(u, mesh, model, sup, ends, settings, kd, g, cols, rows, res_b, d_b, kind,
                  cmask, delta):
        """The system the kernel solves at ``u``: dense K (nodal frames) into
        ``kd``, G into ``g``, the border's columns, rows, residuals,
        derivatives and kinds, the constrained unknowns. Returns nb."""
        w, nb = _evaluated(nd, u, mesh, model, sup, ends, settings, True)
        n = u.shape[0]
        kl = 4 * nd + 1
        kv = 2 * kl
        for j in range(n):
            for i in range(max(0, j - kl), min(n - 1, j + kl) + 1):
                kd[i, j] = w.ab[kv + i - j, j]
        for i in range(n):
            g[i] = w.g[i]
            cmask[i] = w.cmask[i]
            delta[i] = w.delta[i]
        for a in range(nb):
            for i in range(n):
                cols[a, i] = w.cols[a, i]
                rows[a, i] = w.rows[a, i]
            res_b[a] = w.res_b[a]
            kind[a] = w.kind[a]
            for b in range(nb):
                d_b[a, b] = w.d_b[a, b]
        return nb

    @jit(entry=True, _nrt=True, cache=False)
    def residual(u, mesh, model, sup, ends, settings, g, res_bnd):
        """The residual at ``u`` (nodal frames, the frames of this state) into
        ``g``, the boundaries' equations into ``res_bnd``; returns the top's
        effective tension [N]."""
        w = _work(nd, u.shape[0], sup.phi_r.shape[0], mesh.s_el.shape[0], mesh.bnodes.shape[0],
                  model.props, settings.href)
        if _has_boundaries(mesh):
            mesh_lengths(mesh.s_a, mesh.s_b, mesh.s_bd, mesh.s_el)
        _nodal_frames(nd, u, mesh, sup, ends)
        te_top, m_td = _evaluate(nd, u, mesh, model, sup, ends, w, w.g, False)
        _to_nodal_residual(nd, u, mesh, sup, w, m_td)
        for i in range(u.shape[0]):
            g[i] = w.g[i]
        for b in range(res_bnd.shape[0]):
            res_bnd[b] = w.res_bnd[b]
        return te_top

    return linearise, residual


KERNELS = {2: _kernels(2), 3: _kernels(3)}


class System:
    """The kernel's arguments for a Problem (as :func:`.continuation.run_newton`
    builds them), copies that perturbations do not leak from."""

    def __init__(self, pb, g_off=None, tol=1e-8):
        self.pb = pb
        self.nd = pb.nd
        self.g_off = np.zeros_like(pb.u) if g_off is None else g_off
        self.settings = Settings(float(tol), float(pb.settings.fref), float(pb.settings.href),
                                 1, False, C.boundary_step(pb))
        self.u0 = pb.u.copy()
        self.tb0 = pb.tb.copy()
        self.s_bd0 = pb.mesh.s_bd.copy()

    def args(self, u, tb, s_bd):
        pb = self.pb
        if pb.mesh.s_a is not None:
            s_a, s_b = pb.mesh.s_a, pb.mesh.s_b
        else:
            s_a, s_b = np.zeros(pb.nn), np.zeros((pb.bnodes.size, pb.nn))
        mesh = Mesh(pb.s_el.copy(), s_a, s_b, s_bd.copy(), pb.bnodes)
        sp = pb.kernel_supports()
        sup = Supports(*[np.array(a, copy=True) for a in sp])
        e = pb.kernel_ends(self.g_off)
        ends = Ends(e.f_node, e.g_off, tb.copy(), e.slide_dof, e.top_node, e.top_target)
        return u.copy(), mesh, pb.model(), sup, ends, self.settings

    def linearise(self):
        n = self.u0.size
        nbr = 1 + self.pb.bnodes.size
        out = dict(kd=np.zeros((n, n)), g=np.zeros(n), cols=np.zeros((nbr, n)),
                   rows=np.zeros((nbr, n)), res_b=np.zeros(nbr), d_b=np.zeros((nbr, nbr)),
                   kind=np.zeros(nbr, dtype=np.int64), cmask=np.zeros(n, dtype=np.bool_),
                   delta=np.zeros(n))
        u, mesh, model, sup, ends, settings = self.args(self.u0, self.tb0, self.s_bd0)
        nb = KERNELS[self.nd][0](u, mesh, model, sup, ends, settings, out["kd"], out["g"],
                                 out["cols"], out["rows"], out["res_b"], out["d_b"],
                                 out["kind"], out["cmask"], out["delta"])
        out["nb"] = nb
        out["sup"] = sup  # the frames of the base state (the unknowns' map)
        out["mesh"] = mesh
        out["ends"] = ends
        return out

    def full_residual(self, u, tb, s_bd, kinds):
        """The residual and the bordered equations (in the order ``kinds``)."""
        u, mesh, model, sup, ends, settings = self.args(u, tb, s_bd)
        g = np.zeros(u.size)
        res_bnd = np.zeros(self.pb.bnodes.size)
        te = KERNELS[self.nd][1](u, mesh, model, sup, ends, settings, g, res_bnd)
        extra = [te - ends.top_target if k == 0 else res_bnd[k - 2] for k in kinds]
        return np.concatenate([g, np.array(extra)])

    def moved(self, sup, j, h):
        """The state with nodal-frame unknown j moved by h, as the step moves it."""
        dv = np.zeros(self.u0.size)
        dv[j] = h
        _to_global(self.nd, dv, sup.phi_r, sup.phi_rp)
        u = self.u0 + dv
        _onto_curves(self.nd, u, self.u0, dv, 1.0, sup)
        return u


def unknown_scales(sys_, lin, h):
    """Each unknown's FD step (the module docstring)."""
    pb = sys_.pb
    ndn = 2 * pb.nd + 1
    n = sys_.u0.size
    fref = pb.settings.fref
    steps = np.empty(n)
    for i in range(n):
        slot = i % ndn
        if slot < 2 * pb.nd:
            steps[i] = h
        else:
            steps[i] = h * max(abs(sys_.u0[i]), fref)
    return steps


def check(sys_, h=1e-6):
    """The kernel's bordered Jacobian, its central-difference counterpart and
    the row weights: (J_kernel, J_fd, row weights, free-row mask, column
    names)."""
    lin = sys_.linearise()
    pb = sys_.pb
    nd = pb.nd
    ndn = 2 * nd + 1
    n = sys_.u0.size
    nb = lin["nb"]
    kinds = [int(k) for k in lin["kind"][:nb]]
    jk = np.zeros((n + nb, n + nb))
    jk[:n, :n] = lin["kd"]
    jk[:n, n:] = lin["cols"][:nb].T
    jk[n:, :n] = lin["rows"][:nb]
    jk[n:, n:] = lin["d_b"][:nb, :nb]
    jfd = np.zeros_like(jk)
    steps = unknown_scales(sys_, lin, h)
    sup = lin["sup"]
    href = pb.settings.href
    fref = pb.settings.fref
    r0 = sys_.full_residual(sys_.u0, sys_.tb0, sys_.s_bd0, kinds)
    free_rows = np.concatenate([~lin["cmask"], np.ones(nb, dtype=bool)])
    for j in range(n):
        rp = sys_.full_residual(sys_.moved(sup, j, steps[j]), sys_.tb0, sys_.s_bd0, kinds)
        rm = sys_.full_residual(sys_.moved(sup, j, -steps[j]), sys_.tb0, sys_.s_bd0, kinds)
        jfd[:, j] = (rp - rm) / (2 * steps[j])
        if lin["cmask"][j]:
            # a prescribed unknown (its column enters as K_fc delta_c): the
            # side closer to the kernel's, as the state may sit on a kink
            # there (the seabed's x: a power-law current's profile starts
            # there, drag on one side only)
            sides = (jfd[:, j], (rp - r0) / steps[j], (r0 - rm) / steps[j])
            jfd[:, j] = min(sides, key=lambda c: np.abs(c - jk[:, j])[free_rows].max())
    names = []
    for a, k in enumerate(kinds):
        tb, s_bd = sys_.tb0.copy(), sys_.s_bd0.copy()
        if k == 0:
            hk = h * max(abs(tb[0]), fref)
            tp, tm = tb.copy(), tb.copy()
            tp[0] += hk
            tm[0] -= hk
            rp = sys_.full_residual(sys_.u0, tp, s_bd, kinds)
            rm = sys_.full_residual(sys_.u0, tm, s_bd, kinds)
            names.append("T_b")
        else:
            b = k - 2
            hk = h * href * 10
            sp, sm = s_bd.copy(), s_bd.copy()
            sp[b] += hk
            sm[b] -= hk
            rp = sys_.full_residual(sys_.u0, sys_.tb0, sp, kinds)
            rm = sys_.full_residual(sys_.u0, sys_.tb0, sm, kinds)
            names.append(BOUNDARY_NAMES.get(b, f"s_P{b - L.B_PT}"))
        jfd[:, n + a] = (rp - rm) / (2 * hk)
    weights = np.empty(n + nb)
    for i in range(n):
        slot = i % ndn
        weights[i] = 1 / fref if slot < nd else (1 / (fref * href) if slot < 2 * nd else 1 / href)
    for a, k in enumerate(kinds):
        if k == 0:
            weights[n + a] = 1 / fref
        elif k - 2 == L.B_TD:
            weights[n + a] = 1 / (fref * href)
        elif k - 2 == L.B_LO:
            weights[n + a] = 1.0
        else:
            weights[n + a] = 1 / href
    free = np.concatenate([~lin["cmask"], np.ones(nb, dtype=bool)])
    return jk, jfd, weights, free, names, lin


def newton_step(jk, lin, n):
    """The condensed Newton step of the bordered system (dense): the
    constrained unknowns' increments prescribed, the free rows and the
    bordered equations solved. Returns (du (nodal frames), dz)."""
    nb = lin["nb"]
    cm = np.concatenate([lin["cmask"], np.zeros(nb, dtype=bool)])
    rhs = -np.concatenate([lin["g"], lin["res_b"][:nb]])
    x = np.zeros(n + nb)
    x[:n][lin["cmask"]] = lin["delta"][lin["cmask"]]
    f = ~cm
    rhs_f = rhs[f] - jk[np.ix_(f, cm)] @ x[cm]
    x[f] = np.linalg.solve(jk[np.ix_(f, f)], rhs_f)
    return x[:n], x[n:]


def column_groups(pb, names):
    nd = pb.nd
    ndn = 2 * nd + 1
    n = pb.u.size
    slot = np.arange(n) % ndn
    groups = {"r": np.flatnonzero(slot < nd), "r'": np.flatnonzero((slot >= nd) & (slot < 2 * nd)),
              "lambda": np.flatnonzero(slot == 2 * nd)}
    for a, name in enumerate(names):
        groups[name] = np.array([n + a])
    return groups


def column_errors(jk, jfd, weights, free):
    """Per column: the largest weighted difference over the free and border
    rows relative to the column's largest weighted entry (FD or kernel)."""
    wk = (jk * weights[:, None])[free]
    wf = (jfd * weights[:, None])[free]
    size = np.maximum(np.abs(wk).max(axis=0), np.abs(wf).max(axis=0))
    diff = np.abs(wk - wf).max(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        rel = np.where(size > 0, diff / size, 0.0)
    return rel, diff, size


def report(label, pb, jk, jfd, weights, free, names, lin, h, detail=False):
    """Print the tables of one state: column groups (free and bordered rows),
    the bordered rows (over every column, each weighted by its unknown's
    size), the bordered block d_b entry by entry. Returns {entry: relative
    error}. (The Newton step with the difference Jacobian is no check: the
    system's condition, EA against EI, turns the differences' round-off
    into steps that move with h.)"""
    n = pb.u.size
    nb = len(names)
    rel, _diff, size = column_errors(jk, jfd, weights, free)
    out = {}
    print(f"\n### {label}: {n} unknowns, bordered {names}\n")
    print("| columns | max rel. error | at column |")
    print("|---|---|---|")
    for name, idx in column_groups(pb, names).items():
        if idx.size == 0:
            continue
        k = idx[np.argmax(rel[idx])]
        out[name] = float(rel[k])
        print(f"| {name} | {rel[k]:.1e} | {k} (node {k // (2 * pb.nd + 1)}) |")
    steps = unknown_scales_full(pb, names, h)
    for a, name in enumerate(names):
        r = n + a
        wk = jk[r] * steps
        wf = jfd[r] * steps
        size_r = max(np.abs(wf).max(), 1e-300)
        d_rel = np.abs(wk - wf) / size_r
        k = int(np.argmax(d_rel))
        out["row " + name] = float(d_rel[k])
        print(f"| row {name} (x unknown scales) | {d_rel[k]:.1e} | {k} |")
    db_k, db_f = jk[n:, n:], jfd[n:, n:]
    scale = np.maximum(np.abs(db_f), np.abs(db_k))
    floor = 1e-10 * np.abs(jfd[n:]).max(axis=1, keepdims=True)  # FD noise of the row
    with np.errstate(invalid="ignore", divide="ignore"):
        e = np.where(scale > floor, np.abs(db_k - db_f) / scale, 0.0)
    for a in range(nb):
        for b in range(nb):
            if e[a, b] > 0 or scale[a, b] > floor[a, 0]:
                out[f"d_b {names[a]}/{names[b]}"] = float(e[a, b])
                print(f"| d_b d({names[a]} eq.)/d{names[b]} = {db_f[a, b]:.4e} | {e[a, b]:.1e} | "
                      f"kernel {db_k[a, b]:.4e} |")
    if detail:
        for name, idx in column_groups(pb, names).items():
            for k in idx:
                if rel[k] > 1e-5:
                    rows = np.flatnonzero(free & (np.abs(jk[:, k] - jfd[:, k]) * weights
                                                  > 1e-6 * size[k]))
                    print(f"  col {k} ({name}) rel {rel[k]:.2e}: rows {rows[:12].tolist()}"
                          f" kernel {jk[rows[:4], k]} fd {jfd[rows[:4], k]}")
    return out


def unknown_scales_full(pb, names, h):
    """Typical sizes of the unknowns times ``h``: positions href, slopes 1,
    multipliers and the bottom tension fref, arc lengths href."""
    ndn = 2 * pb.nd + 1
    n = pb.u.size
    slot = np.arange(n) % ndn
    href, fref = pb.settings.href, pb.settings.fref
    s = np.where(slot < pb.nd, href, np.where(slot < 2 * pb.nd, 1.0, fref))
    extra = [fref if name == "T_b" else href for name in names]
    return h * np.concatenate([s, extra])


def load(spec):
    """An example's name, or a bench_random case ``SEED:2d-INDEX`` / ``SEED:3d-INDEX``;
    a suffix ``+uniform``: the current's profile uniform (a power law's
    drag has an infinite slope at the seabed, where the laid pipe's
    elements sample it: no difference quotient converges there)."""
    if spec.endswith("+uniform"):
        return load(spec[:-len("+uniform")]).with_changes(
            {"environment.current.profile": "uniform"})
    if ":" not in spec:
        return pf.load_case(spec)
    import random_lay as rl

    seed, rest = spec.split(":")
    dim, index = rest.split("-")
    example, changes, _drawn = rl.case_changes(int(seed), int(dim[0]), int(index))
    return rl.load(example).with_changes(changes)


def solved(spec):
    """(case, its solved problem, the solve's Newton iterations); the
    problem None when the solve fails (the iterations then the message)."""
    case = load(spec)
    try:
        pb, sol = solve_problem(case)
    except (pf.SolveError, ValueError) as err:
        return case, None, str(err)[:160]
    return case, pb, sol.stats["iterations"]


def perturbation_key(case):
    """The key a state part-way along a solve is perturbed by: the stinger's
    a in S-lay (a quadratic stinger), else the top (or bottom) tension."""
    if case.lay.stinger is not None and getattr(case.lay.stinger, "a", None):
        return "lay.stinger.a"
    return "lay.top_tension" if case.lay.top_tension is not None else "lay.bottom_tension"


def history(start, maxit=8, tol=1e-12):
    """The weighted residual after each Newton iteration from ``start``
    (the kernel run with maxit 1, 2, ...: each from ``start``)."""
    out = []
    for k in range(1, maxit + 1):
        pb = copy.deepcopy(start)
        status, _r, _info = C.run_newton(pb, np.zeros_like(pb.u), tol, k)
        # the residual the next iteration would test (maxit 0: residual only)
        res = _weighted_residual(pb)
        out.append(res)
        if status == L.OK or res < 1e-13:
            break
    return out


def _weighted_residual(pb):
    """The free rows' largest weighted residual and the bordered equations'
    scaled residuals at ``pb``'s state (:func:`linearise`)."""
    sys_ = System(pb)
    lin = sys_.linearise()
    n = pb.u.size
    ndn = 2 * pb.nd + 1
    slot = np.arange(n) % ndn
    fref, href = pb.settings.fref, pb.settings.href
    w = np.where(slot < pb.nd, 1 / fref, np.where(slot < 2 * pb.nd, 1 / (fref * href), 1 / href))
    g = np.abs(lin["g"] * w)[~lin["cmask"]].max()
    worst = g
    for a in range(lin["nb"]):
        k = lin["kind"][a]
        scale = fref if k == 0 else (fref * href if k - 2 == L.B_TD else
                                     (1.0 if k - 2 == L.B_LO else href))
        worst = max(worst, abs(lin["res_b"][a]) / scale)
    return max(worst, np.abs(lin["delta"]).max() / href)


def regraded(case, pb):
    """The problem of ``case`` (a neighbour of the case ``pb`` solved) as the
    sensitivities' engine builds it (``engine/sensitivity.py``
    ``regraded_problem``: the mesh a solve of it grades at ``pb``'s
    boundaries, ``pb``'s state interpolated onto it), set for Newton from
    that state (free boundaries, the load path's factors, no tolerance)."""
    from pipelay_fast.engine.sensitivity import regraded_problem

    new = regraded_problem(case, pb)
    new.settings.factors = pb.settings.factors.copy()
    new.settings.tolerance = None
    new.settings.in_balance = True
    return new


def first_steps(case, pb, key, rels, maxit=1):
    """The first Newton step's move of the boundaries against the converged
    move, from ``pb``'s answer regraded for the case with ``key`` changed by
    ``rel`` (relative): the table's rows (rel, boundary, converged move, the
    step's, the relative miss)."""
    from pipelay_fast.input.case import get_path

    p = float(get_path(case.to_dict(), key))
    rows = []
    for rel in rels:
        start = regraded(case.with_changes({key: p * (1 + rel)}), pb)
        s0 = start.mesh.s_bd.copy()
        one = copy.deepcopy(start)
        C.run_newton(one, np.zeros_like(one.u), 1e-12, maxit)
        conv = copy.deepcopy(start)
        st, _r, info = C.run_newton(conv, np.zeros_like(conv.u), 1e-10, 100)
        for b in range(min(start.bnodes.size, L.B_PT + 1)):  # touchdown, lift-off, the tip
            if start.bnodes[b] < 0:
                continue
            d_c = conv.mesh.s_bd[b] - s0[b]
            d_1 = one.mesh.s_bd[b] - s0[b]
            rows.append((rel, BOUNDARY_NAMES.get(b, f"s_P{b - L.B_PT}"), d_c, d_1,
                         abs(d_1 - d_c) / max(abs(d_c), 1e-300), st, int(info[L.I_ITER])))
    print(f"\n{key}: first Newton step from the regraded answer vs converged (same mesh)\n")
    print("| rel | boundary | converged move [m] | 1st step [m] | rel. miss | status, its |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r[0]:g} | {r[1]} | {r[2]:.6e} | {r[3]:.6e} | {r[4]:.1e} | {r[5]}, {r[6]} |")
    return rows


def check_state(label, pb, h, detail):
    """The FD tables of one state (:func:`report`)."""
    sys_ = System(pb)
    jk, jfd, wts, free, names, lin = check(sys_, h)
    return report(label, pb, jk, jfd, wts, free, names, lin, h, detail)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--case", nargs="*", default=["s67", "j125_2d", "s67_3d"],
                    help="examples, or bench_random cases SEED:2d-INDEX")
    ap.add_argument("--partway", action="store_true",
                    help="also the regraded start of a perturbed case and one step into it")
    ap.add_argument("--step", type=float, default=1e-6)
    ap.add_argument("--rel", type=float, default=1e-3, help="the perturbation (relative)")
    ap.add_argument("--detail", action="store_true")
    ap.add_argument("--first-steps", action="store_true",
                    help="the first Newton step's boundary moves against converged ones")
    ap.add_argument("--history", action="store_true",
                    help="residuals per iteration from the regraded perturbed start")
    ap.add_argument("--no-fd", action="store_true")
    args = ap.parse_args(argv)
    for spec in args.case:
        case, pb, its = solved(spec)
        print(f"\n## {spec}: solve {'FAILED: ' + its if pb is None else f'{its} iterations'}")
        if pb is None:
            continue
        key = perturbation_key(case)
        if not args.no_fd:
            check_state(f"{spec}, converged", pb, args.step, args.detail)
        if args.first_steps:
            first_steps(case, pb, key, (1e-3, 1e-4, 1e-5))
        if not (args.partway or args.history):
            continue
        from pipelay_fast.input.case import get_path

        p = float(get_path(case.to_dict(), key))
        start = regraded(case.with_changes({key: p * (1 + args.rel)}), pb)
        if args.history:
            res = history(start)
            ratios = [f"{b / a ** 2:.1e}" if a > 0 else "-"
                      for a, b in zip(res, res[1:], strict=False)]
            print(f"\nresiduals from the regraded start ({key} x (1 + {args.rel:g})): "
                  + ", ".join(f"{r:.1e}" for r in res) + f"; r_k+1 / r_k^2: {ratios}")
        if args.partway and not args.no_fd:
            check_state(f"{spec}, regraded start of {key} x (1 + {args.rel:g})", start,
                        args.step, args.detail)
            one = copy.deepcopy(start)
            C.run_newton(one, np.zeros_like(one.u), 1e-12, 1)
            check_state(f"{spec}, one Newton step into it", one, args.step, args.detail)
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(__import__("pathlib").Path(__file__).parent))
    sys.exit(main())

"""Solve one case: first guess, mesh, constraints, Newton with load-path fallback.

The orchestration lives here; every loop over nodes or elements is a kernel in
:mod:`pipelay_fast.kernels`. The path of a solve:

1. natural-catenary guess (:mod:`.catenary`) plus the laid pipe;
2. mesh graded at touchdown and the top (:mod:`.mesh`);
3. constraints as flat arrays (fixed unknowns in rotated nodal frames, seabed
   contact candidates, a sliding lower end with its tension);
4. Newton with line search (:func:`.kernels.newton.newton`); if it fails, the
   out-of-balance force of the guess is removed in adaptive load steps, and the
   current is then applied in increments (friction is path dependent);
5. if touchdown ended up away from the fine part of the mesh, or too close to
   the lower end, the mesh is rebuilt around it and the solve repeated from the
   interpolated solution.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from .case import Case
from .catenary import Catenary, from_top_tension
from .kernels import layout as L
from .kernels.newton import I_DELTA, I_ITER, I_RES, I_TOP_RES, N_INFO, newton
from .mesh import graded_nodes
from .model import build_props, dimension_of
from .results import (
    Result,
    build_profile,
    build_summary,
    nodal_fields,
    signed_curvature_vector,
    touchdown_estimate,
)


class SolveError(RuntimeError):
    """A case that did not converge: the message names the step, residual and reason."""


@dataclass
class Problem:
    """Everything a Newton solve needs, as arrays (one mesh, one set of constraints)."""

    nd: int
    s: np.ndarray  # node arc lengths [m]
    props: np.ndarray
    table: np.ndarray
    u: np.ndarray  # nodal unknowns (global frame)
    fix_mask: np.ndarray
    fix_val: np.ndarray
    phi_r: np.ndarray
    phi_rp: np.ndarray
    bed: np.ndarray
    bed_active: np.ndarray
    f_node: np.ndarray
    slide_dof: int
    tb: np.ndarray
    top_node: int
    top_target: float
    fref: float
    href: float
    stats: dict = field(default_factory=dict)

    @property
    def ndn(self) -> int:
        return 2 * self.nd + 1

    @property
    def nn(self) -> int:
        return self.s.size

    @property
    def s_el(self) -> np.ndarray:
        return np.diff(self.s)

    def node_values(self, slot):
        return self.u[slot::self.ndn]


def _weights(case: Case):
    """Effective weight below and above the water surface [N/m] for the guess."""
    depth = case.environment.water_depth
    w1 = float(case.effective_weight(0.5 * min(depth, case.pipe.contents_level or depth)))
    w1 = float(case.effective_weight(0.0)) if case.pipe.contents_level <= 0 else w1
    w2 = float(case.effective_weight(depth + 1.0))
    if w1 <= 0.0:
        raise ValueError(
            f"the pipe floats: its submerged effective weight is {w1:.1f} N/m; "
            "increase pipe.steel_density or pipe.coating_density"
        )
    return w1, w2


def _first_catenary(case: Case) -> Catenary:
    lay = case.lay
    depth = case.environment.water_depth
    x_top = lay.top[0]
    w1, w2 = _weights(case)
    if lay.top_tension is not None:
        return from_top_tension(lay.top_tension, w1, w2, depth, x_top)
    if lay.bottom_tension is not None:
        return Catenary(lay.bottom_tension, w1, w2, depth, x_top)
    # pipe_length: lower end fixed at z = 0; find h so that laid + suspended fits
    from scipy.optimize import brentq

    length, z_top = lay.pipe_length, lay.top[1]

    def gap(h):
        cat = Catenary(h, w1, w2, depth, x_top)
        return (z_top - cat.span) - (length - cat.length)

    lo, hi = 1e-6 * w1 * depth, 1e3 * w1 * max(length, z_top)
    if gap(lo) * gap(hi) > 0:
        raise ValueError(
            f"lay.pipe_length = {length:g} m cannot reach the top {lay.top} from a lower end "
            "at (0, 0): it is shorter than the straight line or much longer than a slack catenary"
        )
    return Catenary(brentq(gap, lo, hi, xtol=1e-10 * w1), w1, w2, depth, x_top)


def _mesh_sizes(case: Case, h_bottom: float):
    """h_max, h_min [m] and the flexural length sqrt(EI/T) [m] at touchdown."""
    h_max = case.solver.element_length
    lam = math.sqrt(case.pipe.bending_stiffness / h_bottom)
    if case.solver.min_element_length is not None:
        h_min = case.solver.min_element_length
    else:
        h_min = min(h_max, max(h_max / 8.0, 0.02 * lam))
    return h_max, min(h_min, h_max), lam


def build_problem(case: Case) -> Problem:
    """Natural-catenary guess, graded mesh and constraints of a case."""
    nd = dimension_of(case)
    ndn = 2 * nd + 1
    cat = _first_catenary(case)
    lay = case.lay
    z_top = lay.top[1]
    h_max, h_min, lam = _mesh_sizes(case, cat.h)
    susp = cat.length
    if lay.pipe_length is not None:
        laid = lay.pipe_length - susp
    elif case.solver.laid_length is not None:
        laid = case.solver.laid_length
    else:
        laid = 2.0 * lam + 5.0 * h_max
    total = laid + susp
    # A stiff pipe touches down about one flexural length before the catenary
    # does (boundary-layer asymptotics): the mesh is finest there and the
    # initial seabed contact ends there.
    s_focus = max(laid - lam, 0.25 * laid)
    s = graded_nodes(total, [s_focus, total], h_max, h_min, grading=case.solver.grading)
    u = np.zeros(s.size * ndn)
    z_tdp = z_top - cat.span
    x, z, th, te = cat.at(np.clip(s - laid, 0.0, None))
    on_bed = s < laid
    z = np.where(on_bed, z_tdp - (laid - s), z_tdp + z)
    x = np.where(on_bed, 0.0, x)
    th = np.where(on_bed, 0.0, th)
    te = np.where(on_bed, cat.h, te)
    kappa = np.where(on_bed, 0.0, np.cos(th) ** 2 * np.asarray(case.effective_weight(x)) / cat.h)
    u[0::ndn] = x
    u[nd - 1::ndn] = z
    u[nd::ndn] = np.sin(th)
    u[2 * nd - 1::ndn] = np.cos(th)
    u[2 * nd::ndn] = te - case.pipe.bending_stiffness * kappa**2
    stats = {"catenary": cat, "h_min": h_min, "h_max": h_max, "flexural_length": lam,
             "focus": s_focus}
    fref = max(cat.top_tension, abs(cat.w1) * total)
    return _problem(case, nd, s, u, cat.h, s_focus, fref, stats)


def _problem(case: Case, nd, s, u, tb, s_contact, fref, stats) -> Problem:
    """Constraint arrays for nodes ``s`` with state ``u``; contact below ``s_contact``."""
    ndn = 2 * nd + 1
    nn = s.size
    lay = case.lay
    x_top, z_top = lay.top
    fix_mask = np.zeros(nn * ndn, dtype=np.int8)
    fix_val = np.zeros(nn * ndn)
    phi_r = np.zeros(nn)
    phi_rp = np.zeros(nn)
    top = nn - 1
    base = top * ndn
    for i, val in enumerate((x_top, 0.0, z_top) if nd == 3 else (x_top, z_top)):
        fix_mask[base + i] = 1
        fix_val[base + i] = val
    if lay.top_angle is not None:
        phi_rp[top] = math.radians(lay.top_angle)
        fix_mask[base + nd] = 1  # r' normal to the prescribed direction = 0
        if nd == 3:
            fix_mask[base + nd + 1] = 1  # r'_y = 0
    # lower end: on the seabed with y held; z held only with a given pipe length
    fix_mask[0] = 1
    if nd == 3:
        fix_mask[1] = 1
    zi = nd - 1
    slide_dof, top_target = zi, 0.0
    if lay.pipe_length is not None:
        fix_mask[zi] = 1
        fix_val[zi] = u[zi]
        slide_dof, tb = -1, 0.0
    elif lay.top_tension is not None:
        top_target = lay.top_tension
    else:
        tb = lay.bottom_tension
    bed = np.ones(nn, dtype=np.int8)
    bed[top] = 0
    x = u[0::ndn]
    bed_active = ((s <= s_contact) & (s > 0.0) & (x <= 1e-6)).astype(np.int8)
    props, table = build_props(case)
    return Problem(nd, s, props, table, u, fix_mask, fix_val, phi_r, phi_rp, bed, bed_active,
                   np.zeros(nn * ndn), slide_dof, np.array([float(tb)]), top, top_target, fref,
                   stats["h_max"], stats=stats)


def _run_newton(pb: Problem, g_off, tol, maxit):
    react = np.zeros_like(pb.u)
    info = np.zeros(N_INFO)
    status = newton(pb.nd, pb.s_el, pb.u, pb.props, pb.table, pb.fix_mask, pb.fix_val,
                    pb.phi_r, pb.phi_rp, pb.bed, pb.bed_active, pb.f_node, g_off,
                    pb.slide_dof, pb.tb, pb.top_node, pb.top_target, tol, pb.fref, pb.href,
                    maxit, react, info)
    return status, react, info


def _residual(pb: Problem):
    """Residual at the current state with constrained rows zeroed (for the homotopy)."""
    from .kernels.newton import _system

    g = np.zeros_like(pb.u)
    torques = np.full(pb.nn - 1, pb.props[L.TORQUE])
    _system(pb.nd, pb.s_el, pb.u, pb.props, pb.table, torques, np.zeros((1, 1)), 1, 1, g,
            pb.f_node, np.zeros_like(pb.u), pb.slide_dof, pb.tb, pb.phi_r, pb.phi_rp, False)
    g[pb.fix_mask != 0] = 0.0
    g[0::pb.ndn][pb.bed_active != 0] = 0.0
    return g


def _fail(case, step, info, status, extra=""):
    reason = L.STATUS_TEXT.get(status, f"status {status}")
    raise SolveError(
        f"case {case.name!r} did not converge at {step}: {reason}; weighted residual "
        f"{info[I_RES]:.3e}, constraint violation {info[I_DELTA]:.3e}, top-tension residual "
        f"{info[I_TOP_RES]:.3e} after {int(info[I_ITER])} iterations{extra}"
    )


def newton_with_fallback(case: Case, pb: Problem):
    """Newton from the current state; on failure, the load-path homotopy.

    Returns the reactions and a dict of iteration counts.
    """
    tol = case.solver.tolerance
    maxit = case.solver.max_iterations
    u0, tb0, act0 = pb.u.copy(), pb.tb.copy(), pb.bed_active.copy()
    zero = np.zeros_like(pb.u)
    status, react, info = _run_newton(pb, zero, tol, maxit)
    iters = int(info[I_ITER])
    if status == L.OK:
        return react, {"iterations": iters, "load_steps": 1}
    # homotopy: G(u) - (1 - alpha) G(u0) = 0, alpha from 0 to 1
    pb.u[:], pb.tb[:], pb.bed_active[:] = u0, tb0, act0
    g0 = _residual(pb)
    alpha, step, steps = 0.0, 0.25, 0
    while alpha < 1.0:
        if steps >= case.solver.max_load_steps:
            _fail(case, f"load step {steps} (load factor {alpha:.4f})", info, status,
                  "; maximum number of load steps reached")
        trial = min(1.0, alpha + step)
        saved = pb.u.copy(), pb.tb.copy(), pb.bed_active.copy()
        status, react, info = _run_newton(pb, -(1.0 - trial) * g0, tol, maxit)
        iters += int(info[I_ITER])
        steps += 1
        if status == L.OK:
            alpha = trial
            step = min(2.0 * step, 0.5)
        else:
            pb.u[:], pb.tb[:], pb.bed_active[:] = saved
            step *= 0.5
            if step < 1e-4:
                _fail(case, f"load step {steps} (load factor {trial:.4f})", info, status,
                      "; load step cut below 1e-4")
    return react, {"iterations": iters, "load_steps": steps}


def touchdown_index(pb: Problem) -> int:
    """Index of the last node in seabed contact (the lower end counts as one).

    Contact just behind touchdown need not be contiguous: nodes there may hover
    a micrometre above the seabed with no reaction, so the last contact node
    is used, not the end of the contiguous block.
    """
    act = np.flatnonzero(pb.bed_active)
    return int(act[-1]) if act.size else 0


MAX_MESH_PASSES = 4


def touchdown_position(case: Case, pb: Problem) -> float:
    """Arc length of touchdown [m], located inside its element (see results)."""
    k = touchdown_index(pb)
    lo, hi = max(k - 1, 0), min(k + 5, pb.nn)
    ndn = pb.ndn
    _, rp, rpp = nodal_fields(pb.nd, pb.s[lo:hi], pb.u[lo * ndn:hi * ndn])
    kvec, _ = signed_curvature_vector(pb.nd, rp, rpp)
    moment = case.pipe.bending_stiffness * np.linalg.norm(kvec, axis=1)
    return touchdown_estimate(pb.s[lo:hi], moment, k - lo)


def solve_problem(case: Case):
    """Solve, then move the finest part of the mesh onto touchdown until a node
    sits there (to 2 % of the smallest element).

    Returns (problem, reactions, stats, touchdown arc length [m]).
    """
    t0 = time.perf_counter()
    pb = build_problem(case)
    react, stats = newton_with_fallback(case, pb)
    passes = 1
    s_t = touchdown_position(case, pb)
    while case.solver.grading and passes < MAX_MESH_PASSES:
        lam = pb.stats["flexural_length"]
        short_laid = case.lay.pipe_length is None and s_t < 0.5 * lam
        if abs(s_t - pb.stats["focus"]) <= 0.02 * pb.stats["h_min"] and not short_laid:
            break
        pb = remesh(case, pb, s_t)
        react, more = newton_with_fallback(case, pb)
        stats = {key: stats[key] + more[key] for key in stats}
        passes += 1
        s_t = touchdown_position(case, pb)
    stats["mesh_passes"] = passes
    stats["seconds"] = time.perf_counter() - t0
    return pb, react, stats, s_t


def remesh(case: Case, pb: Problem, s_tdp: float) -> Problem:
    """A mesh graded at ``s_tdp`` with the state interpolated onto it.

    Laid pipe is prepended when touchdown came closer to the lower end than one
    flexural length.
    """
    nd, ndn = pb.nd, pb.ndn
    lam = pb.stats["flexural_length"]
    extra = 0.0
    if case.lay.pipe_length is None and s_tdp < lam:
        extra = 2.0 * lam - s_tdp
    total = pb.s[-1] + extra
    focus = s_tdp + extra
    s = graded_nodes(total, [focus, total], pb.stats["h_max"], pb.stats["h_min"])
    u = interpolate_state(pb.s + extra, pb.u, nd, s)
    first = s < extra
    if first.any():
        u[0::ndn][first] = 0.0
        u[nd - 1::ndn][first] = pb.u[nd - 1] - (extra - s[first])
        u[nd::ndn][first] = 0.0
        u[2 * nd - 1::ndn][first] = 1.0
        u[2 * nd::ndn][first] = pb.u[2 * nd]
        if nd == 3:
            u[1::ndn][first] = pb.u[1]
            u[nd + 1::ndn][first] = 0.0
    stats = dict(pb.stats, focus=focus)
    return _problem(case, nd, s, u, pb.tb[0], focus + 1e-9 * pb.stats["h_min"], pb.fref, stats)


def solve(case: Case) -> Result:
    """Solve one case.

    Returns
    -------
    Result
        ``.summary`` (dict, DESIGN section 4 columns) and ``.profile`` (DataFrame,
        one row per node).

    Raises
    ------
    SolveError
        When Newton and the load-path fallback both fail; the message names the
        case, the load step, the residual and the reason.
    """
    pb, react, stats, s_t = solve_problem(case)
    columns = build_profile(case, pb, react)
    summary = build_summary(case, pb, columns, stats, s_t)
    return Result(case, summary, columns, state=pb)


def interpolate_state(s_old, u_old, nd, s_new):
    """Hermite interpolation of (r, r') and linear interpolation of lambda."""
    ndn = 2 * nd + 1
    idx = np.clip(np.searchsorted(s_old, s_new, side="right") - 1, 0, s_old.size - 2)
    le = s_old[idx + 1] - s_old[idx]
    xi = np.clip((s_new - s_old[idx]) / le, 0.0, 1.0)
    n1 = 1 - 3 * xi**2 + 2 * xi**3
    n2 = le * (xi - 2 * xi**2 + xi**3)
    n3 = 3 * xi**2 - 2 * xi**3
    n4 = le * (-(xi**2) + xi**3)
    d1 = (-6 * xi + 6 * xi**2) / le
    d2 = 1 - 4 * xi + 3 * xi**2
    d3 = (6 * xi - 6 * xi**2) / le
    d4 = -2 * xi + 3 * xi**2
    u = np.zeros(s_new.size * ndn)
    for i in range(nd):
        ra, rb = u_old[i::ndn][idx], u_old[i::ndn][idx + 1]
        pa, pbv = u_old[nd + i::ndn][idx], u_old[nd + i::ndn][idx + 1]
        u[i::ndn] = n1 * ra + n2 * pa + n3 * rb + n4 * pbv
        u[nd + i::ndn] = d1 * ra + d2 * pa + d3 * rb + d4 * pbv
    la, lb = u_old[2 * nd::ndn][idx], u_old[2 * nd::ndn][idx + 1]
    u[2 * nd::ndn] = (1 - xi) * la + xi * lb
    return u


__all__ = ["Problem", "SolveError", "solve"]

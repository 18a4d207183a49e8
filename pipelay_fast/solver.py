"""Solve one case: first guess, mesh, constraints, Newton with load-path fallback.

The orchestration lives here; every loop over nodes or elements is a kernel in
:mod:`pipelay_fast.kernels`. The path of a solve:

1. natural-catenary guess (:mod:`.catenary`) plus the laid pipe;
2. mesh graded at touchdown and the top (:mod:`.mesh`);
3. constraints as flat arrays (fixed unknowns in rotated nodal frames, the
   seabed contact from the lower end to touchdown, the stinger contact from
   lift-off to the top, a sliding lower end with its tension), the mesh
   mapped onto those boundaries, unknowns of Newton (:func:`_follow`);
4. Newton with line search (:func:`.kernels.newton.newton`), switching
   between lifting off and bearing on the stinger's tip when the kernel stops
   at the change of regime (:func:`_newton_in_regime`); if it fails, the
   out-of-balance force of the guess is removed in adaptive load steps, and the
   current is then applied in increments (friction is path dependent);
5. under gravity, until the mesh is graded at the boundaries the solve found
   (or when touchdown came too close to the lower end), the mesh is graded
   anew there and the solve repeated from the interpolated solution, so the
   answer does not depend on the path to it.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from .case import Case
from .guess import first_guess, shape
from .kernels import layout as L
from .kernels.contact import (
    N_STINGER,
    ST_A,
    ST_B,
    ST_C,
    ST_ON,
    ST_ZL,
    ST_ZU,
    friction_forces,
    friction_track,
    tip_geometry,
)
from .kernels.newton import I_DELTA, I_ITER, I_RES, I_TOP_RES, N_BND, N_INFO, _system, newton
from .kernels.types import Ends, Mesh, Model, Settings, Supports, load_factors
from .limits import IterationBudget, check_mesh_size, strain_beyond_line
from .mesh import graded_nodes
from .model import build_props, dimension_of, pin_jump
from .results import (
    Result,
    foundation_exit,
    build_profile,
    build_summary,
)


class SolveError(RuntimeError):
    """A case that did not converge, or whose answer is refused (beyond the
    model, or not a valid solution): the message names the step, residual and
    reason, or the limit."""


class _ShortLaid(Exception):
    """Newton stopped with SHORT_LAID: touchdown runs toward the modelled lower
    end, and the mesh needs more laid pipe (:func:`_solve_gravity`)."""


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
    bed_active: np.ndarray
    stinger: np.ndarray
    st_active: np.ndarray
    tip: np.ndarray
    fric: np.ndarray
    f_node: np.ndarray
    slide_dof: int
    tb: np.ndarray
    top_node: int
    top_target: float
    fref: float
    href: float
    stats: dict = field(default_factory=dict)
    before_current: list | None = None  # state snapshot before the current (friction path)
    warm: bool = False  # started from a neighbour's answer (no load path: the cold start is)
    tolerance: float | None = None  # Newton's tolerance when not solver.tolerance
    # the mesh follows the contact boundaries: node i at s_a[i] + sum_b
    # s_b[b, i] s_bd[b], touchdown on node bnodes[0], lift-off from (or
    # re-contact with) the stinger on bnodes[1], the material point over the
    # stinger's tip on bnodes[2] while it bears (-1: none; until the mesh is
    # mapped, all -1)
    bnodes: np.ndarray = field(default_factory=lambda: np.full(N_BND, -1, dtype=np.int64))
    s_a: np.ndarray | None = None
    s_b: np.ndarray | None = None
    s_bd: np.ndarray = field(default_factory=lambda: np.zeros(N_BND))
    # the load path's factors (layout F_*): the current's, full unless the
    # friction path raises it in steps, and friction, off until that path
    factors: np.ndarray = field(default_factory=lambda: load_factors(1.0, False))

    def model(self) -> Model:
        """What the element kernels read: the case's data and the load path's factors."""
        return Model(self.props, self.table, self.factors)

    def supports(self) -> Supports:
        return Supports(self.fix_mask, self.fix_val, self.phi_r, self.phi_rp, self.bed_active,
                        self.stinger, self.st_active, self.tip, self.fric)

    def ends(self, g_off) -> Ends:
        return Ends(self.f_node, g_off, self.tb, self.slide_dof, self.top_node,
                    float(self.top_target))

    def on_gravity_path(self):
        """No current and no friction: the friction path's first stage."""
        self.factors[:] = load_factors(0.0, False)

    @property
    def td_node(self) -> int:
        return int(self.bnodes[0])

    @property
    def lo_node(self) -> int:
        return int(self.bnodes[1])

    @property
    def tip_node(self) -> int:
        return int(self.bnodes[2])

    def follow(self, nodes, zones):
        """Map the mesh onto the contact boundaries at ``nodes`` (touchdown,
        lift-off or re-contact on the stinger, the stinger's tip; -1: none).

        Anchors are the boundary nodes, the ends of the pipe and, for boundary
        b, the nodes ``zones[b]`` = (below, above) [m] away from it, unless
        another boundary lies nearer; every node between two anchors keeps its
        share of the span between them, so each span's mesh is mapped onto its
        present ends with its grading, and nodes outside every zone stay put.
        """
        s = self.s
        nn = s.size
        kind = {0: -1, nn - 1: -1}  # anchor node -> boundary (-1: a fixed material point)
        for b, k in enumerate(nodes):
            if k >= 0:
                kind[int(k)] = b
        bnd = sorted(int(k) for k in nodes if k >= 0)
        for b, k in enumerate(nodes):
            if k < 0:
                continue
            z_lo, z_hi = zones[b]
            lower = max([j for j in bnd if j < k], default=0)
            upper = min([j for j in bnd if j > k], default=nn - 1)
            lo = int(np.searchsorted(s, s[k] - z_lo)) - 1
            hi = int(np.searchsorted(s, s[k] + z_hi))
            if lower < lo < k:
                kind.setdefault(lo, -1)
            if k < hi < upper:
                kind.setdefault(hi, -1)
        anchors = sorted(kind)
        s_a = s.copy()
        s_b = np.zeros((N_BND, nn))
        for a0, a1 in zip(anchors[:-1], anchors[1:], strict=True):
            i = np.arange(a0, a1 + 1)
            f = (s[i] - s[a0]) / (s[a1] - s[a0])
            s_a[i] = 0.0
            for end, share in ((a0, 1.0 - f), (a1, f)):
                if kind[end] < 0:
                    s_a[i] += share * s[end]
                else:
                    s_b[kind[end], i] = share
        for k, b in kind.items():  # the anchors themselves (counted twice above)
            s_a[k] = s[k] if b < 0 else 0.0
            s_b[:, k] = 0.0
            if b >= 0:
                s_b[b, k] = 1.0
                self.s_bd[b] = s[k]
        self.s_a, self.s_b = s_a, np.ascontiguousarray(s_b)
        self.bnodes = np.asarray(nodes, dtype=np.int64)

    def update_nodes(self):
        """Node arc lengths from the boundary unknowns (after a solve)."""
        if self.s_a is not None:
            self.s[:] = self.s_a + self.s_bd @ self.s_b

    @property
    def ndn(self) -> int:
        return 2 * self.nd + 1

    @property
    def nn(self) -> int:
        return self.s.size

    @property
    def s_el(self) -> np.ndarray:
        return np.diff(self.s)


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
    """First guess, graded mesh and constraints of a case."""
    nd = dimension_of(case)
    ndn = 2 * nd + 1
    h_max = case.solver.element_length

    def laid_default(cat):
        return (2.0 * math.sqrt(case.pipe.bending_stiffness / cat.h) + 5.0 * h_max
                + slipping_length_bound(case, cat))

    g = first_guess(case, laid_default)
    h_max, h_min, lam = _mesh_sizes(case, g.cat.h)
    # A stiff pipe touches down about one flexural length before the catenary
    # does (boundary-layer asymptotics): the mesh is finest there and the
    # initial seabed contact ends there.
    s_focus = max(g.laid - lam, 0.25 * g.laid)
    foci = [s_focus, g.total] + ([g.s_liftoff] if g.s_liftoff is not None else [])
    s = graded_nodes(g.total, foci, h_max, h_min, grading=case.solver.grading,
                     check=lambda n: check_mesh_size(case, n, g.total, g.laid,
                                                     _laid_source(case, g.cat, lam)))
    x, z, th, te, kappa = shape(case, g, s)
    u = np.zeros(s.size * ndn)
    u[0::ndn] = x
    u[nd - 1::ndn] = z
    u[nd::ndn] = np.sin(th)
    u[2 * nd - 1::ndn] = np.cos(th)
    u[2 * nd::ndn] = te - case.pipe.bending_stiffness * kappa**2
    stats = {"h_min": h_min, "h_max": h_max, "flexural_length": lam,
             "focus": s_focus,
             "stinger_foci": [g.s_liftoff] if g.s_liftoff is not None else [],
             "at_tip": g.at_tip}
    fref = max(g.cat.top_tension, abs(g.cat.w1) * g.total,
               case.lay.top_tension or 0.0)
    pb = _problem(case, nd, s, u, g.cat.h, fref, stats)
    _follow(case, pb, s_focus)
    return pb


def _follow(case: Case, pb: Problem, s_focus: float):
    """Map the mesh onto touchdown at the node nearest ``s_focus`` (on a rigid
    seabed: an elastic one is a foundation, with no contact boundary) and, in
    S-lay, onto lift-off and the material point over the stinger's tip."""
    s = pb.s
    zone = 3.0 * pb.stats["flexural_length"]
    pb.bed_active[:] = 0
    k = -1
    if case.seabed.is_rigid:
        k = int(np.argmin(np.abs(s[1:-1] - s_focus))) + 1
        pb.bed_active[1:k + 1] = 1
    lift = pb.stats.get("stinger_foci") or []
    if case.lay.stinger is None:
        _follow_nodes(case, pb, (k, -1, -1))
        return
    # lift-off: the guess's; where the guess leaves from the tip, the pipe
    # regains the stinger further up (a gap span between, bearing on the
    # tip): one flexural length above it as a start
    s_lift = lift[0] + (zone / 3.0 if pb.stats.get("at_tip") else 0.0)
    k0 = max(k, 0)
    kl = int(np.argmin(np.abs(s[k0 + 4:-1] - s_lift))) + k0 + 4
    pb.st_active[:] = 0
    pb.st_active[kl:-1] = 1
    # bearing on the tip (a guess that leaves from it): a node follows the
    # material point over the tip, the one whose guessed height is nearest
    # the tip's; lifting off, there is none until lift-off reaches the tip
    kt = -1
    if pb.stats.get("at_tip"):
        z = pb.u[pb.nd - 1::pb.ndn]
        kt = int(np.argmin(np.abs(z[k0 + 2:kl - 1] - pb.stinger[ST_ZL]))) + k0 + 2
    _follow_nodes(case, pb, (k, kl, kt))


def _follow_nodes(case: Case, pb: Problem, nodes):
    """The mesh follows the boundaries on ``nodes`` (touchdown, lift-off, the
    tip's point; -1: none), each with a zone of three flexural lengths."""
    zone = 3.0 * pb.stats["flexural_length"]
    pb.follow(nodes, ((zone, zone), (zone, min(zone, 0.9 * (pb.s[-1] - pb.s[nodes[1]]))),
                      (zone, zone)))


ON_FOCUS = 0.02  # a mesh is graded at a point within this share of h_min of it
HOLD_SPLIT = 0.1  # the shortest element [h_min] between lift-off and the tip's point


def _graded_on_boundaries(case: Case, pb: Problem) -> bool:
    """True when the mesh that follows the boundaries is graded at each of
    them: touchdown and every point of :func:`_stinger_foci` lie within
    ON_FOCUS h_min of a point the mesh was graded at. Regrading until it is
    makes the answer the mesh's at the boundaries the solve found, whatever
    the path (cold, warm, a target solve's trials) that led there."""
    near = ON_FOCUS * pb.stats["h_min"]
    held = pb.stats.get("stinger_foci", [])
    if abs(touchdown_position(pb) - pb.stats["focus"]) > near:
        return False
    return all(any(abs(p - f) <= near for f in held) for p in _stinger_foci(case, pb))


def _lateral_hold_start(case: Case, pb: Problem):
    """In 3D under lateral load, lifting off above the stinger's tip with no
    node over it: the arc length [m] of the material point over the tip,
    where the lateral hold begins (every point over the stinger's z range is
    held at y = 0), for the mesh to hold a node there. None otherwise (with
    planar loads the hold carries nothing, and the mesh is the 2D case's),
    and when that point lies within HOLD_SPLIT h_min of lift-off (lift-off's
    node then begins the hold, that close to the tip)."""
    if pb.nd != 3 or case.is_planar or pb.lo_node < 0 or pb.tip_node >= 0:
        return None
    found, _gap, _c, s_tip = tip_geometry(pb.nd, pb.s_el, pb.u, pb.stinger,
                                          np.zeros_like(pb.u))
    if not found or s_tip > pb.s[pb.lo_node] - HOLD_SPLIT * pb.stats["h_min"]:
        return None
    return float(s_tip)


def _laid_source(case: Case, cat, lam: float) -> str:
    """What set the laid length of the first mesh (for the mesh-size check)."""
    if case.lay.pipe_length is not None:
        return f"lay.pipe_length = {case.lay.pipe_length!r} m less the suspended span"
    if case.solver.laid_length is not None:
        return f"solver.laid_length = {case.solver.laid_length!r} m"
    text = (f"the default of solver.laid_length: two flexural lengths sqrt(EI/T) = {lam:.4g} m "
            "at touchdown, five elements")
    slip = slipping_length_bound(case, cat)
    if slip > 0.0:
        text += (f" and {slip:.4g} m for seabed friction to take up the lateral drag "
                 "(environment.current.speed, seabed.lateral_friction)")
    return text


def _problem(case: Case, nd, s, u, tb, fref, stats) -> Problem:
    """Constraint arrays for nodes ``s`` with state ``u``. The contact sets
    start empty: the mapping of the mesh onto the boundaries sets them
    (:func:`_follow`, :func:`remesh`), or a warm start copies them."""
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
    stinger = np.zeros(N_STINGER)
    st = lay.stinger
    pinned = lay.top_angle == "pinned"
    top_angle = None if pinned else lay.top_angle
    if st is not None:
        stinger[:] = (st.a, st.b, st.c, st.lower[1], st.upper[1], 1.0)
        if top_angle is None:
            # the firing line, and below a pinned top (the pipe conforms up to
            # the pin, model.pin_jump): held along the stinger's tangent
            top_angle = float(st.angle(st.upper[1]))
    if top_angle is not None:
        phi_rp[top] = math.radians(top_angle)
        fix_mask[base + nd] = 1  # r' normal to the prescribed direction = 0
        if nd == 3 and not pinned:
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
        top_target = lay.top_tension - pin_jump(case)  # Te below a pinned top
    else:
        tb = lay.bottom_tension
    if not case.seabed.is_rigid:  # a foundation: the lower end's x free
        fix_mask[0] = 0
    bed_active = np.zeros(nn, dtype=np.int8)
    st_active = np.zeros(nn, dtype=np.int8)
    props, table = build_props(case)
    fric = np.zeros((nn, L.N_FRIC))
    _anchor(fric, u, nd, s)
    return Problem(nd, s, props, table, u, fix_mask, fix_val, phi_r, phi_rp, bed_active,
                   stinger, st_active, np.zeros(2), fric, np.zeros(nn * ndn), slide_dof,
                   np.array([float(tb)]), top,
                   top_target, fref, stats["h_max"], stats=stats)


def _run_newton(pb: Problem, g_off, tol, maxit):
    react = np.zeros_like(pb.u)
    info = np.zeros(N_INFO)
    if pb.s_a is not None:
        s_a, s_b = pb.s_a, pb.s_b
    else:
        s_a, s_b = np.zeros(pb.nn), np.zeros((N_BND, pb.nn))
    mesh = Mesh(pb.s_el, s_a, s_b, pb.s_bd, pb.bnodes)
    settings = Settings(float(tol), float(pb.fref), float(pb.href), int(maxit))
    status = newton(pb.nd, pb.u, mesh, pb.model(), pb.supports(), pb.ends(g_off), settings,
                    react, info)
    pb.update_nodes()
    return status, react, info


def _residual(pb: Problem):
    """Residual at the current state with constrained rows zeroed (for the homotopy)."""
    g = np.zeros_like(pb.u)
    torques = np.full(pb.nn - 1, pb.props[L.TORQUE])
    _system(pb.nd, pb.s_el, pb.u, pb.model(), torques, np.zeros((1, 1)), 1, 1, g,
            pb.ends(np.zeros_like(pb.u)), pb.phi_r, pb.phi_rp, False)
    friction_forces(pb.nd, pb.u, g, np.zeros((1, 1)), 0, pb.model(), pb.bed_active, pb.fric,
                    np.zeros_like(pb.u), pb.s)
    g[pb.fix_mask != 0] = 0.0
    g[0::pb.ndn][pb.bed_active != 0] = 0.0
    return g


def _newton_state(info, status):
    """The reason and residuals of a Newton call that ended with ``status``."""
    reason = L.STATUS_TEXT.get(status, f"status {status}")
    return (f"{reason}; weighted residual {info[I_RES]:.3e}, constraint violation "
            f"{info[I_DELTA]:.3e}, top-tension residual {info[I_TOP_RES]:.3e} after "
            f"{int(info[I_ITER])} iterations")


def _fail(case, step, info, status, extra=""):
    raise SolveError(f"case {case.name!r} did not converge at {step}: "
                     f"{_newton_state(info, status)}{extra}")


MAX_TIP_SWITCHES = 2  # switches between bearing on the tip and lifting off, per solve


def _passes_below_tip(pb: Problem) -> bool:
    """True when, lifting off with no node over the tip, the pipe passes below
    the stinger's tip (the complementarity at the tip then asks it to bear)."""
    if pb.lo_node < 0 or pb.tip_node >= 0:
        return False
    found, gap, _c, s_tip = tip_geometry(pb.nd, pb.s_el, pb.u, pb.stinger,
                                         np.zeros_like(pb.u))
    return bool(found and s_tip < pb.s[pb.lo_node] and gap < -1e-9 * pb.href)


def _bear_on_tip(case: Case, pb: Problem):
    """The regime switch the complementarity at the tip makes as lift-off
    reaches it from above: the pipe now bears on the tip and regains the
    stinger further up, one flexural length above (as a cold start from a
    guess that leaves at the tip does), with the gap span between free."""
    s = pb.s
    kt = pb.tip_node
    if kt < 0:  # lifting off there was none: lift-off's node, now at the tip
        kt = pb.lo_node
    k = int(np.searchsorted(s, s[pb.lo_node] + pb.stats["flexural_length"]))
    k = min(max(k, pb.lo_node + 1, kt + 1), pb.nn - 2)
    pb.st_active[:] = 0
    pb.st_active[k:-1] = 1
    pb.tip[0], pb.tip[1] = 1.0, 0.0
    _follow_nodes(case, pb, (pb.td_node, k, kt))


def _lift_off_above_tip(case: Case, pb: Problem):
    """The regime switch back: bearing on the tip, Newton closes the gap span
    (status SPAN_CLOSED), so the pipe lifts off the stinger above the tip,
    at re-contact's node, with no node over the tip."""
    pb.tip[0], pb.tip[1] = 0.0, 0.0
    _follow_nodes(case, pb, (pb.td_node, pb.lo_node, -1))


def _budgeted_newton(case: Case, pb: Problem, g_off, budget: IterationBudget, where: str,
                     switch: bool = False):
    """:func:`_run_newton` within the solve's iteration budget; a SolveError
    naming solver.max_iterations_total when it is spent. ``switch``: a
    lift-off that reaches the stinger's tip (status PAST_TIP) is returned to
    the caller, which switches to bearing on the tip, instead of raised."""
    if budget.left < 1:
        raise SolveError(f"case {case.name!r} {budget.spent_message(where)}")
    status, react, info = _run_newton(pb, g_off, pb.tolerance or case.solver.tolerance,
                                      budget.cap(case.solver.max_iterations))
    budget.charge(info[I_ITER])
    if status == L.SHORT_LAID:
        raise _ShortLaid
    if status in (L.PAST_TIP, L.SPAN_CLOSED) and not switch:
        raise SolveError(f"case {case.name!r} at {where}: {_newton_state(info, status)}")
    if status != L.OK and budget.left < 1:
        raise SolveError(f"case {case.name!r} {budget.spent_message(where)} (last Newton "
                         f"call: {_newton_state(info, status)})")
    return status, react, info


_STATE = ("u", "tb", "bed_active", "st_active", "tip", "fric", "phi_r", "phi_rp", "s", "s_bd")


def _snapshot(pb: Problem):
    return [getattr(pb, name).copy() for name in _STATE]


def _restore(pb: Problem, snap):
    for name, arr in zip(_STATE, snap, strict=True):
        getattr(pb, name)[:] = arr


def _newton_in_regime(case: Case, pb: Problem, g_off, budget: IterationBudget, where: str):
    """:func:`_budgeted_newton`, switching between lifting off and bearing on
    the stinger's tip (at most MAX_TIP_SWITCHES times) when the kernel stops
    at the change of regime (PAST_TIP, SPAN_CLOSED) or, lifting off, the
    answer passes below the tip.

    Returns (status, reactions, info, iterations of every call, the state
    the last call started from).
    """
    spent = 0  # iterations of the calls that ended in a switch of regime
    for switches in range(MAX_TIP_SWITCHES + 1):
        start = _snapshot(pb)
        can_switch = pb.lo_node >= 0 and switches < MAX_TIP_SWITCHES
        status, react, info = _budgeted_newton(case, pb, g_off, budget, where,
                                              switch=can_switch)
        if status == L.OK and can_switch and _passes_below_tip(pb):
            status = L.PAST_TIP  # lifting off, the pipe would pass under the tip
        if status not in (L.PAST_TIP, L.SPAN_CLOSED):
            break
        spent += int(info[I_ITER])
        if status == L.PAST_TIP:
            _bear_on_tip(case, pb)
        else:
            _lift_off_above_tip(case, pb)
    return status, react, info, int(info[I_ITER]) + spent, start


def newton_with_fallback(case: Case, pb: Problem, budget: IterationBudget | None = None):
    """Newton from the current state; on failure, the load-path homotopy.
    ``budget``: the solve's Newton iterations left (None: a fresh one).

    Returns the reactions and a dict of iteration counts.
    """
    budget = budget or IterationBudget(case.solver.max_iterations_total)
    zero = np.zeros_like(pb.u)
    # (the boundaries start where the guess puts them; the kernel holds
    # them until the pipe is in equilibrium there: an explicit solve with
    # them held first cost S67 2 to 5 more iterations)
    status, react, info, iters, start = _newton_in_regime(
        case, pb, zero, budget, "the first Newton solve on a mesh")
    if status == L.OK:
        return react, {"iterations": iters, "load_steps": 1}
    if pb.warm:
        # a warm start is Newton from the neighbour's answer; where that does
        # not converge the neighbour is too far, and the cold start (with its
        # load path) is cheaper than a load path from the neighbour's state
        _fail(case, "the warm start's Newton solve", info, status)
    # homotopy: G(u) - (1 - alpha) G(u0) = 0, alpha from 0 to 1
    _restore(pb, start)
    g0 = _residual(pb)
    alpha, step, steps = 0.0, 0.25, 0
    while alpha < 1.0:
        if steps >= case.solver.max_load_steps:
            _fail(case, f"load step {steps} (load factor {alpha:.4f})", info, status,
                  "; maximum number of load steps reached")
        trial = min(1.0, alpha + step)
        saved = _snapshot(pb)
        status, react, info, used, _start = _newton_in_regime(
            case, pb, -(1.0 - trial) * g0, budget,
            f"load step {steps + 1} (load factor {trial:.4f})")
        iters += used
        steps += 1
        if status == L.OK:
            alpha = trial
            step = min(2.0 * step, 0.5)
        else:
            _restore(pb, saved)
            step *= 0.5
            if step < 1e-4:
                _fail(case, f"load step {steps} (load factor {trial:.4f})", info, status,
                      "; load step cut below 1e-4")
    return react, {"iterations": iters, "load_steps": steps}


MAX_MESH_PASSES = 4
LOOSE_TOLERANCE = 1e-4  # the first mesh's Newton tolerance [-]: boundaries to about 1e-4 href


def touchdown_position(pb: Problem) -> float:
    """Arc length of touchdown [m]: its node's on a rigid seabed; on an
    elastic one, where the pipe rises out of the foundation (x = 0, linear
    between the last node below the surface and the next)."""
    if pb.td_node >= 0:
        return float(pb.s[pb.td_node])
    return foundation_exit(pb.s, pb.u[0::pb.ndn])


def conform_end(pb: Problem):
    """Arc length [m] where the pipe leaves (or regains) the stinger's curve:
    lift-off's node; None without a stinger."""
    return float(pb.s[pb.lo_node]) if pb.lo_node >= 0 else None


def tip_position(pb: Problem):
    """Arc length [m] of the material point on the stinger's tip when it bears."""
    if pb.stinger[ST_ON] == 0.0 or pb.tip[0] == 0.0 or pb.tip_node < 0:
        return None
    return float(pb.s[pb.tip_node])


def liftoff_position(case: Case, pb: Problem):
    """Arc length of lift-off [m]: the tip when it bears, else where the pipe
    leaves the stinger's curve; None without a stinger."""
    if pb.stinger[ST_ON] == 0.0:
        return None
    s_tip = tip_position(pb)
    if s_tip is not None:
        return s_tip
    s_c = conform_end(pb)
    return float(pb.s[-1]) if s_c is None else s_c


def _stinger_foci(case: Case, pb: Problem):
    """Arc lengths [m] the mesh should hold as nodes on the stinger side (a
    mesh that follows the boundaries: lift-off's and the tip's nodes, and in
    3D where the lateral hold begins, :func:`_lateral_hold_start`)."""
    foci = [float(pb.s[k]) for k in (pb.lo_node, pb.tip_node) if k >= 0]
    s_hold = _lateral_hold_start(case, pb)
    return foci if s_hold is None else [*foci, s_hold]


MAX_LAID_DOUBLINGS = 6


def solve_problem(case: Case, warm: Problem | None = None):
    """Solve with enough laid pipe: when the lower end, held laterally, carries
    more than LOWER_END_SHARE of the laid pipe's lateral force (friction has not
    taken it all up), the laid length is doubled and the case solved again.
    ``warm``: the solved problem of a neighbouring case to start from. All
    the passes share one budget of solver.max_iterations_total iterations.

    Returns (problem, reactions, stats, touchdown and lift-off arc lengths [m]).
    """
    t0 = time.perf_counter()
    current = case
    budget = IterationBudget(case.solver.max_iterations_total)
    for _ in range(MAX_LAID_DOUBLINGS + 1):
        pb, react, stats, s_t, s_l = _solve_mesh(current, warm, budget)
        warm = None
        if not _lower_end_holds(pb, react) or case.lay.pipe_length is not None:
            stats["seconds"] = time.perf_counter() - t0
            return pb, react, stats, s_t, s_l
        laid = s_t + pb.stats["flexural_length"]  # what this mesh modelled behind touchdown
        current = current.with_changes({"solver.laid_length": 2.0 * laid})
    raise SolveError(
        f"case {case.name!r}: seabed friction does not hold the laid pipe before its "
        f"modelled lower end even with {current.solver.laid_length:.0f} m of it (the current "
        "on the laid pipe may exceed the friction); check seabed.lateral_friction and the "
        "current profile, or set solver.laid_length"
    )


LOWER_END_SHARE = 0.01  # largest share of the seabed's lateral force the held lower end may carry


def _lower_end_holds(pb: Problem, react) -> bool:
    """True when the lower end, held laterally, carries more than LOWER_END_SHARE
    of the lateral force on the laid pipe: the slipping (or elastically held)
    zone then reaches it, and more laid pipe is needed."""
    if pb.nd != 3 or pb.factors[L.F_FRICTION] == 0.0:
        return False
    on_bed = np.flatnonzero(pb.fric[:, L.FR_W] > 0.0)
    total = np.abs(react[on_bed * pb.ndn + 1]).sum() + abs(react[1])
    return abs(react[1]) > LOWER_END_SHARE * total


def _solve_mesh(case: Case, warm: Problem | None, budget: IterationBudget):
    """Solve under gravity, grading the mesh anew at the boundaries found until
    it is graded at them (:func:`_graded_on_boundaries`), then follow the
    current's path (the mesh follows the boundaries it moves). ``budget``:
    the solve's Newton iterations left.

    Returns (problem, reactions, stats, touchdown and lift-off arc lengths [m]).
    """
    t0 = time.perf_counter()
    pb = build_problem(case) if warm is None else warm_problem(case, warm)
    # friction is path dependent: gravity first, then the current in steps
    path = friction_path(case)
    if path:
        pb.on_gravity_path()
    # the first mesh only to LOOSE_TOLERANCE: it is to find where the
    # boundaries are, and is graded anew there unless it already is
    pb.tolerance = max(case.solver.tolerance, LOOSE_TOLERANCE)
    pb, react, stats = _solve_gravity(case, pb, budget)
    passes = 1
    while True:
        s_t = touchdown_position(pb)
        foci = _stinger_foci(case, pb)
        lam = pb.stats["flexural_length"]
        short_laid = case.lay.pipe_length is None and s_t < 0.5 * lam
        # the mesh follows the boundaries: graded anew at them until it is
        # graded where they are, and when laid pipe is short
        if (not case.solver.grading or passes >= MAX_MESH_PASSES
                or (_graded_on_boundaries(case, pb) and not short_laid)):
            if pb.tolerance is not None:  # on to the tolerance, this mesh
                pb.tolerance = None
                pb, react, more = _solve_gravity(case, pb, budget)
                stats = {key: stats[key] + more[key] for key in stats}
                s_t = touchdown_position(pb)
                foci = _stinger_foci(case, pb)
            break
        pb = remesh(case, pb, s_t, foci)
        pb.tolerance = None  # graded at the boundaries: to the tolerance
        if path:
            pb.on_gravity_path()
        pb, react, more = _solve_gravity(case, pb, budget)
        stats = {key: stats[key] + more[key] for key in stats}
        passes += 1
    while path:
        pb.before_current = _snapshot(pb)
        # friction springs anchored where the pipe lies under gravity alone
        _anchor(pb.fric, pb.u, pb.nd, pb.s)
        friction_track(pb.nd, pb.u, react, pb.props, pb.bed_active, pb.fric, pb.s)
        pb.factors[L.F_FRICTION] = 1.0
        try:
            react, more = apply_current(case, pb, budget)
            short = False
        except _ShortLaid:  # touchdown ran toward the lower end under the current
            short = True
        if not short:
            # the mesh follows the boundaries the current moves
            stats = {key: stats[key] + more[key] for key in stats}
            s_t = touchdown_position(pb)
            break
        # more laid pipe, from the pipe under gravity alone, and the path again
        _restore(pb, pb.before_current)
        pb = _with_more_laid(case, pb)
        pb.on_gravity_path()
        pb, react, more = _solve_gravity(case, pb, budget)
        stats = {key: stats[key] + more[key] for key in stats}
        passes += 1
    stats["mesh_passes"] = passes
    stats["seconds"] = time.perf_counter() - t0
    return pb, react, stats, s_t, liftoff_position(case, pb)


def _solve_gravity(case: Case, pb: Problem, budget: IterationBudget):
    """:func:`newton_with_fallback`, with laid pipe prepended each time Newton
    stops because touchdown runs toward the modelled lower end (SHORT_LAID).

    Returns (problem, reactions, iteration counts).
    """
    used = budget.used
    for _ in range(MAX_LAID_DOUBLINGS + 1):
        try:
            react, stats = newton_with_fallback(case, pb, budget)
        except _ShortLaid:
            pb = _with_more_laid(case, pb)
            continue
        stats["iterations"] = budget.used - used  # the stopped calls' too
        return pb, react, stats
    raise SolveError(f"case {case.name!r}: touchdown still runs toward the lower end with "
                     f"{touchdown_position(pb):.4g} m of laid pipe modelled after "
                     f"{MAX_LAID_DOUBLINGS} doublings of it; the case may have no touchdown")


def _with_more_laid(case: Case, pb: Problem) -> Problem:
    """The mesh with its laid pipe doubled (at least two flexural lengths):
    touchdown ran toward the lower end. A given pipe length has no more pipe:
    SolveError."""
    s_t = touchdown_position(pb)
    if case.lay.pipe_length is not None:
        raise SolveError(f"case {case.name!r}: touchdown runs into the lower end, held at "
                         f"lay.pipe_length = {case.lay.pipe_length!r} m (the pipe is too "
                         "short to reach the seabed and lie on it)")
    lam = pb.stats["flexural_length"]
    return remesh(case, pb, s_t, _stinger_foci(case, pb), laid=max(2.0 * lam, 2.0 * s_t))


def apply_current(case: Case, pb: Problem, budget: IterationBudget | None = None,
                  first_step=0.25, max_step=0.25):
    """Raise the current factor from 0 to 1 in load steps (friction follows
    this path), halving a step that fails; at most ``max_step`` per step.
    ``budget``: the solve's Newton iterations left (None: a fresh one).

    Steps of 0.5 save a quarter of the iterations and give the same answer on
    meshes of 1 m and coarser, but on S125 3D at 0.05 m they follow another
    slip path (slipping length 25 m against 15.6 m, peak stress 0.5 % lower).
    """
    budget = budget or IterationBudget(case.solver.max_iterations_total)
    factor, step = 0.0, first_step
    stats = {"iterations": 0, "load_steps": 0}
    zero = np.zeros_like(pb.u)
    react = None
    while factor < 1.0:
        trial = min(1.0, factor + step)
        saved = _snapshot(pb)
        pb.factors[L.F_CURRENT] = trial
        status, react, info, iters, _start = _newton_in_regime(
            case, pb, zero, budget, f"current factor {trial:.4f}")
        stats["iterations"] += iters
        stats["load_steps"] += 1
        if status != L.OK:
            _restore(pb, saved)
            step *= 0.5
            if step < 1e-3 or stats["load_steps"] >= 4 * case.solver.max_load_steps:
                _fail(case, f"current factor {trial:.4f}", info, status,
                      f"; current step cut to {step:.1e}")
            continue
        factor = trial
        step = min(2.0 * step, max_step)
    pb.factors[L.F_CURRENT] = 1.0
    return react, stats


def warm_problem(case: Case, old: Problem) -> Problem:
    """The problem of ``case`` on the mesh of a solved neighbouring case, its
    state (shape, contacts, tension) the starting point. On the friction path
    the state before the current is taken, so that the slip path is followed
    from gravity alone again."""
    nd = dimension_of(case)
    if nd != old.nd:
        raise ValueError(f"warm: a {old.nd}D solution cannot start a {nd}D case")
    if (old.stinger[ST_ON] != 0.0) != (case.lay.stinger is not None):
        raise ValueError(f"warm: lay.method {case.lay.method!r} differs from the warm case's")
    state = dict(zip(_STATE, old.before_current or _snapshot(old), strict=True))
    new = _problem(case, nd, old.s.copy(), state["u"].copy(), state["tb"][0], old.fref,
                   dict(old.stats))
    new.warm = True
    for name in ("bed_active", "st_active", "tip", "fric"):
        getattr(new, name)[:] = state[name]
    if old.s_a is not None:
        new.bnodes, new.s_a, new.s_b = old.bnodes.copy(), old.s_a.copy(), old.s_b.copy()
        new.s_bd = state["s_bd"].copy()
        new.s[:] = state["s"]
    _onto_stinger(new, old.stinger)
    return new


def _onto_stinger(pb: Problem, old_stinger: np.ndarray):
    """Carry a warm state over to a changed stinger: every node over the
    stinger's z range moves in x by the change of the curve there (which
    vanishes at both ends when only ``a`` changed), its slope with it, so the
    contacts start on the new curve and the free span keeps its shape."""
    if pb.stinger[ST_ON] == 0.0 or old_stinger[ST_ON] == 0.0:
        return
    nd, ndn = pb.nd, pb.ndn
    z = pb.u[nd - 1::ndn].copy()
    zp = pb.u[2 * nd - 1::ndn].copy()
    over = (z >= pb.stinger[ST_ZL]) & (z <= pb.stinger[ST_ZU])

    def curve(st, zz):
        return (st[ST_A] * zz + st[ST_B]) * zz + st[ST_C], 2.0 * st[ST_A] * zz + st[ST_B]

    x_new, dx_new = curve(pb.stinger, z[over])
    x_old, dx_old = curve(old_stinger, z[over])
    shift, slope = x_new - x_old, dx_new - dx_old
    # below the tip, down to touchdown: a shift that continues the slope
    # change at the tip and vanishes at touchdown (no kink at the tip)
    z_l = pb.stinger[ST_ZL]
    z_td = float(np.interp(touchdown_position(pb), pb.s, z))
    span = (z < z_l) & (z > z_td)
    if span.any() and z_l > z_td:
        k = curve(pb.stinger, np.array([z_l]))[1][0] - curve(old_stinger, np.array([z_l]))[1][0]
        zs = z[span]
        shift = np.concatenate([shift, k * (zs - z_l) * (zs - z_td) / (z_l - z_td)])
        slope = np.concatenate([slope, k * (2.0 * zs - z_l - z_td) / (z_l - z_td)])
        over = np.concatenate([np.flatnonzero(over), np.flatnonzero(span)])
    else:
        over = np.flatnonzero(over)
    idx = over * ndn
    pb.u[idx] += shift
    rp = pb.u[(idx + nd)[:, None] + np.arange(nd)]
    stretch = np.linalg.norm(rp, axis=1)  # kept: the axial strain is unchanged
    rp[:, 0] += slope * zp[over]
    rp *= (stretch / np.linalg.norm(rp, axis=1))[:, None]
    pb.u[(idx + nd)[:, None] + np.arange(nd)] = rp


def remesh(case: Case, pb: Problem, s_tdp: float, stinger_foci=(),
           laid: float | None = None) -> Problem:
    """A mesh with nodes at ``s_tdp`` and ``stinger_foci`` [m], graded there, the
    state interpolated onto it.

    Laid pipe is prepended when touchdown came closer to the lower end than one
    flexural length (to two of them), or to ``laid`` [m] behind touchdown when
    that is given.
    """
    nd, ndn = pb.nd, pb.ndn
    lam = pb.stats["flexural_length"]
    extra = 0.0
    if case.lay.pipe_length is None and s_tdp < lam:
        extra = 2.0 * lam - s_tdp
    if laid is not None:
        extra = max(extra, laid - s_tdp)
    total = pb.s[-1] + extra
    focus = s_tdp + extra
    held = [f + extra for f in stinger_foci]
    foci = [focus, total, *held]
    source = (f"remeshed, {extra:.4g} m of it prepended to keep two flexural lengths "
              f"sqrt(EI/T) = {lam:.4g} m behind touchdown, which a lower tension T there "
              "lengthens")
    s = graded_nodes(total, foci, pb.stats["h_max"], pb.stats["h_min"],
                     check=lambda n: check_mesh_size(case, n, total, focus, source))
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
    stats = dict(pb.stats, focus=focus, stinger_foci=held)
    new = _problem(case, nd, s, u, pb.tb[0], pb.fref, stats)
    new.warm, new.tolerance = pb.warm, pb.tolerance
    # the new mesh follows the same boundaries, each on the node graded onto it
    def at(k):
        return -1 if k < 0 else int(np.argmin(np.abs(s - (pb.s[k] + extra))))
    new.bed_active[:] = 0
    new.bed_active[1:at(pb.td_node) + 1] = 1
    if pb.lo_node >= 0:
        new.st_active[:] = 0
        new.st_active[at(pb.lo_node):-1] = 1
    _follow_nodes(case, new, (at(pb.td_node), at(pb.lo_node), at(pb.tip_node)))
    new.tip[:] = pb.tip  # a bearing tip keeps bearing (its point moves with the pipe)
    return new


def solve(case: Case, *, warm: Result | None = None) -> Result:
    """Solve one case.

    ``warm``: the result of a neighbouring case (same dimension and lay method,
    e.g. the previous `a` of a sweep); Newton starts from its solution on its
    mesh instead of from the catenary guess, and falls back to the catenary
    guess if that fails (or if its answer is refused).

    Returns
    -------
    Result
        ``.summary`` (dict, the columns of ``results.SUMMARY_UNITS``) and ``.profile`` (DataFrame,
        one row per node).

    Raises
    ------
    SolveError
        When Newton and the load-path fallback both fail, or
        solver.max_iterations_total Newton iterations are spent (each start,
        warm and cold, has its own budget); the message names the case, the
        load step, the residual and the reason. Also when the answer is
        refused: non-finite, strained beyond solver.max_strain, or a contact
        that pulls.
    ValueError
        When the mesh would exceed solver.max_elements (checked before it is
        built).
    """
    if warm is not None and not isinstance(getattr(warm, "state", None), Problem):
        raise ValueError("warm: expected a Result from pipelay_fast.solve, got "
                         f"{type(warm).__name__}")
    if warm is not None:
        try:
            return _checked_solve(case, warm.state)
        except SolveError:  # a neighbour too far away: start from the catenary
            pass
    return _checked_solve(case)


def _checked_solve(case: Case, warm: Problem | None = None) -> Result:
    """Solve, build the result and refuse it if it is not finite or is
    strained beyond solver.max_strain."""
    pb, react, stats, s_t, s_l = solve_problem(case, warm)
    _check_regime(case, pb)
    columns = build_profile(case, pb, react)
    summary = build_summary(case, pb, columns, stats, s_t, s_l)
    bad = [key for key, val in summary.items() if isinstance(val, float) and np.isinf(val)]
    bad += [key for key, col in columns.items()
            if col.dtype.kind == "f" and not np.isfinite(col).all()]
    if bad:
        raise SolveError(f"case {case.name!r}: the solution has non-finite values in "
                         f"{', '.join(bad)}; it is not returned")
    beyond = strain_beyond_line(case, columns)
    if beyond is not None:
        raise SolveError(f"case {case.name!r}: {beyond}")
    return Result(case, summary, columns, state=pb)


def _check_regime(case: Case, pb: Problem):
    """Refuse a lift-off that the boundaries unknowns put below the stinger's
    tip, on the curve continued past it: there the pipe bears on the tip,
    but the solve ended lifting off (it switches between the two regimes at
    most MAX_TIP_SWITCHES times)."""
    if pb.lo_node < 0:
        return
    z_lo = float(pb.u[pb.lo_node * pb.ndn + pb.nd - 1])
    z_tip = float(pb.stinger[ST_ZL])
    if z_lo < z_tip:
        raise SolveError(
            f"case {case.name!r}: the pipe bears on the stinger's tip (its lift-off, "
            f"z = {z_lo:.3f} m, would lie below the tip, z = {z_tip:.3f} m), but the solve "
            f"ended lifting off (it switches between bearing on the tip and lifting off "
            f"at most {MAX_TIP_SWITCHES} times)")


def slipping_length_bound(case: Case, cat) -> float:
    """Laid length [m] over which friction takes up the lateral drag's share at
    touchdown, so that the held lower end carries none (0 off the friction
    path or without a lateral current).

    The suspended span, the natural catenary ``cat`` (:mod:`.catenary`), as a
    taut string from touchdown to its top, straight in height: the lateral
    drag q(t) on it puts a share int q (1 - t) ds on touchdown, which friction
    mu w carries over its slipping length. The string ignores the pipe's
    lateral bending and the drag's fall as the pipe swings, so this bounds the
    slipping length found (about twice it in J125, 1 and 2 m/s).
    """
    ey = case.current_direction[0]
    if not (friction_path(case) and dimension_of(case) == 3 and ey != 0.0):
        return 0.0
    t = np.linspace(0.0, 1.0, 65)
    pipe = case.pipe
    speed = np.asarray(case.current_speed_at(t * cat.x_top)) * ey
    q = (0.5 * case.environment.water_density * pipe.drag_coefficient
         * pipe.hydrodynamic_diameter * speed**2) * (1.0 - t)
    share = cat.length * float(np.sum(0.5 * (q[1:] + q[:-1]) * np.diff(t)))
    return share / (case.seabed.lateral_friction * float(case.effective_weight(0.0)))


def friction_path(case: Case) -> bool:
    """True when seabed friction meets the current: its load path is followed."""
    lateral = dimension_of(case) == 3 and case.seabed.lateral_friction > 0.0
    return (lateral or case.seabed.axial_friction > 0.0) and case.environment.current.speed > 0.0


def _anchor(fric, u, nd, s):
    """Friction springs unstretched: anchors at the nodes' present positions
    and material points (arc lengths ``s`` [m])."""
    ndn = 2 * nd + 1
    fric[:, L.FR_S] = s
    fric[:, L.FR_Z] = u[nd - 1::ndn]
    if nd == 3:
        fric[:, L.FR_Y] = u[1::ndn]
    fric[:, L.FR_DIR] = 0.0
    fric[:, L.FR_DIRZ] = 0.0


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

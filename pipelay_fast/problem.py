"""A solve's problem as arrays: the mesh, its constraints and its state.

:class:`Problem` holds what the Newton kernel reads (the case's data, the
mesh that follows the contact boundaries, the supports, the ends, the
state). It is built from the first guess (:func:`build_problem`), carried
over from a solved neighbour (:func:`warm_problem`), or graded anew with the
state interpolated onto the new mesh (:func:`remesh`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .boundaries import (
    bear_on_tip,
    follow_boundaries,
    follow_nodes,
    over_rollers,
    touchdown_position,
)
from .case import Case
from .guess import first_guess, guide_case, shape
from .kernels import layout as L
from .kernels.geometry import hermite_state
from .kernels.grading import boundary_map
from .kernels.layout import B_LO, B_PT, N_STINGER, ST_A, ST_B, ST_C, ST_ON, ST_ZL, ST_ZU
from .kernels.types import Ends, Model, Supports, load_factors
from .limits import check_mesh_size
from .mesh import graded_nodes, grading_rates
from .model import build_props, dimension_of, pin_jump
from .results import roller_gaps


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
    points: np.ndarray  # (n_points, N_PT) the rigid points: the stinger's tip (L.PT_*)
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
    # the friction path's converged steps, one dict each (:meth:`path_state`),
    # and a warm start's: its neighbour's, each step's start (:meth:`start_step`)
    current_path: list = field(default_factory=list)
    warm_path: list | None = None
    warm: bool = False  # started from a neighbour's answer (no load path: the cold start is)
    tolerance: float | None = None  # Newton's tolerance when not solver.tolerance
    # the state is a solution refined (to the tolerance, or onto a mesh graded
    # anew): the next Newton call does not hold the boundaries (run_newton
    # reads and clears it)
    in_balance: bool = False
    # the mesh follows the contact boundaries: node i at s_a[i] + sum_b
    # s_b[b, i] s_bd[b], touchdown on node bnodes[0], lift-off from (or
    # re-contact with) the stinger on bnodes[1], the material point over
    # rigid point j (the stinger's tip: j = 0) on bnodes[2 + j] (-1: none;
    # until the mesh is mapped, all -1)
    bnodes: np.ndarray | None = None
    s_a: np.ndarray | None = None
    s_b: np.ndarray | None = None
    s_bd: np.ndarray | None = None
    # the map in zones (:meth:`follow`) of a mesh that follows its grading: the
    # current's path moves the boundaries on it (``Problem.follow_rates``)
    zone_b: np.ndarray | None = None
    # and its map with the grading's own rates: a warm start from this answer
    # follows its boundaries with it (a mesh graded at its boundaries found)
    grade_b: np.ndarray | None = None
    # the load path's factors (layout F_*): the current's, full unless the
    # friction path raises it in steps, and friction, off until that path
    factors: np.ndarray = field(default_factory=lambda: load_factors(1.0, False))
    # the nodes the stinger holds laterally (3D), as the last Newton call held them
    y_held: np.ndarray | None = None

    def __post_init__(self):
        if self.y_held is None:
            self.y_held = np.zeros(self.s.size, dtype=np.bool_)
        if self.bnodes is None:
            self.bnodes = np.full(B_PT + len(self.points), -1, dtype=np.int64)
            self.s_bd = np.zeros(self.bnodes.size)

    def model(self) -> Model:
        """What the element kernels read: the case's data and the load path's factors."""
        return Model(self.props, self.table, self.factors)

    def supports(self) -> Supports:
        return Supports(self.fix_mask, self.fix_val, self.phi_r, self.phi_rp, self.bed_active,
                        self.stinger, self.st_active, self.points, self.fric, self.y_held)

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
        """The node over the quadratic stinger's tip, the first rigid point
        (-1: none; a roller stinger has no curve, and no tip of one)."""
        if self.stinger[ST_ON] == 0.0 or self.bnodes.size <= B_PT:
            return -1
        return int(self.bnodes[B_PT])

    @property
    def roller_nodes(self) -> np.ndarray:
        """The nodes over a roller stinger's rollers, one per roller (-1:
        none); empty without rollers."""
        if self.stinger[ST_ON] != 0.0:
            return self.bnodes[:0]
        return self.bnodes[B_PT:]

    @property
    def tip(self) -> np.ndarray:
        """The stinger tip's contact state, a view: [bears (0/1), normal reaction [N]]."""
        return self.points[0, L.PT_BEAR:L.PT_R + 1]

    def follow(self, nodes, zones):
        """Map the mesh onto the contact boundaries at ``nodes`` (touchdown,
        lift-off or re-contact on the stinger, then one per rigid point, the
        stinger's tip first; -1: none).

        Anchors are the boundary nodes, the ends of the pipe and, for boundary
        b, the nodes ``zones[b]`` = (below, above) [m] away from it, unless
        another boundary lies nearer; every node between two anchors keeps its
        share of the span between them, so each span's mesh is mapped onto its
        present ends with its grading, and nodes outside every zone stay put.
        """
        if len(nodes) != self.bnodes.size:
            raise ValueError(f"follow: {len(nodes)} boundary nodes for {self.bnodes.size} "
                             f"boundaries (touchdown, lift-off, {len(self.points)} points)")
        nodes = np.asarray(nodes, dtype=np.int64)
        zones = np.asarray(zones, dtype=float).reshape(-1, 2)
        nn = self.s.size
        if (nodes >= nn).any() or zones.shape[0] != nodes.size:  # (the kernel checks no bounds)
            raise ValueError(f"follow: boundary nodes {nodes.tolist()} on {nn} nodes, "
                             f"{zones.shape[0]} zones for {nodes.size} boundaries")
        s_a, s_b = np.empty(nn), np.empty((nodes.size, nn))
        boundary_map(self.s, nodes, zones, np.empty(nn, dtype=np.int64),
                     np.empty(nn, dtype=np.int64), s_a, s_b, self.s_bd)
        self.s_a, self.s_b = s_a, s_b
        self.bnodes = nodes
        self.zone_b = self.grade_b = None  # (the map is in zones now)

    def follow_rates(self, nodes, rates):
        """Map the mesh onto the boundaries at ``nodes`` (as :meth:`follow`)
        with each node's rate with each boundary: node i at s_i + sum_b
        rates[b, i] (s_b - s_b0), from the present nodes and boundaries (rows
        of zeros for nodes -1): a mesh's grading at fixed element counts
        (:func:`.mesh.grading_rates`), with which a mesh graded at boundaries
        moves as its grading does, or the zones' shares kept in ``zone_b``."""
        self.bnodes = np.asarray(nodes, dtype=np.int64)
        s_b = np.ascontiguousarray(rates, dtype=float)
        for b, k in enumerate(self.bnodes):
            if k >= 0:
                self.s_bd[b] = self.s[k]
        self.s_a = self.s - self.s_bd @ s_b
        self.s_b = s_b

    def move_boundary(self, b: int, s_new: float):
        """Boundary ``b`` to arc length ``s_new`` [m], the mesh following it
        (its map) and the state interpolated onto the moved nodes."""
        s_old = self.s.copy()
        self.s_bd[b] = s_new
        self.update_nodes()
        self.u[:] = interpolate_state(s_old, self.u, self.nd, self.s)

    def path_state(self, level: float) -> dict:
        """The converged state at ``level`` of the current's path: what a
        neighbour's warm start, or this path's next step, begins a step from
        (:meth:`start_step`)."""
        return {"level": level, "s": self.s.copy(), "u": self.u.copy(),
                "on": self.bnodes >= 0, "tb": self.tb.copy(), "s_bd": self.s_bd.copy()}

    def start_step(self, level: float) -> bool:
        """A step of the current's path to ``level``: a warm start's begins from
        its own state plus the neighbour's increment over that step (its
        answers at both ends of the step, at this mesh's material points;
        the bottom tension's and the boundaries' moves too, the state carried
        to the nodes those move: S125 3D from a + 2e-5, 14 -> 13 iterations,
        at most 2 a step instead of 3), when the neighbour converged at both
        ends with the same boundaries. The friction
        springs' anchors are this path's: the step's answer is the cold
        solve's (its slip path), only its start is nearer. That start is
        near balance, so the step does not hold the boundaries
        (``in_balance``). S67 and S125 3D at 4 m, a = -0.0021 to -0.0009,
        each from its neighbour 2e-5 away: 21 to 26 iterations a solve with
        5 to 6 a current step before, 13 to 16 with 2 to 3 now, the same
        peak stress (held: 18 to 22, 4 to 5 a step; from the neighbour's
        answer carried onto the changed stinger instead of its increment,
        31 to 44, 7 to 10 a step: carried, the conforming pipe's axial
        strain changed with the curve's length, a residual of 16 reference
        forces).

        Otherwise, past the path's first step, the step begins from this
        path's own last increment, scaled to the step (a secant predictor;
        same conditions): the paper's 3D scenes at 1 to 16 m, cold, 1784 ->
        1406 iterations, at most 5 a current step instead of 7, their answers
        within 1.1e-9 in peak stress (``bench_contact.py --quick``). Returns
        whether it did."""
        prev = self.current_path[-1]["level"] if self.current_path else 0.0
        scale = 1.0
        ends = [None, None]
        for state in self.warm_path or ():
            for k, lev in enumerate((prev, level)):
                if abs(state["level"] - lev) <= 1e-12:
                    ends[k] = state
        if ends[0] is None or ends[1] is None:
            if len(self.current_path) < 2:
                return False
            # this path's own last step, extrapolated (secant predictor)
            ends = self.current_path[-2:]
            scale = (level - prev) / (prev - ends[0]["level"])
        for end in ends:  # the same boundaries
            if not np.array_equal(end["on"], self.bnodes >= 0):
                return False
        # material points matched from the top (the pipes may differ in the
        # laid length modelled, each the length of its own cold start); the
        # boundaries move by the neighbour's moves, the state carried to the
        # nodes they move
        # (the neighbour's pipe is one length along its path: its moves are
        # the same from the top as from the lower end)
        moved = self.s_bd + scale * np.where(self.bnodes >= 0, ends[1]["s_bd"] - ends[0]["s_bd"],
                                             0.0)
        s_old, bd_old = self.s.copy(), self.s_bd.copy()
        self.s_bd[:] = moved
        self.update_nodes()
        if not (np.diff(self.s) > 0.0).all():  # a move beyond this mesh's map
            self.s_bd[:] = bd_old
            self.update_nodes()
            return False
        du = sum(sign * interpolate_state(end["s"], end["u"], self.nd,
                                          self.s - self.s[-1] + end["s"][-1])
                 for sign, end in ((1.0, ends[1]), (-1.0, ends[0])))
        self.u[:] = interpolate_state(s_old, self.u, self.nd, self.s) + scale * du
        self.tb += scale * (ends[1]["tb"] - ends[0]["tb"])
        self.in_balance = True
        return True

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


def _mesh_sizes(case: Case, lam: float):
    """h_max, h_min [m] of a case whose flexural length sqrt(EI/T) at
    touchdown is ``lam`` [m] (ungraded, h_min = h_max: a mesh remeshed to put
    a node somewhere stays uniform between its nodes, :func:`remesh`)."""
    h_max = case.solver.element_length
    if not case.solver.grading:
        h_min = h_max
    elif case.solver.min_element_length is not None:
        h_min = case.solver.min_element_length
    else:
        h_min = min(h_max, max(h_max / 8.0, 0.02 * lam))
    return h_max, min(h_min, h_max)


def _guess(case: Case):
    """The first guess of a case (:func:`.guess.first_guess`), its laid pipe
    the default of solver.laid_length unless that is given."""
    h_max = case.solver.element_length

    def laid_default(cat):
        return (2.0 * math.sqrt(case.pipe.bending_stiffness / cat.h) + 5.0 * h_max
                + friction_laid_length(case, cat))

    return first_guess(case, laid_default)


def _mesh_stats(case: Case, g) -> dict:
    """What a case's meshes are graded by, from its first guess ``g``: the
    element lengths h_max, h_min [m], the flexural length at touchdown [m],
    the boundary layer [m] (0: none) and the length of pipe modelled [m]."""
    lam = math.sqrt(case.pipe.bending_stiffness / g.cat.h)  # the flexural length at touchdown
    h_max, h_min = _mesh_sizes(case, lam)
    # a tension-dominated lay (the flexural length shorter than the heavy
    # elastica's (EI / w)^(1/3)) has boundary layers of that length at its
    # contact boundaries (:func:`.continuation.boundary_step`); 0: none
    layer = lam if lam < (case.pipe.bending_stiffness / abs(g.cat.w1)) ** (1.0 / 3.0) else 0.0
    return {"h_min": h_min, "h_max": h_max, "flexural_length": lam, "boundary_layer": layer,
            "cold_total": g.total}


def _reference_force(case: Case, g) -> float:
    """The force [N] Newton's residual is measured against, from the first guess."""
    return max(g.cat.top_tension, abs(g.cat.w1) * g.total, case.lay.top_tension or 0.0)


def build_problem(case: Case) -> Problem:
    """First guess, graded mesh and constraints of a case (a roller
    stinger's: :func:`roller_problem`)."""
    nd = dimension_of(case)
    ndn = 2 * nd + 1
    g = _guess(case)
    stats = {**_mesh_stats(case, g),
             "stinger_foci": [g.s_liftoff] if g.s_liftoff is not None else []}
    h_max, h_min, lam = stats["h_max"], stats["h_min"], stats["flexural_length"]
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
    pb = _problem(case, nd, s, u, g.cat.h, _reference_force(case, g), stats)
    follow_boundaries(case, pb, s_focus)
    # the catenary leaves below the tip: the pipe bears on it, with the gap
    # span the guess's lift-off past the tip gives (:func:`.guess.slay_liftoff`)
    if g.tip_past is not None:
        bear_on_tip(case, pb, g.tip_past)
    return pb


def roller_problem(case: Case, guide: Problem) -> Problem:
    """A roller stinger's problem from the answer ``guide`` of its guide case
    (the quadratic stinger through its rollers, :func:`.guess.guide_case`):
    the same length of pipe, a node over each roller (the guide answer's
    material point nearest it, ROLLER_PROJECTIONS projections on its
    tangent from the nearest node; ungraded there), graded at the answer's
    touchdown, the state interpolated. The rollers it passes on or below
    bear (Newton's first step lifts the pipe onto those it passes below:
    from this equilibrium, where the reactions mean something, that step
    was cheaper than moving the rollers onto their places in load steps
    from where the answer passes them: 277 against 316 iterations over 24
    cold cases with the guide then fitted through the last roller, the tip
    rollers raised up to 1 m among them; from the first guess itself,
    0.2 m below the last rollers of S67 on 12 m spacing, the contacts swung
    for 5 to 30 iterations and 1.5 m spacing diverged)."""
    nd, ndn = guide.nd, guide.ndn
    rollers = case.lay.roller_positions()
    stats = dict(guide.stats)
    # the case's own element sizes (the guide's are coarser: it is a start)
    h_max, h_min = _mesh_sizes(case, stats["flexural_length"])
    stats["h_max"], stats["h_min"] = h_max, h_min
    s_t = touchdown_position(guide)
    total = float(guide.s[-1])
    # from the nearest node, projections on the answer's tangent
    u = guide.u
    d2 = ((u[0::ndn][None, :] - rollers[:, :1]) ** 2
          + (u[nd - 1::ndn][None, :] - rollers[:, 1:]) ** 2)
    s_r = guide.s[np.argmin(d2, axis=1)]
    for _ in range(ROLLER_PROJECTIONS):
        u_r = interpolate_state(guide.s, u, nd, s_r)
        xp, zp = u_r[nd::ndn], u_r[2 * nd - 1::ndn]
        along = ((rollers[:, 0] - u_r[0::ndn]) * xp
                 + (rollers[:, 1] - u_r[nd - 1::ndn]) * zp) / np.hypot(xp, zp)
        s_r = np.clip(s_r + along, s_t, total)
    source = "the guide's answer (the quadratic stinger through the rollers)"
    s = graded_nodes(total, [s_t, total], h_max, h_min, grading=case.solver.grading,
                     check=lambda n: check_mesh_size(case, n, total, s_t, source), nodes=s_r)
    u = interpolate_state(guide.s, guide.u, nd, s)
    pb = _problem(case, nd, s, u, guide.tb[0], guide.fref, stats)
    pb.fix_val[:ndn] = guide.fix_val[:ndn]
    k_td = int(np.argmin(np.abs(s - s_t)))
    pb.bed_active[1:k_td + 1] = 1
    over = np.searchsorted(s, s_r)  # (each a node: graded_nodes keeps them)
    over -= (over > 0) & (np.abs(s[np.maximum(over - 1, 0)] - s_r) < np.abs(s[over] - s_r))
    nodes = (k_td, -1, *over.tolist())
    follow_nodes(case, pb, nodes)
    if case.solver.grading:  # graded at touchdown, the grading moving with it
        _follow_grading(pb, nodes, total, [s_t, total], s_r)
    pb.points[:, L.PT_BEAR] = (roller_gaps(pb) <= ROLLER_ON * h_min).astype(float)
    return pb


def _follow_grading(pb: Problem, nodes, total: float, foci, over):
    """After :func:`.boundaries.follow_nodes`: the mesh (graded at ``foci``
    [m] with plain nodes ``over`` [m] over the rollers, :func:`.mesh.graded_nodes`,
    ``total`` [m] long) follows its boundaries on ``nodes`` as its grading
    moves with them: each boundary's node is a focus of the grading, or a
    roller's plain node (:func:`.mesh.grading_rates` moves either; in the
    zones' shares the rollers had before, a warm start's mesh was 3.5 cm
    from the one graded at a 5 cm move of a roller, and was graded anew).
    The zones are kept for the current's path (``zone_b``)."""
    rates = np.zeros((len(nodes), pb.nn))
    moving, rows = [], []
    plain = len(foci)  # (``over`` holds the rollers that have a node, in order)
    for b, k in enumerate(nodes):
        if k < 0:
            continue
        if pb.roller_nodes.size > 0 and b >= B_PT:  # a roller's plain node
            moving.append(plain)
            plain += 1
        else:
            moving.append(int(np.argmin(np.abs(np.asarray(foci) - pb.s[k]))))
        rows.append(b)
    if plain != len(foci) + len(over):
        raise ValueError(f"_follow_grading: {plain - len(foci)} rollers with a node, "
                         f"{len(over)} plain nodes")
    if rows:
        rates[rows] = grading_rates(total, foci, moving, pb.stats["h_max"], pb.stats["h_min"],
                                    nodes=over)
    pb.zone_b, pb.grade_b = pb.s_b, rates
    pb.follow_rates(nodes, rates)


ROLLER_PROJECTIONS = 2  # the points over the rollers: 2 projections from the nearest node
ROLLER_ON = 1e-6  # a roller bears at the start within this share of h_min of the pipe


def _laid_source(case: Case, cat, lam: float) -> str:
    """What set the laid length of the first mesh (for the mesh-size check)."""
    if case.lay.pipe_length is not None:
        return f"lay.pipe_length = {case.lay.pipe_length!r} m less the suspended span"
    if case.solver.laid_length is not None:
        return f"solver.laid_length = {case.solver.laid_length!r} m"
    text = (f"the default of solver.laid_length: two flexural lengths sqrt(EI/T) = {lam:.4g} m "
            "at touchdown, five elements")
    slip = friction_laid_length(case, cat)
    if slip > 0.0:
        text += (f" and {slip:.4g} m for seabed friction to take up the lateral drag "
                 "(environment.current.speed, seabed.lateral_friction)")
    return text


def _problem(case: Case, nd, s, u, tb, fref, stats) -> Problem:
    """Constraint arrays for nodes ``s`` with state ``u``. The contact sets
    start empty: the mapping of the mesh onto the boundaries sets them
    (:func:`follow_boundaries`, :func:`remesh`), or a warm start copies them."""
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
    st = lay.curve  # (a roller stinger is its points)
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
    anchor_friction(fric, u, nd, s)
    return Problem(nd, s, props, table, u, fix_mask, fix_val, phi_r, phi_rp, bed_active,
                   stinger, st_active, _points(case, stinger), fric, np.zeros(nn * ndn),
                   slide_dof,
                   np.array([float(tb)]), top,
                   top_target, fref, stats["h_max"], stats=stats)


STATE = ("u", "tb", "bed_active", "st_active", "points", "fric", "phi_r", "phi_rp", "s",
         "s_bd")
# the mesh's map onto its boundaries (a switch of regime at the tip replaces it)
MAP = ("bnodes", "s_a", "s_b", "zone_b", "grade_b")


def _points(case: Case, stinger: np.ndarray) -> np.ndarray:
    """The rigid points of a case (rows ``L.PT_*``): the quadratic stinger's
    tip (x_L, z_L), a roller stinger's rollers (each holding the pipe
    laterally or not), none in J-lay."""
    rollers = case.lay.roller_positions()
    if rollers is not None:
        pts = np.zeros((len(rollers), L.N_PT))
        pts[:, L.PT_X] = rollers[:, 0]
        pts[:, L.PT_Z] = rollers[:, 1]
        pts[:, L.PT_HOLD] = case.lay.stinger.lateral_hold()
        return pts
    if stinger[ST_ON] == 0.0:
        return np.zeros((0, L.N_PT))
    pts = np.zeros((1, L.N_PT))
    z_l = stinger[ST_ZL]
    pts[0, L.PT_X] = (stinger[ST_A] * z_l + stinger[ST_B]) * z_l + stinger[ST_C]
    pts[0, L.PT_Z] = z_l
    return pts


def snapshot(pb: Problem):
    """The state (``STATE``, copied) and the mesh's map onto its boundaries
    (``MAP``: its arrays are replaced, never written in place, so they are
    kept as they are)."""
    return ([getattr(pb, name).copy() for name in STATE]
            + [getattr(pb, name) for name in MAP])


def restore(pb: Problem, snap):
    """Back to a :func:`snapshot`: the state and the map it had."""
    for name, arr in zip(STATE, snap[:len(STATE)], strict=True):
        getattr(pb, name)[:] = arr
    for name, value in zip(MAP, snap[len(STATE):], strict=True):
        setattr(pb, name, value)


def warm_problem(case: Case, old: Problem) -> Problem:
    """The problem of ``case`` on the mesh of a solved neighbouring case, its
    state (shape, contacts, tension) the starting point. On the friction path
    the state before the current is taken, so that the slip path is followed
    from gravity alone again; each of its steps then starts from the
    neighbour's increment over it (``warm_path``, :meth:`Problem.start_step`)."""
    nd = dimension_of(case)
    if nd != old.nd:
        raise ValueError(f"warm: a {old.nd}D solution cannot start a {nd}D case")
    if (old.stinger[ST_ON] != 0.0) != (case.lay.curve is not None):
        raise ValueError(f"warm: lay.method {case.lay.method!r} or its stinger differs from the "
                         "warm case's")
    if old.stinger[ST_ON] == 0.0 and len(old.points) != case.lay.roller_count:
        raise ValueError(f"warm: the case has {case.lay.roller_count} rollers, the warm case "
                         f"{len(old.points)}")
    # (the map with it: where the neighbour's tip switched regime along the
    # path, its map after the switch did not fit the state before the
    # current, and the warm start diverged: S67 and S125 3D at 4 m under a
    # 2 m/s current, a = -0.00114 and -0.00166)
    state = dict(zip(STATE + MAP, old.before_current or snapshot(old), strict=True))
    g = _guess(guide_case(case) if case.lay.has_rollers else case)
    new = _problem(case, nd, state["s"].copy(), state["u"].copy(), state["tb"][0],
                   _reference_force(case, g), dict(old.stats))
    new.warm = True
    # the mesh sizes and length of pipe of the cold start (its guess's): the
    # mesh is graded anew with them (the neighbour's, sized for its own lay,
    # gave another h_min, lower end and element counts: J125 warm from 1.02
    # times the top tension, 1.05e-5 from the cold peak stress; S125 3D from
    # a + 1.5e-4, 2.0e-6)
    new.stats.update(_mesh_stats(case, g))
    for name in ("bed_active", "st_active", "fric"):
        getattr(new, name)[:] = state[name]
    # the points' contact states (their positions are the new case's)
    new.points[:, L.PT_BEAR:L.PT_R + 1] = state["points"][:, L.PT_BEAR:L.PT_R + 1]
    if state["s_a"] is not None:
        new.bnodes, new.s_a, new.s_b = (state["bnodes"].copy(), state["s_a"].copy(),
                                        state["s_b"].copy())
        new.s_bd = state["s_bd"].copy()
        new.s[:] = state["s"]
        if state["grade_b"] is not None:
            # as the neighbour's grading moves (touchdown, and each rigid
            # point's node, which moves only as the pipe slides over it: in
            # the zones the nodes between rollers drifted 3.5 cm from the
            # graded mesh at a 5 cm move, and the mesh was graded anew); but
            # lift-off, which a change of the stinger moves far along it, in
            # its zone (with the grading's rates S67 2D at 1 m warm from
            # a + 1.5e-4 and 3D at 4 m from a - 3e-4 did not converge in 100
            # iterations; 5 of 44 warm S-lays at 1 and 4 m, a 1.5e-4 and
            # 3e-4 away, failed so)
            new.grade_b, new.zone_b = state["grade_b"], state["zone_b"]
            rates = new.grade_b.copy()
            rates[B_LO] = new.zone_b[B_LO]
            new.follow_rates(new.bnodes, rates)
    _onto_stinger(new, old.stinger)
    new.warm_path = old.current_path
    return new


def _onto_stinger(pb: Problem, old_stinger: np.ndarray):
    """Carry a warm state over to a changed stinger: every node over the
    stinger's z range moves in x by the change of the curve there (which
    vanishes at both ends when only ``a`` changed), its slope with it, so the
    contacts start on the new curve and the free span keeps its shape; then
    every node slides along the pipe so that the elements keep their
    lengths (:func:`_slide_to_length`). S67 and S125 2D at 2 and 4 m, warm
    from a neighbour 2e-5 away: 186 -> 175 iterations over 36 solves; 1.5e-4
    away: 331 -> 247 (the residual the warm state starts with: S67 at 2 m,
    a = -0.0021, 20 -> 0.26 reference forces)."""
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
    # below the tip, down to touchdown: a cubic shift that continues the
    # slope change at the tip and vanishes at touchdown with its slope (no
    # kink at the tip nor at touchdown: the parabola's kink there was a
    # residual of 15 reference forces on the node above touchdown)
    z_l = pb.stinger[ST_ZL]
    z_td = float(np.interp(touchdown_position(pb), pb.s, z))
    span = (z < z_l) & (z > z_td)
    if span.any() and z_l > z_td:
        k = curve(pb.stinger, np.array([z_l]))[1][0] - curve(old_stinger, np.array([z_l]))[1][0]
        t, span_z = z[span] - z_td, z_l - z_td
        shift = np.concatenate([shift, k * t * t * (t - span_z) / span_z**2])
        slope = np.concatenate([slope, k * t * (3.0 * t - 2.0 * span_z) / span_z**2])
        over = np.concatenate([np.flatnonzero(over), np.flatnonzero(span)])
    else:
        over = np.flatnonzero(over)
    r_old = pb.u[_positions(pb)]
    idx = over * ndn
    pb.u[idx] += shift
    rp = pb.u[(idx + nd)[:, None] + np.arange(nd)]
    stretch = np.linalg.norm(rp, axis=1)  # kept: the axial strain is unchanged
    rp[:, 0] += slope * zp[over]
    rp *= (stretch / np.linalg.norm(rp, axis=1))[:, None]
    pb.u[(idx + nd)[:, None] + np.arange(nd)] = rp
    if pb.slide_dof >= 0:
        _slide_to_length(pb, r_old)


def _slide_to_length(pb: Problem, r_old: np.ndarray):
    """Each node slid along the pipe so that every element keeps its chord
    length from ``r_old`` (nn, nd) [m]: the top stays, and the nodes below
    it move along their tangents by the sum of the lengthening of the
    elements above them (the lower end slides along the seabed). A shift in
    x alone stretched the conforming pipe with the curve's length."""
    pos = _positions(pb)
    r = pb.u[pos]
    longer = np.linalg.norm(np.diff(r, axis=0), axis=1) - np.linalg.norm(np.diff(r_old, axis=0),
                                                                         axis=1)
    slide = np.concatenate([np.cumsum(longer[::-1])[::-1], [0.0]])
    rp = pb.u[pos + pb.nd]
    pb.u[pos] = r + slide[:, None] * rp / np.linalg.norm(rp, axis=1)[:, None]


def _positions(pb: Problem) -> np.ndarray:
    """(nn, nd) indices of the nodes' positions r in the state u."""
    return (np.arange(pb.nn) * pb.ndn)[:, None] + np.arange(pb.nd)


def remesh(case: Case, pb: Problem, s_tdp: float, stinger_foci=(),
           laid: float | None = None, grading: bool = False,
           total: float | None = None) -> Problem:
    """A mesh with nodes at ``s_tdp`` and ``stinger_foci`` [m], graded there, the
    state interpolated onto it.

    Laid pipe is prepended when touchdown came closer to the lower end than one
    flexural length (to two of them), or to ``laid`` [m] behind touchdown when
    that is given; with ``total`` [m], laid pipe is added or cut at the lower
    end to that length of pipe (but for the flexural length kept). The mesh
    follows the boundaries in zones (:meth:`Problem.follow`,
    for boundaries that are still to be found) or, with ``grading`` (graded at
    boundaries found), as its grading moves with them
    (:meth:`Problem.follow_rates`), the zones kept for the current's path.
    """
    nd, ndn = pb.nd, pb.ndn
    lam = pb.stats["flexural_length"]
    extra = 0.0 if total is None else total - pb.s[-1]
    if case.lay.pipe_length is None and s_tdp + extra < lam:
        extra = 2.0 * lam - s_tdp
    if laid is not None:
        extra = max(extra, laid - s_tdp)
    total = pb.s[-1] + extra
    focus = s_tdp + extra
    held = [f + extra for f in stinger_foci]
    foci = [focus, total, *held]
    over = over_rollers(pb) + extra  # nodes, ungraded there
    source = (f"remeshed, {extra:.4g} m of it prepended to keep two flexural lengths "
              f"sqrt(EI/T) = {lam:.4g} m behind touchdown, which a lower tension T there "
              "lengthens")
    s = graded_nodes(total, foci, pb.stats["h_max"], pb.stats["h_min"],
                     check=lambda n: check_mesh_size(case, n, total, focus, source), nodes=over)
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
    stats = dict(pb.stats)
    new = _problem(case, nd, s, u, pb.tb[0], pb.fref, stats)
    # the lower end stays held where the case holds it (with a given pipe
    # length, at z = 0: cut or lengthened there, the pipe's state was held
    # where the neighbour's laid pipe put that material point, 2 m off,
    # and its top tension came out 59 % off; Newton moves it back)
    new.fix_val[:ndn] = pb.fix_val[:ndn]
    new.warm, new.tolerance, new.warm_path = pb.warm, pb.tolerance, pb.warm_path
    # the new mesh follows the same boundaries, each on the node graded onto it
    def at(k):
        return -1 if k < 0 else int(np.argmin(np.abs(s - (pb.s[k] + extra))))
    new.bed_active[:] = 0
    new.bed_active[1:at(pb.td_node) + 1] = 1
    if pb.lo_node >= 0:
        new.st_active[:] = 0
        new.st_active[at(pb.lo_node):-1] = 1
    nodes = [at(int(k)) for k in pb.bnodes]
    follow_nodes(case, new, nodes)
    if grading:
        _follow_grading(new, nodes, total, foci, over)
    # a bearing point keeps bearing (the node over it moves with the pipe)
    new.points[:, L.PT_BEAR:L.PT_R + 1] = pb.points[:, L.PT_BEAR:L.PT_R + 1]
    return new


# Decay lengths of the sticking zone behind the slipping one the laid pipe
# modelled holds: e^-3, the held lower end's share of the lateral force 5 %
# of what it was at the slipping zone's end. Without them S67 3D at 2 m left
# the held lower end 0.4 to 1 % of the laid pipe's lateral force (a = -0.0022
# to -0.0009; the laid pipe doubled above 1 %, from a = -0.0008), and a warm
# start from a neighbour whose laid pipe had been doubled solved another
# domain: 4.7e-6 from the cold peak stress (S67 3D 2 m, a = -0.0009 from
# -0.00088), 8.6e-8 with them; 0.02 to 0.05 % left at the lower end, 17
# elements more of 235 (4 m: 0.2 % -> 0.015 %, 8 more of 150).
STICK_DECAY_LENGTHS = 3.0


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
    return share / _sliding_force(case)


def _sliding_force(case: Case) -> float:
    """Lateral friction of the laid pipe when sliding, mu w [N/m]."""
    return case.seabed.lateral_friction * float(case.effective_weight(0.0))


def friction_laid_length(case: Case, cat) -> float:
    """Laid length [m] the friction path needs behind touchdown: the slipping
    length (:func:`slipping_length_bound`) and STICK_DECAY_LENGTHS decay
    lengths of the sticking zone behind it, where the sticking springs (mu w
    / friction_slip per m) hold the pipe as an elastic foundation and the
    force left decays over (4 EI friction_slip / mu w)^(1/4) (0 where the
    slipping length is)."""
    slip = slipping_length_bound(case, cat)
    if slip <= 0.0:
        return 0.0
    decay = (4.0 * case.pipe.bending_stiffness * case.seabed.friction_slip
             / _sliding_force(case)) ** 0.25
    return slip + STICK_DECAY_LENGTHS * decay


def friction_path(case: Case) -> bool:
    """True when seabed friction meets the current: its load path is followed.
    Lateral friction needs a lateral load: under planar loads (an in-plane
    current) the 3D pipe stays in its plane, the lateral springs carry
    nothing, and the solve is the 2D one's."""
    lateral = (dimension_of(case) == 3 and case.seabed.lateral_friction > 0.0
               and not case.is_planar)
    return (lateral or case.seabed.axial_friction > 0.0) and case.environment.current.speed > 0.0


def anchor_friction(fric, u, nd, s):
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
    """The state ``u_old`` on nodes ``s_old`` [m] at nodes ``s_new`` [m]:
    Hermite interpolation of (r, r') and linear interpolation of lambda
    (:func:`.kernels.geometry.hermite_state`; the powers of xi NumPy's, as
    the NumPy version had them, so every value is the same to the bit)."""
    idx = np.clip(np.searchsorted(s_old, s_new, side="right") - 1, 0, s_old.size - 2)
    le = s_old[idx + 1] - s_old[idx]
    xi = np.clip((s_new - s_old[idx]) / le, 0.0, 1.0)
    u = np.empty(s_new.size * (2 * nd + 1))
    hermite_state(idx, xi, xi**2, xi**3, le, np.ascontiguousarray(u_old, dtype=float), nd, u)
    return u

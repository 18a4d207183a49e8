"""The state of a solve: :class:`Problem`, what the Newton kernel reads and
writes for one mesh, in named parts: the mesh and its map onto the contact
boundaries (:class:`MeshMap`), the contacts (:class:`Contacts`), the
prescribed unknowns and the ends (:class:`EndConditions`), the settings of
the next Newton call (:class:`Settings`) and the load path's record
(:class:`Path`); with snapshots of a state and its interpolation onto other
nodes.

Units: SI; nn nodes, nd = 2 or 3 dimensions, ndn = 2 nd + 1 unknowns a node
(:mod:`pipelay_fast.kernels.layout`). The functions that build a Problem are
:mod:`.problem`'s and :mod:`.warm`'s; the boundaries' placement and the
regime at the stinger's tip are :mod:`.boundaries`'; the Newton kernel
updates the state, the contacts and the boundaries through
:func:`.continuation.run_newton`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..kernels import layout as L
from ..kernels.geometry import hermite_state
from ..kernels.grading import boundary_map
from ..kernels.layout import B_PT
from ..kernels.types import Ends, Model, Supports, load_factors
from .supports import Contacts, support_table


@dataclass
class MeshMap:
    """The mesh and its map onto the contact boundaries: node i at
    ``s_a[i] + sum_b s_b[b, i] s_bd[b]`` [m]. Written by its own methods
    (:meth:`follow`, :meth:`follow_rates`, :meth:`update_nodes`) and by the
    Newton kernel (``s_bd``, the boundaries' unknowns).

    ``s`` (nn,) [m]: node arc lengths from the lower end, unstretched;
    ``bnodes`` (nb,): the node on each boundary (touchdown, lift-off or
    re-contact on the stinger, then one per rigid point, the stinger's tip
    first; -1: none); ``s_bd`` (nb,) [m]: the boundaries' arc lengths;
    ``s_a`` (nn,) [m], ``s_b`` (nb, nn) [-]: the map (None until mapped);
    ``zone_b``, ``grade_b`` (nb, nn) [-]: its rates in zones, and with the
    mesh's grading (a warm start from this answer follows them).
    """

    s: np.ndarray
    bnodes: np.ndarray
    s_bd: np.ndarray
    s_a: np.ndarray | None = None
    s_b: np.ndarray | None = None
    zone_b: np.ndarray | None = None
    grade_b: np.ndarray | None = None

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
                             f"boundaries (touchdown, lift-off, {self.bnodes.size - B_PT} "
                             "points)")
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

    def update_nodes(self):
        """Node arc lengths from the boundary unknowns (after a solve)."""
        if self.s_a is not None:
            self.s[:] = self.s_a + self.s_bd @ self.s_b


@dataclass
class EndConditions:
    """The prescribed unknowns and the loads at the ends, fixed for a
    problem (:mod:`.problem` builds them).

    ``fix_mask`` (nn ndn,) int8: 1 where an unknown is prescribed, to
    ``fix_val`` [m, -, N]; ``f_node`` (nn ndn,) [N, N m]: nodal loads;
    ``slide_dof``: the lower end's z row the bottom tension acts on, an
    unknown when the top tension is given (-1: none); ``top_node`` and
    ``top_target`` [N]: the node whose effective tension is held, and its
    value (0: none); ``slide_angle`` [rad]: the angle above horizontal of
    the seabed the lower end slides along, the bottom tension's direction;
    ``pin_slope``, ``pin_jump`` [N]: a pinned S-lay top's slope row, held along
    the stinger's tangent, and Te's jump across the pin (:func:`.model.pin_jump`;
    -1, 0: not pinned), while the pipe conforms up to it (not clear of the stinger).
    """

    fix_mask: np.ndarray
    fix_val: np.ndarray
    f_node: np.ndarray
    slide_dof: int
    top_node: int
    top_target: float
    slide_angle: float = 0.0
    pin_slope: int = -1
    pin_jump: float = 0.0


@dataclass
class Settings:
    """How the next Newton call runs (:func:`.continuation.run_newton`).

    ``fref`` [N], ``href`` [m]: the residual's reference force and length;
    ``tolerance`` [-]: None for solver.tolerance (a loose first mesh sets
    it, :mod:`.solver`); ``in_balance``: the state is a refined solution, so
    the call does not hold the boundaries (set by :mod:`.solver` and
    :meth:`Problem.start_step`, cleared by the call); ``factors``
    (N_FACTORS,): the load path's factors on the current and friction
    (layout ``F_*``); ``top_target`` [N]: the top tension's target on the
    load path (the homotopy's, :func:`.continuation.homotopy`), None for the
    ends' (the case's).
    """

    fref: float
    href: float
    tolerance: float | None = None
    in_balance: bool = False
    factors: np.ndarray = field(default_factory=lambda: load_factors(1.0, False))
    top_target: float | None = None


@dataclass
class Path:
    """The load path's record.

    ``stats``: the mesh's sizes (``h_min``, ``h_max``, ``flexural_length``,
    ``boundary_layer`` [m]; ``cold_total`` [m], the cold start's length of
    pipe; ``stinger_foci`` [m]); ``warm``: started from a neighbour's answer;
    ``before_current``: the :func:`snapshot` before the current's path;
    ``current_path``: its converged steps (:meth:`Problem.path_state`);
    ``warm_path``: the neighbour's, which each step of a warm start begins
    from (:meth:`Problem.start_step`).
    """

    stats: dict = field(default_factory=dict)
    warm: bool = False
    before_current: list | None = None
    current_path: list = field(default_factory=list)
    warm_path: list | None = None


@dataclass
class Problem:
    """Everything a Newton solve needs: the case's data as arrays, and the
    parts above.

    ``nd``: 2 or 3; ``props`` (N_PROPS,): the scene's scalars, indexed by
    ``layout`` (SI units); ``table`` (n, 2): the current table [[x m, speed
    m/s], ...]; ``section`` (nn - 1, N_SECTION): the pipe's section, a row
    per element of this mesh (layout ``S_*``; its node count is fixed: a new
    mesh is a new problem, :func:`.model.section_array`); the unknowns ``u``
    (nn ndn,): x, (y), z [m], r' [-], lambda [N] node by node, and ``tb``
    (1,) [N]: the bottom tension.
    """

    nd: int
    props: np.ndarray
    table: np.ndarray
    section: np.ndarray
    u: np.ndarray
    tb: np.ndarray
    mesh: MeshMap
    contacts: Contacts
    ends: EndConditions
    settings: Settings
    path: Path = field(default_factory=Path)
    bed: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))

    def model(self) -> Model:
        """What the element kernels read: the case's data and the load path's factors."""
        return Model(self.props, self.table, self.settings.factors, self.section, self.bed)

    def kernel_supports(self) -> Supports:
        """The kernel's constraints and contacts (shared; clear of the stinger a pin is free)."""
        c, e = self.contacts, self.ends
        fix_mask = (np.where(np.arange(e.fix_mask.size) == e.pin_slope, 0, e.fix_mask)
                    if e.pin_slope >= 0 and self.clear_of_stinger else e.fix_mask)
        return Supports(fix_mask, e.fix_val, c.phi_r, c.phi_rp, c.kind, c.geom, c.active,
                        c.fric, c.y_held)

    @property
    def clear_of_stinger(self) -> bool:
        """The quadratic stinger holds the pipe at its upper end, the top (and
        its tip) alone: no lift-off (:func:`.boundaries.conform_from`)."""
        return self.has_curve and self.lo_node < 0 and not self.contacts.st_active.any()

    @property
    def curve_support(self) -> tuple:
        """(kind, parameters) of the stinger curve's row of the supports' table."""
        return int(self.contacts.kind[L.ROW_CURVE]), self.contacts.geom[L.ROW_CURVE]

    @property
    def has_curve(self) -> bool:
        """Whether the stinger is a curve (S-lay with a quadratic stinger)."""
        return bool(self.contacts.kind[L.ROW_CURVE] == L.SUP_CURVE)

    def kernel_ends(self, g_off) -> Ends:
        """The Newton kernel's ends, with the residual's offset ``g_off`` (nn ndn,) [N]
        and the load path's top-tension target (:class:`Settings`)."""
        e = self.ends
        target = e.top_target if self.settings.top_target is None else self.settings.top_target
        target += e.pin_jump if target > 0.0 and self.clear_of_stinger else 0.0  # no jump
        return Ends(e.f_node, g_off, self.tb, e.slide_dof, e.top_node, float(target),
                    float(e.slide_angle))

    def on_gravity_path(self):
        """No current and no friction: the friction path's first stage."""
        self.settings.factors[:] = load_factors(0.0, False)

    @property
    def s(self) -> np.ndarray:
        """Node arc lengths [m] (the mesh's)."""
        return self.mesh.s

    @property
    def bnodes(self) -> np.ndarray:
        """The boundaries' nodes (the mesh's map, :class:`MeshMap`)."""
        return self.mesh.bnodes

    @property
    def stats(self) -> dict:
        """The mesh's sizes and the path's record (:class:`Path`)."""
        return self.path.stats

    @property
    def td_node(self) -> int:
        return int(self.mesh.bnodes[0])

    @property
    def lo_node(self) -> int:
        return int(self.mesh.bnodes[1])

    @property
    def tip_node(self) -> int:
        """The node over the quadratic stinger's tip, the first rigid point
        (-1: none; a roller stinger has no curve, and no tip of one)."""
        if not self.has_curve or self.mesh.bnodes.size <= B_PT:
            return -1
        return int(self.mesh.bnodes[B_PT])

    @property
    def roller_nodes(self) -> np.ndarray:
        """The nodes over a roller stinger's rollers, one per roller (-1:
        none); empty without rollers."""
        if self.has_curve:
            return self.mesh.bnodes[:0]
        return self.mesh.bnodes[B_PT:]

    @property
    def tip(self) -> np.ndarray:
        """The stinger tip's contact state, a view: [bears (0/1), normal reaction [N]]."""
        return self.contacts.points[0, L.PT_BEAR:L.PT_R + 1]

    def move_boundary(self, b: int, s_new: float):
        """Boundary ``b`` to arc length ``s_new`` [m], the mesh following it
        (its map) and the state interpolated onto the moved nodes."""
        m = self.mesh
        s_old = m.s.copy()
        m.s_bd[b] = s_new
        m.update_nodes()
        self.u[:] = interpolate_state(s_old, self.u, self.nd, m.s)

    def path_state(self, level: float) -> dict:
        """The converged state at ``level`` of the current's path: what a
        neighbour's warm start, or this path's next step, begins a step from
        (:meth:`start_step`)."""
        m = self.mesh
        return {"level": level, "s": m.s.copy(), "u": self.u.copy(),
                "on": m.bnodes >= 0, "tb": self.tb.copy(), "s_bd": m.s_bd.copy()}

    def start_step(self, level: float) -> bool:
        """Move the state to a predicted start of the current's path step to
        ``level`` [-], and return whether it did (then ``in_balance``: the
        step does not hold the boundaries).

        The prediction is the neighbour's increment over the step (a warm
        start's ``warm_path``, its states at both ends of the step at this
        mesh's material points, matched from the top), else, past the
        path's first step, this path's own last increment scaled to the step
        (a secant predictor). Each moves the state, the bottom tension and
        the boundaries (the mesh carried with them). No prediction when the
        ends' contact boundaries differ from the present ones, or when the
        moved boundaries would fold the mesh. The friction springs' anchors
        stay this path's: only the step's start is nearer, its answer is the
        cold solve's."""
        prev = self.path.current_path[-1]["level"] if self.path.current_path else 0.0
        scale = 1.0
        ends = [None, None]
        for state in self.path.warm_path or ():
            for k, lev in enumerate((prev, level)):
                if state["level"] == lev:  # both sums of the same binary fractions
                    ends[k] = state
        if ends[0] is None or ends[1] is None:
            if len(self.path.current_path) < 2:
                return False
            # this path's own last step, extrapolated (secant predictor)
            ends = self.path.current_path[-2:]
            scale = (level - prev) / (prev - ends[0]["level"])
        for end in ends:  # the same boundaries
            if not np.array_equal(end["on"], self.mesh.bnodes >= 0):
                return False
        # material points matched from the top (the pipes may differ in the
        # laid length modelled, each the length of its own cold start); the
        # boundaries move by the neighbour's moves, the state carried to the
        # nodes they move
        # (the neighbour's pipe is one length along its path: its moves are
        # the same from the top as from the lower end)
        moved = self.mesh.s_bd + scale * np.where(self.mesh.bnodes >= 0,
                                                  ends[1]["s_bd"] - ends[0]["s_bd"], 0.0)
        s_old, bd_old = self.mesh.s.copy(), self.mesh.s_bd.copy()
        self.mesh.s_bd[:] = moved
        self.mesh.update_nodes()
        if not (np.diff(self.mesh.s) > 0.0).all():  # a move beyond this mesh's map
            self.mesh.s_bd[:] = bd_old
            self.mesh.update_nodes()
            return False
        du = sum(sign * interpolate_state(end["s"], end["u"], self.nd,
                                          self.mesh.s - self.mesh.s[-1] + end["s"][-1])
                 for sign, end in ((1.0, ends[1]), (-1.0, ends[0])))
        self.u[:] = interpolate_state(s_old, self.u, self.nd, self.mesh.s) + scale * du
        self.tb += scale * (ends[1]["tb"] - ends[0]["tb"])
        self.settings.in_balance = True
        return True

    @property
    def ndn(self) -> int:
        return 2 * self.nd + 1

    @property
    def nn(self) -> int:
        return self.mesh.s.size

    @property
    def s_el(self) -> np.ndarray:
        """Element lengths [m], unstretched."""
        return np.diff(self.mesh.s)


@dataclass(frozen=True)
class Solution:
    """A solved problem as the output layer reads it: the engine's answer,
    nothing of its working state (:func:`pipelay_fast.engine.solver.solve_problem`).

    ``nd``; ``s`` (nn,) [m]: node arc lengths; ``u`` (nn ndn,): the nodal
    unknowns (:class:`Problem`); ``bottom_tension`` [N]: the lower end's
    applied tension (None when the lower end is held: then the profile's);
    ``react`` (nn ndn,) [N, N m]: the constraints' reactions, in the nodal
    frames ``phi_r`` (nn,) [rad]; ``bed_active``, ``st_active`` (nn,) int8,
    ``fric`` (nn, N_FRIC), ``points`` (n_points, N_PT), ``y_held`` (nn,)
    bool: the contacts (:class:`Contacts`); ``torque`` [N m]: the top's;
    ``lo_node``: lift-off's node (-1: none); ``tip``: (the node over the
    stinger's tip, its normal reaction [N]) while the pipe bears on the tip,
    else None; ``roller_nodes`` (n_rollers,): the nodes over the rollers;
    ``roller_gaps`` (n_rollers,) [m]: the pipe's clearance over each;
    ``last_roller``: the last roller it bears on (-1: none; None without
    rollers); ``s_tdp``, ``s_liftoff`` [m]: touchdown and lift-off (None:
    the top); ``stats``: the solve's counts and time; ``top_jump`` [N]: Te's
    jump across the top (:class:`EndConditions`).
    """

    nd: int
    s: np.ndarray
    u: np.ndarray
    bottom_tension: float | None
    react: np.ndarray
    phi_r: np.ndarray
    bed_active: np.ndarray
    st_active: np.ndarray
    fric: np.ndarray
    points: np.ndarray
    y_held: np.ndarray
    torque: float
    lo_node: int
    tip: tuple | None
    roller_nodes: np.ndarray
    roller_gaps: np.ndarray
    last_roller: int | None
    s_tdp: float
    s_liftoff: float | None
    stats: dict
    top_jump: float = 0.0

    @property
    def ndn(self) -> int:
        return 2 * self.nd + 1


def make_problem(*, nd: int, s, props, table, section, u, ends: EndConditions, fref: float,
                 href: float, points=None, curve=None, tb: float = 0.0, bed_active=None,
                 st_active=None, fric=None, phi_r=None, phi_rp=None, stats: dict | None = None,
                 factors=None, seabed=(0.0, 0.0, 0.0), bed=None) -> Problem:
    """A :class:`Problem` on nodes ``s`` [m] with unknowns ``u`` and the
    elements' ``section`` (nn - 1, N_SECTION), its mesh not yet mapped onto
    boundaries (every boundary node -1); the parts' arrays not given are
    empty: no rigid points (``points``, rows ``PT_*``), no stinger's
    ``curve`` (a, b, c, zL, zU, turn: layout ``ST_*``), no contacts, no
    nodal frames, the friction springs unanchored, the load factors full
    current without friction, the seabed flat at x = 0 (``seabed``: level,
    angle, z0) with no profile (``bed``: the profile's knots,
    :func:`..input.profile.bed_knots`). The supports' table is
    :func:`.supports.support_table`'s."""
    nn = s.size
    kind, geom, active = support_table(nn, curve, points, seabed)
    nb = kind.size
    if bed_active is not None:
        active[L.ROW_BED] = bed_active
    if st_active is not None:
        active[L.ROW_CURVE] = st_active

    def zeros(value, dtype=float):
        return np.zeros(nn, dtype=dtype) if value is None else value

    contacts = Contacts(kind, geom, active, np.zeros((nn, L.N_FRIC)) if fric is None else fric,
                        zeros(phi_r), zeros(phi_rp), np.zeros(nn, dtype=np.bool_))
    settings = Settings(fref, href)
    if factors is not None:
        settings.factors = factors
    if section.shape != (nn - 1, L.N_SECTION):
        raise ValueError(f"section {section.shape}: one row of {L.N_SECTION} per element of "
                         f"{nn - 1} expected")
    section = np.ascontiguousarray(section, dtype=np.float64)  # one type: one compile
    return Problem(nd, props, table, section, u, np.array([float(tb)]),
                   MeshMap(s, np.full(nb, -1, dtype=np.int64), np.zeros(nb)),
                   contacts, ends, settings, Path({} if stats is None else stats),
                   np.zeros((0, 3)) if bed is None else np.ascontiguousarray(bed, dtype=float))


# what a snapshot copies: the unknowns, the contacts' arrays, the mesh's nodes and
# boundaries; and the map, whose arrays a switch of regime replaces, never writes, as is
STATE = ("u", "tb", "bed_active", "st_active", "points", "fric", "phi_r", "phi_rp", "s",
         "s_bd")
MAP = ("bnodes", "s_a", "s_b", "zone_b", "grade_b")
_STATE_PARTS = ("problem", "problem", "contacts", "contacts", "contacts", "contacts",
                "contacts", "contacts", "mesh", "mesh")


def _owner(pb: Problem, part: str):
    return pb if part == "problem" else getattr(pb, part)


def snapshot(pb: Problem):
    """The state (``STATE``, copied) and the mesh's map onto its boundaries
    (``MAP``, as it is)."""
    return ([getattr(_owner(pb, p), n).copy() for p, n in zip(_STATE_PARTS, STATE, strict=True)]
            + [getattr(pb.mesh, name) for name in MAP])


def restore(pb: Problem, snap):
    """Back to a :func:`snapshot`: the state and the map it had."""
    for part, name, arr in zip(_STATE_PARTS, STATE, snap[:len(STATE)], strict=True):
        getattr(_owner(pb, part), name)[:] = arr
    for name, value in zip(MAP, snap[len(STATE):], strict=True):
        setattr(pb.mesh, name, value)


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

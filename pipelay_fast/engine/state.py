"""The state of a solve: :class:`Problem`, what the Newton kernel reads and
writes for one mesh (the case's data as arrays, the mesh and its map onto
the contact boundaries, the supports, the ends, the unknowns), and the
interpolation of a state onto other nodes.

The functions that build a Problem are :mod:`.problem`'s; the boundaries'
placement is :mod:`.boundaries`'.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..kernels import layout as L
from ..kernels.contact import ST_ON
from ..kernels.geometry import hermite_state
from ..kernels.grading import boundary_map
from ..kernels.newton import B_PT
from ..kernels.types import Ends, Model, Supports, load_factors


@dataclass
class Problem:
    """Everything a Newton solve needs, as arrays: one mesh, one set of
    constraints, the unknowns. nn nodes, nd = 2 or 3, ndn = 2 nd + 1
    unknowns a node (:mod:`pipelay_fast.kernels.layout`).

    Built by :mod:`.problem` (cold start, remesh, roller stinger) or
    :mod:`.warm` (from a neighbour); the Newton kernel updates the state
    (``u``, ``tb``, the contact sets, ``y_held``, the boundaries ``s_bd``)
    through :func:`.continuation.run_newton`.

    The case's data
        ``nd``; ``props`` (N_PROPS,): the case's scalars, indexed by
        ``layout`` (SI units); ``table`` (n, 2): the current table
        [[x m, speed m/s], ...]; ``factors`` (N_FACTORS,): the load path's
        factors on the current and friction (layout ``F_*``, set by
        :mod:`.solver` and :mod:`.continuation`).
    The mesh and its map onto the contact boundaries (:meth:`follow`,
    :meth:`follow_rates`, :meth:`update_nodes`)
        ``s`` (nn,) [m]: node arc lengths from the lower end, unstretched;
        node i at ``s_a[i] + sum_b s_b[b, i] s_bd[b]`` [m]; ``bnodes`` (nb,)
        the node on each boundary (touchdown, lift-off or re-contact on the
        stinger, then one per rigid point, the stinger's tip first; -1:
        none); ``s_bd`` (nb,) [m] the boundaries' arc lengths; ``zone_b``,
        ``grade_b`` (nb, nn) [-]: the map's rates in zones, and with the
        grading's own rates (a warm start from this answer follows them).
    The constraints (:data:`pipelay_fast.kernels.types.Supports`)
        ``fix_mask`` (nn ndn,) int8, 1 where an unknown is prescribed, to
        ``fix_val`` [m, -, N]; ``phi_r``, ``phi_rp`` (nn,) [rad]: the nodal
        frames' rotations of r and r' (the stinger's tangent at a node on
        it); ``bed_active``, ``st_active`` (nn,) int8: the seabed and
        stinger contact sets; ``stinger`` (N_STINGER,): the quadratic
        stinger's coefficients and ends (contact ``ST_*``; ``ST_ON`` 0
        without one); ``points`` (n_points, N_PT): the rigid points (the
        tip, rollers; layout ``PT_*``); ``fric`` (nn, N_FRIC): the friction
        springs (layout ``FR_*``); ``y_held`` (nn,) bool: the nodes the
        stinger held laterally in the last Newton call.
    The ends (:data:`pipelay_fast.kernels.types.Ends`)
        ``f_node`` (nn ndn,) [N, N m]: nodal loads; ``tb`` (1,) [N]: the
        bottom tension, an unknown when ``slide_dof`` >= 0 (the lower end's
        z row it acts on; -1: none) and the top tension is given;
        ``top_node`` and ``top_target`` [N]: the node whose effective
        tension is held, and its value (0: none).
    The state: ``u`` (nn ndn,): the nodal unknowns x, (y), z [m], r'
        [-], lambda [N] node by node; ``tb``.
    Settings of the next Newton call (:func:`.continuation.run_newton`)
        ``fref`` [N], ``href`` [m]: the residual's reference force and
        length; ``tolerance`` [-]: None for solver.tolerance (set by
        :mod:`.solver` for a loose first mesh); ``in_balance``: the state
        is a refined solution, the call does not hold the boundaries
        (set by :mod:`.solver` and :meth:`start_step`, cleared by the call).
    The path
        ``stats``: the mesh's sizes (``h_min``, ``h_max``,
        ``flexural_length``, ``boundary_layer`` [m]; ``cold_total`` [m], the
        cold start's length of pipe; ``stinger_foci``); ``warm``: started
        from a neighbour's answer; ``before_current``: the snapshot
        (:func:`snapshot`) before the current's path; ``current_path``: its
        converged steps (:meth:`path_state`); ``warm_path``: the
        neighbour's, which each step of a warm start begins from
        (:meth:`start_step`).
    """

    nd: int
    s: np.ndarray
    props: np.ndarray
    table: np.ndarray
    u: np.ndarray
    fix_mask: np.ndarray
    fix_val: np.ndarray
    phi_r: np.ndarray
    phi_rp: np.ndarray
    bed_active: np.ndarray
    stinger: np.ndarray
    st_active: np.ndarray
    points: np.ndarray
    fric: np.ndarray
    f_node: np.ndarray
    slide_dof: int
    tb: np.ndarray
    top_node: int
    top_target: float
    fref: float
    href: float
    stats: dict = field(default_factory=dict)
    before_current: list | None = None
    current_path: list = field(default_factory=list)
    warm_path: list | None = None
    warm: bool = False
    tolerance: float | None = None
    in_balance: bool = False
    bnodes: np.ndarray | None = None
    s_a: np.ndarray | None = None
    s_b: np.ndarray | None = None
    s_bd: np.ndarray | None = None
    zone_b: np.ndarray | None = None
    grade_b: np.ndarray | None = None
    factors: np.ndarray = field(default_factory=lambda: load_factors(1.0, False))
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


STATE = ("u", "tb", "bed_active", "st_active", "points", "fric", "phi_r", "phi_rp", "s",
         "s_bd")
# the mesh's map onto its boundaries (a switch of regime at the tip replaces it)
MAP = ("bnodes", "s_a", "s_b", "zone_b", "grade_b")


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

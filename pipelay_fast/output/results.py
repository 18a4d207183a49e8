"""Post-processing: the per-node profile, the summary row and touchdown location.

Column names and units are a contract (the README's Outputs): ``SUMMARY_UNITS``
and ``PROFILE_UNITS`` map every column to its unit, which is written into the
Parquet schema metadata.
"""

from __future__ import annotations

import hashlib
import json
import math
import weakref

import numpy as np
import pandas as pd

from ..engine.state import Solution
from ..input.case import Case
from ..input.frame import vessel_note
from ..input.surface import heights
from ..kernels import layout as L
from ..kernels.geometry import centreline_fields
from .design import DESIGN_UNITS, bend_regions, design_columns, interior_peak
from .spans import SPAN_UNITS, TOUCHDOWN_UNITS, span_table, touchdown_columns

PROFILE_UNITS = {
    "s": "m", "x": "m", "y": "m", "z": "m", "angle_deg": "deg",
    "effective_tension": "N", "wall_tension": "N",
    "moment_x": "N m", "moment_y": "N m", "moment_z": "N m", "moment": "N m",
    "curvature": "1/m", "torque": "N m", "axial_strain": "-", "von_mises": "Pa",
    "seabed_reaction": "N", "seabed_reaction_y": "N", "stinger_reaction": "N",
    "reaction_x": "N", "reaction_y": "N", "reaction_z": "N", "slipping": "", "contact": "",
}

ROLLER_UNITS = {
    "roller": "", "x": "m", "z": "m", "s": "m", "reaction": "N", "lateral_reaction": "N",
    "clearance": "m", "in_contact": "",
}

SUMMARY_UNITS = {
    "case_id": "", "method": "", "dimension": "", "a": "1/m", "stinger_radius": "m",
    "roller_shift": "m", "water_depth": "m", "trim_deg": "deg",
    "current_speed": "m/s", "current_heading_deg": "deg", "status": "", "message": "",
    "top_tension": "N", "bottom_tension": "N", "tdp_z": "m", **TOUCHDOWN_UNITS, "liftoff_z": "m",
    "liftoff_angle_deg": "deg", "top_angle_deg": "deg", "suspended_length": "m",
    "max_von_mises": "Pa", "max_von_mises_over_smys": "-", "yielded": "",
    "overbend_max_von_mises": "Pa", "sagbend_max_von_mises": "Pa",
    "overbend_max_moment": "N m", "sagbend_max_moment": "N m", "max_strain": "-",
    "max_lateral_deflection": "m", "tip_reaction": "N", "bears_on_tip": "",
    "liftoff_reaction": "N",
    "max_roller_reaction": "N", "last_roller_in_contact": "",
    **DESIGN_UNITS,
    "n_elements": "", "n_iterations": "", "n_current_steps": "",
    "max_current_step_iterations": "", "n_meshes": "", "solve_seconds": "s",
}


def case_id(case: Case) -> str:
    """Stable 16-hex-digit id of a case's inputs (the name is not an input):
    :func:`tables_id` of ``case.to_dict()``, remembered while the case
    lives (a sweep names its cases from their tables and tells it,
    :func:`remember_case_id`: their summaries then cost no second id)."""
    cid = _known_ids.get(case)
    if cid is None:
        cid = tables_id(case.to_dict())
        remember_case_id(case, cid)
    return cid


_known_ids: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def remember_case_id(case: Case, cid: str):
    """Record ``cid`` as the :func:`case_id` of ``case``, for as long as
    ``case`` lives."""
    _known_ids[case] = cid


def tables_id(tables: dict) -> str:
    """:func:`case_id` of the case whose ``to_dict()`` is ``tables``."""
    text = json.dumps({k: v for k, v in tables.items() if k != "name"}, sort_keys=True,
                      separators=(",", ":"), default=float)
    return hashlib.sha1(text.encode()).hexdigest()[:16]


class Result:
    """The answer to one case.

    Attributes
    ----------
    case : Case
    summary : dict
        One row, the columns of ``SUMMARY_UNITS`` (with their units).
    profile : pandas.DataFrame
        One row per node (units in ``PROFILE_UNITS``); built on first access
        from ``columns``, the same data as numpy arrays.
    spans : pandas.DataFrame
        The free spans behind touchdown on an elastic seabed, one row each
        from the lower end (units in ``SPAN_UNITS``, :mod:`.spans`); empty
        without spans (always on the rigid seabed).
    rollers : pandas.DataFrame or None
        A roller stinger's rollers, one row each from the vessel down (units
        in ``ROLLER_UNITS``): position, the arc length of the material point
        over it, its normal and lateral reactions, the pipe's clearance
        above it and whether the pipe bears on it; None without rollers.
        Built on first access from ``roller_columns``.
    state : object
        The solved problem (mesh, unknowns, constraints) for warm starts.
    target : dict or None
        Of a target solve (:func:`pipelay_fast.solve_for`): the column, its
        goal, the varied key, its value and the number of solves.
    functional : dict or None
        The profile columns of the case's functional load case (the case
        without its current) when its code check splits the current off
        (:meth:`pipelay_fast.input.checks.Checks.splits_current`), else None.
    sensitivities : pandas.DataFrame or None
        The derivatives of the summary's numeric columns by the keys that
        ``pipelay_fast.solve(case, sensitivities=[...])`` named
        (:func:`pipelay_fast.output.sensitivity.sensitivity_table`); None
        when none were asked for.
    """

    def __init__(self, case: Case, summary: dict, columns: dict, state=None,
                 roller_columns: dict | None = None, functional: dict | None = None,
                 span_columns: dict | None = None):
        self.case = case
        self.span_columns = span_columns
        self.functional = functional
        self.summary = summary
        self.columns = columns
        self.roller_columns = roller_columns
        self.state = state
        self.target = None
        self.sensitivities = None
        self._profile = None
        self._rollers = None

    @property
    def profile(self) -> pd.DataFrame:
        """One row per node, the columns of ``PROFILE_UNITS`` (SI)."""
        if self._profile is None:
            self._profile = pd.DataFrame(self.columns)
        return self._profile

    @property
    def spans(self) -> pd.DataFrame:
        """One row per free span behind touchdown, the columns of
        ``SPAN_UNITS`` (SI); empty without spans."""
        return pd.DataFrame(self.span_columns or {k: [] for k in SPAN_UNITS})

    @property
    def rollers(self) -> pd.DataFrame | None:
        """One row per roller, the columns of ``ROLLER_UNITS`` (SI); None
        without a roller stinger."""
        if self._rollers is None and self.roller_columns is not None:
            self._rollers = pd.DataFrame(self.roller_columns)
        return self._rollers

    def plot(self, path=None):
        """The lay's figure (:func:`pipelay_fast.output.plot.plot_result`):
        elevation, lateral offset in 3D, signed in-plane moment, von Mises
        with SMYS and the utilisations, all against s with touchdown,
        lift-off and the tip marked; written to ``path`` (PNG, or SVG/PDF by
        the suffix) when given. Returns the matplotlib Figure."""
        from .plot import plot_result

        return plot_result(self, path)

    def __repr__(self):
        sm = self.summary
        return (f"Result({self.case.name!r}, {sm['dimension']}, tdp_z={sm['tdp_z']:.3f} m, "
                f"max_von_mises={sm['max_von_mises'] / 1e6:.2f} MPa, {sm['n_elements']} elements)")


def nodal_fields(nd, s, u, clamped=None):
    """(r [m], r' [-], each (nn, nd); the curvature vector (r' x r'')/|r'|^3
    [1/m] and the unit tangent [-], each (nn, 3) in (x, y, z), the plane's
    y = 0 embedded in 2D) at the nodes ``s`` [m] of the unknowns ``u`` in
    dimension ``nd``. r'' at a node is averaged over the elements beside it,
    but the lateral y'' at a node of ``clamped`` (bool per node) is the free
    side's (:func:`pipelay_fast.kernels.geometry.centreline_fields`)."""
    nn = s.size
    r, rp, rpp = np.empty((nn, nd)), np.empty((nn, nd)), np.empty((nn, nd))
    kvec, t3 = np.empty((nn, 3)), np.empty((nn, 3))
    held = np.zeros(nn, dtype=bool) if clamped is None else np.asarray(clamped, dtype=bool)
    centreline_fields(nd, s, np.ascontiguousarray(u, dtype=float), held, r, rp, rpp, kvec, t3)
    return r, rp, kvec, t3


def liftoff_reaction(s, reaction, k) -> float:
    """Concentrated reaction [N] where the pipe leaves the stinger's curve (or,
    bearing on the tip, regains it) at node ``k``: the node's stinger
    reaction less the distributed support's share of the element above it,
    int N_k p ds = h (2 p_k + p_k+1) / 6, with the support per length p taken
    from the two nodes above (their reactions over their shares of the pipe),
    extrapolated linearly to node k. NaN without lift-off's node, or with
    fewer than two stinger nodes above it."""
    if k < 0 or k + 3 > s.size - 1:
        return math.nan
    share = node_shares(s)
    p1, p2 = reaction[k + 1] / share[k + 1], reaction[k + 2] / share[k + 2]
    h = s[k + 1] - s[k]
    p0 = p1 + (p1 - p2) * h / (s[k + 2] - s[k + 1])
    return float(reaction[k] - h * (2.0 * p0 + p1) / 6.0)


def node_shares(s) -> np.ndarray:
    """Each node's share of the pipe [m]: half of each element beside it."""
    share = np.zeros(s.size)
    share[:-1] += 0.5 * np.diff(s)
    share[1:] += 0.5 * np.diff(s)
    return share


def foundation_force(s, x, k_bed) -> np.ndarray:
    """Nodal force [N] of an elastic seabed: k (-x) at a node below the
    seabed over its share of the pipe (the NumPy reference of the normal
    force W that :func:`pipelay_fast.kernels.contact.friction_track` gives
    friction). ``s`` [m] per node, ``x`` [m] the node's clearance above the
    seabed, ``k_bed`` [N/m per m of pipe]."""
    return k_bed * np.maximum(-x, 0.0) * node_shares(s)


def constraint_forces(nd, phi_r, react):
    """Force of every constraint on each node in (x, y, z) [N], shape (nn, 3)
    (nodal frames undone; y = 0 in 2D), from the reactions ``react`` in the
    nodal frames ``phi_r`` (nn,) [rad], in dimension ``nd``.

    Zero on free unknowns; at the top it is the load the vessel carries. Applied
    loads (the bottom tension of a sliding lower end) are not reactions.
    """
    ndn = 2 * nd + 1
    f = np.stack([react[i::ndn] for i in range(nd)], axis=1)
    c, sn = np.cos(phi_r), np.sin(phi_r)
    a, b = f[:, 0].copy(), f[:, nd - 1].copy()
    # the nodal frame is (x, z) -> (c x - s z, s x + c z); invert it
    f[:, 0] = c * a + sn * b
    f[:, nd - 1] = -sn * a + c * b
    if nd == 2:
        f = np.stack([f[:, 0], np.zeros(len(f)), f[:, 1]], axis=1)
    return f


def stinger_columns(lay) -> dict:
    """The summary's stinger inputs of a lay: ``a`` of a quadratic stinger, a
    roller stinger's ``stinger_radius`` (rollers placed on a radius) and
    ``roller_shift``; NaN where the stinger has none."""
    st = lay.stinger
    radius = getattr(st, "radius", None)
    return {"a": getattr(st, "a", math.nan),
            "stinger_radius": math.nan if radius is None else float(radius),
            "roller_shift": float(getattr(st, "height_shift", math.nan))}


def build_rollers(case: Case, sol: Solution) -> dict | None:
    """The columns of ``ROLLER_UNITS`` (one value per roller, from the vessel
    down) of a solution with a roller stinger; None without one. The
    clearance is the pipe's axis above the roller along the pipe's normal
    at the node over it (0 to round-off where it bears), the reactions the
    multipliers of its contact (normal) and of its lateral hold (a V roller
    bearing, 3D)."""
    if not case.lay.has_rollers:
        return None
    nodes = sol.roller_nodes
    if (nodes < 0).any():  # (every roller has its node once the mesh follows them)
        raise RuntimeError(f"rollers {np.flatnonzero(nodes < 0).tolist()} have no node")
    nd, react = sol.nd, sol.react
    base = nodes * sol.ndn
    pts = sol.points
    clearance = sol.roller_gaps
    bearing = pts[:, L.PT_BEAR] != 0.0
    lateral = np.zeros(nodes.size)
    if nd == 3:
        held = bearing & (pts[:, L.PT_HOLD] != 0.0)
        lateral[held] = react[base[held] + 1]
    return {
        "roller": np.arange(nodes.size), "x": pts[:, L.PT_X].copy(),
        "z": pts[:, L.PT_Z].copy(), "s": sol.s[nodes].copy(),
        "reaction": np.where(bearing, pts[:, L.PT_R], 0.0), "lateral_reaction": lateral,
        "clearance": np.where(bearing, 0.0, clearance), "in_contact": bearing,
    }


def build_profile(case: Case, sol: Solution) -> dict:
    """The columns of ``PROFILE_UNITS`` (numpy arrays, one value per node, SI)
    of the solution ``sol``."""
    nd, ndn, s, u, react = sol.nd, sol.ndn, sol.s, sol.u, sol.react
    pipe = case.pipe
    ei = pipe.bending_stiffness
    r, rp, kvec, t3 = nodal_fields(nd, s, u, sol.y_held)
    jump = sol.top_jump
    if jump:  # a pinned S-lay top: the pin's own values, past the moment's fall
        kvec[-1] = 0.0
    torque = sol.torque
    mom = ei * kvec + torque * t3
    curvature = np.linalg.norm(kvec, axis=1)
    x = r[:, 0]
    y = r[:, 1] if nd == 3 else np.zeros(s.size)
    z = r[:, nd - 1]
    horiz = np.hypot(t3[:, 1], t3[:, 2])
    angle = np.degrees(np.arctan2(t3[:, 0], horiz))
    lam = u[2 * nd::ndn]
    te = lam + ei * curvature**2
    # at the held top the reaction is the internal force: Te = R . t there is
    # exact, while lam + EI kappa^2 carries the O(h) error of the lam field at
    # an end
    top = (s.size - 1) * ndn
    te[-1] = float(react[top:top + nd] @ (rp[-1] / np.linalg.norm(rp[-1]))) + jump
    tw = np.asarray(case.wall_tension(te, x), dtype=float)
    strain = tw / pipe.axial_stiffness
    pe = np.asarray(case.external_pressure(x))
    pi_ = np.asarray(case.internal_pressure(x))
    sig_h = (pi_ * pipe.inner_diameter - pe * pipe.outer_diameter) / (2.0 * pipe.wall_thickness)
    m_abs = ei * curvature
    bend = m_abs * pipe.outer_diameter / (2.0 * pipe.second_moment)
    tau = torque * pipe.outer_diameter / (2.0 * pipe.polar_moment)
    vm = np.zeros(s.size)
    for sign in (1.0, -1.0):
        sa = tw / pipe.steel_area + sign * bend
        vm = np.maximum(vm, np.sqrt(sa * sa + sig_h * sig_h - sa * sig_h + 3.0 * tau * tau))
    contact = np.full(s.size, "free", dtype="<U7")  # (the longest: "stinger")
    fric = sol.fric
    if case.seabed.is_rigid:
        act = sol.bed_active.astype(bool)  # the contacts, the held lower end apart
        seabed = np.where(act, react[0::ndn], 0.0)
        seabed[0] = react[0]
        contact[0] = "seabed"
    else:  # the foundation's force, lumped at the nodes below the seabed
        gap = u[0::ndn] - heights(case.seabed, case.environment.water_depth, u[nd - 1::ndn])
        act = gap < 0.0
        # (on a sloped plane its normal force, the normal penetration's)
        seabed = foundation_force(s, gap, case.seabed.stiffness) * np.cos(case.seabed.slope)
    contact[act] = "seabed"
    seabed_y = np.zeros(s.size)
    if nd == 3:  # friction (the held lower end's lateral reaction is not)
        seabed_y[act] = react[1::ndn][act]
    stinger = np.zeros(s.size)
    on_st = sol.st_active.astype(bool)
    stinger[on_st] = react[0::ndn][on_st]
    contact[on_st] = "stinger"
    contact[-1] = "fixed"
    reaction = constraint_forces(nd, sol.phi_r, react)
    tip = sol.tip
    if tip is not None:  # the node over the tip (its force is among the constraint forces)
        k, normal = tip
        stinger[k] += normal
        if contact[k] == "free":
            contact[k] = "tip"
    if case.lay.has_rollers:  # the nodes over the rollers the pipe bears on
        on = sol.points[:, L.PT_BEAR] != 0.0
        nodes = sol.roller_nodes[on]
        stinger[nodes] += sol.points[on, L.PT_R]
        contact[nodes] = "roller"
    return {
        "s": s, "x": x, "y": y, "z": z, "angle_deg": angle,
        "effective_tension": te, "wall_tension": tw,
        "moment_x": mom[:, 0], "moment_y": mom[:, 1], "moment_z": mom[:, 2], "moment": m_abs,
        "curvature": curvature, "torque": np.full(s.size, torque), "axial_strain": strain,
        "von_mises": vm, "seabed_reaction": seabed, "seabed_reaction_y": seabed_y,
        "stinger_reaction": stinger,
        "reaction_x": reaction[:, 0], "reaction_y": reaction[:, 1], "reaction_z": reaction[:, 2],
        "slipping": act & ((fric[:, L.FR_DIR] != 0.0) | (fric[:, L.FR_DIRZ] != 0.0)),
        "contact": contact,
    }


def _bottom_tension(case: Case, sol: Solution, s, te, s_tdp: float) -> float:
    """The bottom tension [N]: on a flat seabed the effective tension at the
    lower end (the solve's, when it slides); on a sloped one the effective
    tension at touchdown, ``te`` [N] at ``s_tdp`` [m] along ``s`` (along the
    laid pipe it changes by the weight's component, seabed.slope_deg)."""
    if case.seabed.slope != 0.0:
        return float(np.interp(s_tdp, s, te))
    return sol.bottom_tension if sol.bottom_tension is not None else float(te[0])

def build_summary(case: Case, sol: Solution, cols: dict, rollers: dict | None = None,
                  functional: dict | None = None, identify: bool = True,
                  spans: dict | None = None) -> dict:
    """The summary row (the columns of ``SUMMARY_UNITS``) of one solved case
    from its solution ``sol`` (the solver's counts and time, touchdown and
    lift-off), its profile columns ``cols``, the roller columns ``rollers``
    (None without rollers) and ``functional``, the profile columns of its functional load case, for
    the code check (:func:`pipelay_fast.output.design.lcc_sections`).
    ``identify``: False leaves ``case_id`` "" (a summary that is no
    dataset's row, as the sensitivities' neighbours: the id hashes the
    case's tables, a third of a millisecond). ``spans``: the laid pipe's
    span table (:func:`.spans.span_table`; None: found here).

    Overbend and sagbend are
    :func:`pipelay_fast.output.design.bend_regions`' (by the sign of the
    in-plane moment above touchdown); J-lay has no overbend (NaN). The lay design answers
    (layback, tip clearance, strains, utilisations) are
    :func:`pipelay_fast.output.design.design_columns`'.

    Flags: ``yielded`` where the largest von Mises stress exceeds
    ``pipe.smys`` (``max_von_mises_over_smys`` > 1); ``bears_on_tip`` where
    the pipe leaves the stinger at its tip with a concentrated reaction
    (``sol.tip``; a roller stinger: bearing on its last roller; J-lay:
    False).
    """
    cur = case.environment.current
    stats, s_tdp, s_liftoff = sol.stats, sol.s_tdp, sol.s_liftoff
    s = cols["s"]
    z_tdp = float(np.interp(s_tdp, s, cols["z"]))
    beyond = s >= s_tdp
    fibre = np.abs(cols["axial_strain"]) + cols["curvature"] * case.pipe.outer_diameter / 2.0
    stinger = case.lay.stinger
    te = cols["effective_tension"]
    nan = math.nan
    vm, mom = cols["von_mises"], cols["moment"]
    hog, sag = bend_regions(cols, s_tdp, s_liftoff, stinger is not None)
    if stinger is not None:
        over_vm = float(vm[hog].max()) if hog.any() else nan
        over_m = float(mom[hog].max()) if hog.any() else nan
        sag_vm = float(vm[sag].max()) if sag.any() else nan
        sag_m = float(mom[sag].max()) if sag.any() else nan
        lift = s_liftoff if s_liftoff is not None else s[-1]
        liftoff_z = float(np.interp(lift, s, cols["z"]))
        liftoff_angle = float(np.interp(lift, s, cols["angle_deg"]))
        suspended = float(lift - s_tdp)
    else:
        over_vm = over_m = liftoff_z = liftoff_angle = nan
        sag_vm = interior_peak(vm[beyond])
        sag_m = interior_peak(mom[beyond])
        suspended = float(s[-1] - s_tdp)
    bearing = sol.tip
    tip = 0.0 if bearing is None else bearing[1]
    nd = sol.nd
    nodal = sol.u.reshape(-1, sol.ndn)
    r, rp = np.ascontiguousarray(nodal[:, :nd]), np.ascontiguousarray(nodal[:, nd:2 * nd])
    departure = liftoff_angle if stinger is not None else float(cols["angle_deg"][-1])
    last_roller = None  # (no roller stinger)
    max_roller = nan
    last_clearance = None
    bears_on_tip = bearing is not None
    if rollers is not None:  # the tip's clearance is the last roller's
        bears_on_tip = bool(rollers["in_contact"][-1])
        last_roller = sol.last_roller
        max_roller = float(rollers["reaction"].max())
        last_clearance = float(rollers["clearance"][-1])
    design = design_columns(case, cols, r, rp, s_tdp, hog, sag, bearing is not None, departure,
                            last_clearance, functional)
    return {
        "case_id": case_id(case) if identify else "",
        "method": case.lay.method,
        "dimension": f"{nd}d",
        **stinger_columns(case.given_lay),
        "water_depth": case.environment.water_depth,
        "trim_deg": case.given_lay.trim_deg,
        "current_speed": cur.speed,
        "current_heading_deg": cur.heading,
        "status": "ok",
        "message": vessel_note(case.given_lay, case.lay, case.environment.water_depth),
        "top_tension": float(te[-1]),
        "bottom_tension": _bottom_tension(case, sol, s, te, s_tdp),
        "tdp_z": z_tdp,
        **touchdown_columns(case, sol, cols, span_table(case, sol) if spans is None else spans),
        "liftoff_z": liftoff_z,
        "liftoff_angle_deg": liftoff_angle,
        "top_angle_deg": float(cols["angle_deg"][-1]),
        "suspended_length": suspended,
        "max_von_mises": float(vm.max()),
        "max_von_mises_over_smys": float(vm.max()) / case.pipe.smys,
        "yielded": bool(vm.max() > case.pipe.smys),
        "overbend_max_von_mises": over_vm,
        "sagbend_max_von_mises": sag_vm,
        "overbend_max_moment": over_m,
        "sagbend_max_moment": sag_m,
        "max_strain": float(fibre.max()),
        "max_lateral_deflection": float(np.abs(cols["y"]).max()),
        "tip_reaction": tip,
        "bears_on_tip": bears_on_tip,
        "liftoff_reaction": liftoff_reaction(s, cols["stinger_reaction"], sol.lo_node),
        "max_roller_reaction": max_roller,
        "last_roller_in_contact": last_roller,
        **design,
        "n_elements": int(s.size - 1),
        "n_iterations": int(stats["iterations"]),
        "n_current_steps": int(stats["current_steps"]),
        "max_current_step_iterations": int(stats["current_step_max"]),
        "n_meshes": int(stats["meshes"]),
        "solve_seconds": float(stats["seconds"]),
    }

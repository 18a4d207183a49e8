"""A solve's problem as arrays: the mesh, its constraints and its state.

:class:`Problem` holds what the Newton kernel reads (the case's data, the
mesh that follows the contact boundaries, the supports, the ends, the
state). It is built from the first guess (:func:`build_problem`), carried
over from a solved neighbour (:func:`warm_problem`), or graded anew with the
state interpolated onto the new mesh (:func:`remesh`).
"""

from __future__ import annotations

import math

import numpy as np

from ..input.case import Case
from ..input.limits import check_mesh_size
from ..input.profile import bed_knots
from ..kernels import layout as L
from ..kernels.layout import B_PT
from . import tuning as T
from .beam import BeamSpan, ElasticaSpan, bending_dominated
from .boundaries import (
    bear_on_tip,
    follow_boundaries,
    follow_nodes,
    over_rollers,
    roller_gaps,
    touchdown_position,
)
from .friction import anchor_friction, friction_laid_length
from .guess import first_guess, guide_case, shape
from .mesh import graded_nodes, grading_rates
from .model import build_props, dimension_of, pin_jump, section_array, sections_of
from .state import EndConditions, Problem, interpolate_state, make_problem
from .supports import line_height, seabed_row, surface_heights


def _mesh_sizes(case: Case, lam: float):
    """h_max, h_min [m] of a case whose flexural length sqrt(EI/T) at
    touchdown is ``lam`` [m] (ungraded, h_min = h_max: a mesh remeshed to put
    a node somewhere stays uniform between its nodes, :func:`remesh`). On a
    seabed profile h_max is at most the foundation's length (4 EI/k)^(1/4)
    (at 0.7 of it a span's length and largest gap were within 0.4 % of an
    independent solution, tests/test_profile_solve.py)."""
    h_max = case.solver.element_length
    if case.seabed.profile is not None:  # an element per foundation length at most
        h_max = min(h_max, (4.0 * case.pipe.bending_stiffness / case.seabed.stiffness) ** 0.25)
    if not case.solver.grading:
        h_min = h_max
    elif case.solver.min_element_length is not None:
        h_min = case.solver.min_element_length
    else:
        h_min = min(h_max, max(h_max / T.FINEST_COARSENING, T.FINEST_IN_LAYER * lam))
    return h_max, min(h_min, h_max)


def _guess(case: Case, laid: float | None = None):
    """The first guess of a case (:func:`.guess.first_guess`) with ``laid``
    [m] of laid pipe; None: solver.laid_length, or its default when that is
    not given either. The default reaches back over a seabed profile's
    table behind touchdown, and LAID_LENGTHS flexural lengths beyond its
    first row, so that the spans it makes are in the model."""
    h_max = case.solver.element_length
    given = laid if laid is not None else case.solver.laid_length
    profile = case.seabed.profile

    def laid_of(cat, z_td):
        lam = math.sqrt(case.pipe.bending_stiffness / cat.h)
        default = given or (T.LOAD_STEP_FACTOR * T.LAID_LENGTHS * lam + T.LAID_ELEMENTS * h_max
                            + friction_laid_length(case, cat))
        if profile is None or given:
            return default
        return max(default, z_td - profile[0][0] + T.LAID_LENGTHS * lam)

    return first_guess(case, laid_of)


def _mesh_stats(case: Case, g) -> dict:
    """What a case's meshes are graded by, from its first guess ``g``
    (:func:`sized_mesh`)."""
    return sized_mesh(case, _guessed(case, g))


def _guessed(case: Case, g) -> dict:
    """The first guess ``g``'s values a mesh is sized by (:func:`guess_sizes`)."""
    return {"flexural_length": math.sqrt(case.pipe.bending_stiffness / g.cat.h),
            "weight": abs(g.cat.w1), "cold_total": g.total}


def guess_sizes(case: Case) -> dict:
    """The values of a cold solve's first guess (a roller stinger's: its
    guide case's, :func:`.guess.guide_case`) that its meshes are sized by:
    the flexural length sqrt(EI/T) at touchdown [m], the effective weight
    there [N/m] and the length of pipe [m] (:func:`sized_mesh`)."""
    return _guessed(case, _guess(guide_case(case) if case.lay.has_rollers else case))


def sized_mesh(case: Case, guessed: dict) -> dict:
    """What a case's meshes are graded by, from its first guess's values
    ``guessed`` (:func:`guess_sizes`): the element lengths h_max, h_min
    [m], the flexural length at touchdown [m], the boundary layer [m] (0:
    none) and the length of pipe modelled [m] (``cold_total``)."""
    lam = guessed["flexural_length"]
    h_max, h_min = _mesh_sizes(case, lam)
    # a tension-dominated lay has boundary layers of length lam at its
    # contact boundaries (:func:`.continuation.boundary_step`); 0: none
    layer = 0.0 if bending_dominated(case.pipe.bending_stiffness, lam, guessed["weight"]) else lam
    return {"h_min": h_min, "h_max": h_max, "flexural_length": lam, "boundary_layer": layer,
            "cold_total": guessed["cold_total"]}


def _reference_force(case: Case, g) -> float:
    """The force [N] Newton's residual is measured against, from the first guess."""
    return max(g.cat.top_tension, abs(g.cat.w1) * g.total, case.lay.top_tension or 0.0)


def build_problem(case: Case, laid: float | None = None) -> Problem:
    """First guess, graded mesh and constraints of a case (a roller
    stinger's: :func:`roller_problem`), with ``laid`` [m] of laid pipe
    behind the guess's touchdown (None: the case's, :func:`_guess`)."""
    nd = dimension_of(case)
    ndn = 2 * nd + 1
    g = _guess(case, laid)
    stats = {**_mesh_stats(case, g),
             "stinger_foci": [g.s_liftoff] if g.s_liftoff is not None else []}
    h_max, h_min, lam = stats["h_max"], stats["h_min"], stats["flexural_length"]
    # A stiff pipe touches down about one flexural length before the catenary
    # does (boundary-layer asymptotics): the mesh is finest there and the
    # initial seabed contact ends there (on a shorter laid pipe, a share of
    # it); the beam-column's guess touches down there already.
    s_focus = (g.laid if isinstance(g.cat, (BeamSpan, ElasticaSpan))
               else max(g.laid - lam, T.TOUCHDOWN_FOCUS_SHARE * g.laid))
    foci = [s_focus, g.total] + ([g.s_liftoff] if g.s_liftoff is not None else [])
    s = graded_nodes(g.total, foci, h_max, h_min, grading=case.solver.grading,
                     check=lambda n: check_mesh_size(case, n, g.total, g.laid,
                                                     _laid_source(case, g.cat, lam, laid)))
    x, z, th, te, kappa = shape(case, g, s)
    u = np.zeros(s.size * ndn)
    u[0::ndn] = x
    u[nd - 1::ndn] = z
    u[nd::ndn] = np.sin(th)
    u[2 * nd - 1::ndn] = np.cos(th)
    u[2 * nd::ndn] = te - case.pipe.bending_stiffness * kappa**2
    pb = _problem(case, nd, s, u, g.cat.h, _reference_force(case, g), stats, g.knots)
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
    material point nearest it: projections on its tangent from the nearest
    node, each taken while it moves the point less than the last, so to
    round-off; ungraded there), graded at the answer's touchdown, the state
    interpolated. The rollers it passes on (its gap within round-off of
    h_min: the guide's tip) or below bear (Newton's first step lifts the
    pipe onto those it passes below: from this equilibrium the reactions
    mean something; measured against moving the rollers onto their places
    in load steps: benchmarks/bench_rollers.py)."""
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
    last = np.full(s_r.size, np.inf)  # each roller's last step [m]
    while True:  # (Gauss-Newton on the foot of the normal, to round-off)
        u_r = interpolate_state(guide.s, u, nd, s_r)
        xp, zp = u_r[nd::ndn], u_r[2 * nd - 1::ndn]
        along = ((rollers[:, 0] - u_r[0::ndn]) * xp
                 + (rollers[:, 1] - u_r[nd - 1::ndn]) * zp) / np.hypot(xp, zp)
        moved = np.clip(s_r + along, s_t, total)
        step = np.abs(moved - s_r)
        shorter = step < last
        if not shorter.any():
            break
        s_r, last = np.where(shorter, moved, s_r), np.where(shorter, step, last)
    source = "the guide's answer (the quadratic stinger through the rollers)"
    s = graded_nodes(total, [s_t, total], h_max, h_min, grading=case.solver.grading,
                     check=lambda n: check_mesh_size(case, n, total, s_t, source), nodes=s_r)
    u = interpolate_state(guide.s, guide.u, nd, s)
    pb = _problem(case, nd, s, u, guide.tb[0], guide.settings.fref, stats, guide.bed)
    pb.ends.fix_val[:ndn] = guide.ends.fix_val[:ndn]
    k_td = int(np.argmin(np.abs(s - s_t)))
    pb.contacts.bed_active[1:k_td + 1] = 1
    over = np.searchsorted(s, s_r)  # (each a node: graded_nodes keeps them)
    over -= (over > 0) & (np.abs(s[np.maximum(over - 1, 0)] - s_r) < np.abs(s[over] - s_r))
    nodes = (k_td, -1, *over.tolist())
    follow_nodes(case, pb, nodes, share_overlaps=not case.solver.grading)
    if case.solver.grading:  # graded at touchdown, the grading moving with it
        _follow_grading(pb, nodes, total, [s_t, total], s_r)
    pb.contacts.points[:, L.PT_BEAR] = (roller_gaps(pb) <= T.REL_ROUNDOFF * h_min).astype(float)
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
    pb.mesh.zone_b, pb.mesh.grade_b = pb.mesh.s_b, rates
    pb.mesh.follow_rates(nodes, rates)


def _laid_source(case: Case, cat, lam: float, laid: float | None = None) -> str:
    """What set the laid length of the first mesh (for the mesh-size check);
    ``laid``: the solve's own laid length [m], :func:`build_problem`'s."""
    if case.lay.pipe_length is not None:
        return f"lay.pipe_length = {case.lay.pipe_length!r} m less the suspended span"
    if laid is not None:
        return (f"{laid:.4g} m of laid pipe, doubled because seabed friction did not hold "
                "the laid pipe before its modelled lower end")
    if case.solver.laid_length is not None:
        return f"solver.laid_length = {case.solver.laid_length!r} m"
    lay = case.lay
    key, tension = (("lay.top_tension", lay.top_tension) if lay.top_tension is not None
                    else ("lay.bottom_tension", lay.bottom_tension))
    text = (f"the default of solver.laid_length: twice {T.LAID_LENGTHS:g} flexural length "
            f"sqrt(EI/T) = {lam:.4g} m at touchdown, where {key} = {tension!r} N gives the "
            f"tension T = {cat.h:.4g} N, and {T.LAID_ELEMENTS:g} elements")
    slip = friction_laid_length(case, cat)
    if slip > 0.0:
        text += (f" and {slip:.4g} m for seabed friction to take up the lateral drag "
                 "(environment.current.speed, seabed.lateral_friction)")
    return text


def _problem(case: Case, nd, s, u, tb, fref, stats, knots) -> Problem:
    """Constraint arrays for nodes ``s`` with state ``u`` over the seabed
    profile's ``knots`` (:func:`..input.profile.bed_knots`; a cold
    start's are its first guess's, ``Guess.knots``). The contact sets
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
    curve = None
    st = lay.curve  # (a roller stinger is its points)
    pinned = lay.top_angle == "pinned"
    top_angle = None if pinned else lay.top_angle
    if st is not None:
        curve = st.support_row()
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
    bed = seabed_row(case.seabed)
    angle = bed[1]
    if angle != 0.0:  # the lower end in the seabed's frame: x its normal, z its tangent
        phi_r[0] = phi_rp[0] = angle
        fix_val[0] = bed[0] * math.cos(angle) - bed[2] * math.sin(angle)
        fix_val[zi] = u[0] * math.sin(angle) + u[zi] * math.cos(angle)
    props, table = build_props(case)
    fric = np.zeros((nn, L.N_FRIC))
    anchor_friction(fric, u, nd, s, props)
    pin = pinned and st is not None  # held along the stinger's tangent, conforming
    ends = EndConditions(fix_mask, fix_val, np.zeros(nn * ndn), slide_dof, top, top_target,
                         angle, base + nd if pin else -1, pin_jump(case) if pin else 0.0)
    section = section_array(s, sections_of(case))
    return make_problem(nd=nd, s=s, props=props, table=table, section=section, u=u, ends=ends,
                        fref=fref, href=stats["h_max"], points=_points(case, curve), curve=curve,
                        tb=tb, fric=fric, phi_r=phi_r, phi_rp=phi_rp, stats=stats, seabed=bed,
                        bed=knots)


def _points(case: Case, curve) -> np.ndarray:
    """The rigid points of a case (rows ``L.PT_*``): the tip (x_L, z_L) of
    the quadratic stinger ``curve`` (its row, layout ``ST_*``; None: none),
    a roller stinger's rollers (each holding the pipe laterally or not),
    none in J-lay."""
    rollers = case.lay.roller_positions()
    if rollers is not None:
        pts = np.zeros((len(rollers), L.N_PT))
        pts[:, L.PT_X] = rollers[:, 0]
        pts[:, L.PT_Z] = rollers[:, 1]
        pts[:, L.PT_HOLD] = case.lay.stinger.lateral_hold()
        return pts
    if curve is None:
        return np.zeros((0, L.N_PT))
    pts = np.zeros((1, L.N_PT))
    z_l = curve[L.ST_ZL]
    pts[0, L.PT_X] = line_height(L.SUP_CURVE, curve, z_l)[0]
    pts[0, L.PT_Z] = z_l
    return pts


def remesh(case: Case, pb: Problem, s_tdp: float, stinger_foci=(),
           laid: float | None = None, grading: bool = False,
           total: float | None = None, keep_rates: bool = False) -> Problem:
    """A mesh with nodes at ``s_tdp`` and ``stinger_foci`` [m], graded there, the
    state interpolated onto it.

    Laid pipe is prepended to ``laid`` [m] behind touchdown when that is
    given (:func:`.solver.more_laid`); with ``total`` [m], laid pipe is added
    or cut at the lower end to that length of pipe. The mesh
    follows the boundaries in zones (:meth:`Problem.follow`,
    for boundaries that are still to be found) or, with ``grading`` (graded at
    boundaries found), as its grading moves with them
    (:meth:`Problem.follow_rates`), the zones kept for the current's path.
    With ``keep_rates`` (and ``grading``), ``pb``'s map's rates are kept where
    the boundaries fall on ``pb``'s nodes (``pb`` graded at the same
    boundaries with other sizes: the rates differ by the change of the
    sizes, a second-order change of the nodes' moves).
    """
    nd, ndn = pb.nd, pb.ndn
    extra = 0.0 if total is None else total - pb.s[-1]
    if laid is not None:
        extra = max(extra, laid - s_tdp)
    total = pb.s[-1] + extra
    focus = s_tdp + extra
    held = [f + extra for f in stinger_foci]
    foci = [focus, total, *held]
    over = over_rollers(pb) + extra  # nodes, ungraded there
    source = (f"remeshed, {extra:.4g} m of it prepended: the laid pipe doubled as touchdown "
              "ran toward the modelled lower end (a case with no touchdown runs on), or "
              "with friction not holding the laid pipe before it")
    s = graded_nodes(total, foci, pb.stats["h_max"], pb.stats["h_min"],
                     check=lambda n: check_mesh_size(case, n, total, focus, source), nodes=over)
    u = interpolate_state(pb.s + extra, pb.u, nd, s)
    first = s < extra
    if first.any():  # along the seabed (its plane, or its profile) from the old lower end
        angle = seabed_row(case.seabed)[1]
        z_first = pb.u[nd - 1] - (extra - s[first]) * math.cos(angle)
        x_b, dx_b = surface_heights(pb.props, pb.bed, z_first)
        c = 1.0 / np.hypot(1.0, dx_b)  # tangent to the surface: (dx_b, 1) / |.|
        u[0::ndn][first] = x_b
        u[nd - 1::ndn][first] = z_first
        u[nd::ndn][first] = dx_b * c
        u[2 * nd - 1::ndn][first] = c
        u[2 * nd::ndn][first] = pb.u[2 * nd]
        if nd == 3:
            u[1::ndn][first] = pb.u[1]
            u[nd + 1::ndn][first] = 0.0
    stats = dict(pb.stats)
    new = _problem(case, nd, s, u, pb.tb[0], pb.settings.fref, stats,
                   bed_knots(case.seabed.profile, case.environment.water_depth))
    # the lower end stays held where the case holds it (with a given pipe
    # length, at z = 0: cut or lengthened there, the pipe's state was held
    # where the neighbour's laid pipe put that material point, 2 m off,
    # and its top tension came out 59 % off; Newton moves it back)
    new.ends.fix_val[:ndn] = pb.ends.fix_val[:ndn]
    new.path.warm, new.path.warm_path = pb.path.warm, pb.path.warm_path
    new.settings.tolerance = pb.settings.tolerance
    # the new mesh follows the same boundaries, each on the node graded onto it
    def at(k):
        return -1 if k < 0 else int(np.argmin(np.abs(s - (pb.s[k] + extra))))
    new.contacts.bed_active[:] = 0
    new.contacts.bed_active[1:at(pb.td_node) + 1] = 1
    if pb.lo_node >= 0:
        new.contacts.st_active[:] = 0
        new.contacts.st_active[at(pb.lo_node):-1] = 1
    nodes = [at(int(k)) for k in pb.bnodes]
    if keep_rates and grading and nodes == pb.bnodes.tolist():
        new.mesh.follow_rates(nodes, pb.mesh.s_b)
        new.mesh.zone_b, new.mesh.grade_b = pb.mesh.zone_b, pb.mesh.grade_b
    else:
        follow_nodes(case, new, nodes, share_overlaps=not grading)
        if grading:
            _follow_grading(new, nodes, total, foci, over)
    # a bearing point keeps bearing (the node over it moves with the pipe)
    new.contacts.points[:, L.PT_BEAR:L.PT_R + 1] = pb.contacts.points[:, L.PT_BEAR:L.PT_R + 1]
    return new

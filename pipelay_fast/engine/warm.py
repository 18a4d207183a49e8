"""A warm start: a solved neighbour's problem carried over to a case that
differs from it in its data (a sweep's next ``a``, tension or roller
heights), its state moved onto the changed stinger."""

from __future__ import annotations

import numpy as np

from ..input.case import Case
from ..kernels import layout as L
from ..kernels.layout import B_LO
from .boundaries import touchdown_position
from .guess import guide_case
from .model import dimension_of
from .problem import _guess, _mesh_stats, _problem, _reference_force
from .state import MAP, STATE, Problem, snapshot
from .supports import line_height, line_span


def warm_problem(case: Case, old: Problem) -> Problem:
    """The problem of ``case`` on the mesh of a solved neighbouring case, its
    state (shape, contacts, tension) the starting point. On the friction path
    the state before the current is taken, so that the slip path is followed
    from gravity alone again; each of its steps then starts from the
    neighbour's increment over it (``warm_path``, :meth:`Problem.start_step`)."""
    nd = dimension_of(case)
    if nd != old.nd:
        raise ValueError(f"warm: a {old.nd}D solution cannot start a {nd}D case")
    if old.has_curve != (case.lay.curve is not None):
        raise ValueError(f"warm: lay.method {case.lay.method!r} or its stinger differs from the "
                         "warm case's")
    if not old.has_curve and len(old.contacts.points) != case.lay.roller_count:
        raise ValueError(f"warm: the case has {case.lay.roller_count} rollers, the warm case "
                         f"{len(old.contacts.points)}")
    # (the map with it: where the neighbour's tip switched regime along the
    # path, its map after the switch does not fit the state before the
    # current)
    state = dict(zip(STATE + MAP, old.path.before_current or snapshot(old), strict=True))
    g = _guess(guide_case(case) if case.lay.has_rollers else case)
    new = _problem(case, nd, state["s"].copy(), state["u"].copy(), state["tb"][0],
                   _reference_force(case, g), dict(old.stats), g.knots)
    new.path.warm = True
    # the mesh sizes and length of pipe of the cold start (its guess's): the
    # mesh is graded anew with them, so that the warm answer is the cold
    # one's (the neighbour's sizes, for its own lay, give another mesh)
    new.stats.update(_mesh_stats(case, g))
    for name in ("bed_active", "st_active", "fric"):
        getattr(new.contacts, name)[:] = state[name]
    # the points' contact states (their positions are the new case's)
    new.contacts.points[:, L.PT_BEAR:L.PT_R + 1] = state["points"][:, L.PT_BEAR:L.PT_R + 1]
    if state["s_a"] is not None:
        new.mesh.bnodes, new.mesh.s_a, new.mesh.s_b = (
            state["bnodes"].copy(), state["s_a"].copy(), state["s_b"].copy())
        new.mesh.s_bd = state["s_bd"].copy()
        new.mesh.s[:] = state["s"]
        if state["grade_b"] is not None:
            # as the neighbour's grading moves (touchdown, and each rigid
            # point's node, which moves only as the pipe slides over it); but
            # lift-off, which a change of the stinger moves far along it, in
            # its zone (with the grading's rates the mesh folds there)
            new.mesh.grade_b, new.mesh.zone_b = state["grade_b"], state["zone_b"]
            rates = new.mesh.grade_b.copy()
            rates[B_LO] = new.mesh.zone_b[B_LO]
            new.mesh.follow_rates(new.bnodes, rates)
    if old.has_curve:
        _onto_stinger(new, old.curve_support)
    new.path.warm_path = old.path.current_path
    return new


def _onto_stinger(pb: Problem, old_curve: tuple):
    """Carry a warm state over to a changed stinger: every node over the
    stinger's z range moves in x by the change of the curve there (which
    vanishes at both ends when only ``a`` changed), its slope with it, so the
    contacts start on the new curve and the free span keeps its shape; then
    every node slides along the pipe so that the elements keep their
    lengths (:func:`_slide_to_length`)."""
    if not pb.has_curve:
        return
    nd, ndn = pb.nd, pb.ndn
    z = pb.u[nd - 1::ndn].copy()
    zp = pb.u[2 * nd - 1::ndn].copy()
    new_curve = pb.curve_support
    z_l, z_u = line_span(*new_curve)
    over = (z >= z_l) & (z <= z_u)

    def curve(kind_g, zz):
        return line_height(*kind_g, zz)

    x_new, dx_new = curve(new_curve, z[over])
    x_old, dx_old = curve(old_curve, z[over])
    shift, slope = x_new - x_old, dx_new - dx_old
    # below the tip, down to touchdown: a cubic shift that continues the
    # slope change at the tip and vanishes at touchdown with its slope (no
    # kink at the tip nor at touchdown: the parabola's kink there was a
    # residual of 15 reference forces on the node above touchdown)
    z_td = float(np.interp(touchdown_position(pb), pb.s, z))
    span = (z < z_l) & (z > z_td)
    if span.any() and z_l > z_td:
        k = curve(new_curve, np.array([z_l]))[1][0] - curve(old_curve, np.array([z_l]))[1][0]
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
    if pb.ends.slide_dof >= 0:
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

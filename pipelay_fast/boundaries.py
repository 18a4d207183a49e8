"""The contact boundaries: where they are, the mesh that follows them, the
regime at the stinger's tip.

Touchdown, lift-off from the stinger (or, bearing on the tip, re-contact
above it) and the material point over the tip are unknowns of Newton
(:mod:`.kernels.newton`). This module maps a mesh onto them
(:func:`follow_boundaries`), reads where a solve put them
(:func:`touchdown_position`, :func:`liftoff_position`, ...), says whether the
mesh is graded there (:func:`graded_on_boundaries`), and makes the switch
between lifting off and bearing on the tip that the kernel's complementarity
asks for when it stops at the change of regime (:func:`bear_on_tip`,
:func:`lift_off_above_tip`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from .kernels.contact import ST_ON, ST_ZL, tip_geometry
from .mesh import graded_nodes
from .results import foundation_exit

if TYPE_CHECKING:
    from .case import Case
    from .problem import Problem


def follow_boundaries(case: Case, pb: Problem, s_focus: float):
    """Map the mesh onto touchdown at the node nearest ``s_focus`` (on a rigid
    seabed: an elastic one is a foundation, with no contact boundary) and, in
    S-lay, onto lift-off and the material point over the stinger's tip."""
    s = pb.s
    pb.bed_active[:] = 0
    k = -1
    if case.seabed.is_rigid:
        k = int(np.argmin(np.abs(s[1:-1] - s_focus))) + 1
        pb.bed_active[1:k + 1] = 1
    lift = pb.stats.get("stinger_foci") or []
    if case.lay.stinger is None:
        follow_nodes(case, pb, (k, -1))
        return
    # lift-off: the guess's; where the guess leaves from the tip, the pipe
    # regains the stinger further up (a gap span between, bearing on the
    # tip, :func:`.guess.gap_span`)
    s_lift = lift[0] + (pb.stats["gap_span"] if pb.stats.get("at_tip") else 0.0)
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
    follow_nodes(case, pb, (k, kl, kt))


def follow_nodes(case: Case, pb: Problem, nodes):
    """The mesh follows the boundaries on ``nodes`` (touchdown, lift-off, then
    one per rigid point, the stinger's tip first; -1: none), each with a zone
    of three flexural lengths."""
    zone = 3.0 * pb.stats["flexural_length"]
    zones = [(zone, zone), (zone, min(zone, 0.9 * (pb.s[-1] - pb.s[nodes[1]])))]
    pb.follow(nodes, zones + [(zone, zone)] * (len(nodes) - 2))


ON_FOCUS = 0.02  # a mesh is graded at its foci when no node is further than this share of h_min
HOLD_SPLIT = 0.1  # the shortest element [h_min] between lift-off and the tip's point


def graded_on_boundaries(case: Case, pb: Problem) -> bool:
    """True when the mesh is the one graded at the boundaries found (touchdown
    and every point of :func:`stinger_foci`), with its element counts: no
    node further than ON_FOCUS h_min from that mesh's. Regrading until it is
    makes the answer the mesh's at the boundaries the solve found, whatever
    the path (cold, warm, a target solve's trials) that led there. A mesh
    regraded at boundaries Newton then moves by d follows them as its grading
    does (:meth:`.Problem.follow_rates`), within O(d^2) of this one."""
    total = float(pb.s[-1])
    graded = graded_nodes(total, [touchdown_position(pb), total, *stinger_foci(case, pb)],
                          pb.stats["h_max"], pb.stats["h_min"])
    return (graded.size == pb.s.size
            and float(np.abs(graded - pb.s).max()) <= ON_FOCUS * pb.stats["h_min"])


def lateral_hold_start(case: Case, pb: Problem):
    """In 3D under lateral load, lifting off above the stinger's tip with no
    node over it: the arc length [m] of the material point over the tip,
    where the lateral hold begins (every point over the stinger's z range is
    held at y = 0), for the mesh to hold a node there. None otherwise (with
    planar loads the hold carries nothing, and the mesh is the 2D case's),
    and when that point lies within HOLD_SPLIT h_min of lift-off (lift-off's
    node then begins the hold, that close to the tip)."""
    if pb.nd != 3 or case.is_planar or pb.lo_node < 0 or pb.tip_node >= 0:
        return None
    found, _gap, s_tip = tip_geometry(pb.nd, pb.s_el, pb.u, pb.stinger)
    if not found or s_tip > pb.s[pb.lo_node] - HOLD_SPLIT * pb.stats["h_min"]:
        return None
    return float(s_tip)


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


def stinger_foci(case: Case, pb: Problem):
    """Arc lengths [m] the mesh should hold as nodes on the stinger side (a
    mesh that follows the boundaries: lift-off's and the tip's nodes, and in
    3D where the lateral hold begins, :func:`lateral_hold_start`)."""
    foci = [float(pb.s[k]) for k in (pb.lo_node, pb.tip_node) if k >= 0]
    s_hold = lateral_hold_start(case, pb)
    return foci if s_hold is None else [*foci, s_hold]


MAX_TIP_SWITCHES = 2  # switches between bearing on the tip and lifting off, per solve


def passes_below_tip(pb: Problem) -> bool:
    """True when, lifting off with no node over the tip, the pipe passes below
    the stinger's tip (the complementarity at the tip then asks it to bear)."""
    if pb.lo_node < 0 or pb.tip_node >= 0:
        return False
    found, gap, s_tip = tip_geometry(pb.nd, pb.s_el, pb.u, pb.stinger)
    return bool(found and s_tip < pb.s[pb.lo_node] and gap < -1e-9 * pb.href)


def tip_released(pb: Problem) -> bool:
    """True when a node follows the point over the stinger's tip but the
    tip's complementarity has released it (it carries nothing): the pipe
    then lifts off above the tip, and the node over the tip is not a
    boundary of the answer (:func:`lift_off_above_tip`)."""
    return pb.tip_node >= 0 and pb.tip[0] == 0.0


def regained_span(lam: float, past: float) -> float:
    """The gap span L [m] above a bearing tip, just past the change of regime,
    from ``past`` [m], how far lift-off would go past the tip on the
    stinger's curve continued (Newton's step there), and the flexural length
    ``lam`` = sqrt(EI/T) [m] at the tip. Small deflections, the gap span
    short next to lam (no tension in it): the pipe lifts off at re-contact
    with the stinger's curvature kappa, carries no support p = T kappa over
    L, so reaches the tip steeper by p L^3 / (24 EI) with p L^2 / 4 more
    moment; the free span below takes that moment over lam, d theta =
    M / (T lam). Matching the far field of the lift-off past the tip (steeper
    by kappa d): d = L^2 / (4 lam) + L^3 / (24 lam^2), solved for L."""
    roots = np.roots([1.0 / (24.0 * lam * lam), 1.0 / (4.0 * lam), 0.0, -past])
    real = roots[np.abs(roots.imag) < 1e-9 * lam].real
    return float(real[real > 0.0].min())


def bear_on_tip(case: Case, pb: Problem, past: float | None = None):
    """The regime switch the complementarity at the tip makes as lift-off
    reaches it from above: the pipe now bears on the tip and regains the
    stinger further up, with the gap span between free: :func:`regained_span`
    above it when Newton's step ``past`` [m] that took lift-off past the tip
    is known, else one flexural length above (as a cold start from a guess
    that leaves at the tip near the change of regime does)."""
    s = pb.s
    kt = pb.tip_node
    if kt < 0:  # lifting off there was none: lift-off's node, now at the tip
        kt = pb.lo_node
    span = pb.stats["flexural_length"]
    te = pb.u[pb.lo_node * pb.ndn + 2 * pb.nd]  # about Te at the tip (less EI kappa^2)
    if past is not None and past > 0.0 and te > 0.0:
        span = regained_span(math.sqrt(case.pipe.bending_stiffness / te), past)
    k = int(np.searchsorted(s, s[pb.lo_node] + span))
    k = min(max(k, pb.lo_node + 1, kt + 1), pb.nn - 2)
    pb.st_active[:] = 0
    pb.st_active[k:-1] = 1
    pb.tip[0], pb.tip[1] = 1.0, 0.0
    follow_nodes(case, pb, (pb.td_node, k, kt))


def lift_off_above_tip(case: Case, pb: Problem):
    """The regime switch back: bearing on the tip, Newton closes the gap span
    (status SPAN_CLOSED), or the tip carries nothing at the answer
    (:func:`tip_released`), so the pipe lifts off the stinger above the tip,
    at re-contact's node, with no node over the tip."""
    pb.tip[0], pb.tip[1] = 0.0, 0.0
    follow_nodes(case, pb, (pb.td_node, pb.lo_node, -1))

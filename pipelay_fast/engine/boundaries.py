"""The contact boundaries: where they are, the mesh that follows them, the
regime at the stinger's tip.

Touchdown, lift-off from the stinger (or, bearing on the tip, re-contact
above it) and the material point over the tip are unknowns of Newton
(:mod:`.kernels.newton`). This module maps a mesh onto them
(:func:`follow_boundaries`), reads where a solve put them
(:func:`touchdown_position`, :func:`liftoff_position`, ...), says whether the
mesh is graded there (:func:`graded_on_boundaries`), and decides the
regime at the stinger's tip, the one place that does: from the Newton
kernel's status and its answer (:func:`tip_regime`), the switch between
lifting off and bearing on the tip (:func:`bear_on_tip`,
:func:`lift_off_above_tip`), and the refusal of an answer in the wrong one
(:func:`check_final_regime`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from scipy.optimize import brentq

from ..input.errors import SolveError
from ..kernels import layout as L
from ..kernels.constraints import point_gaps
from ..kernels.contact import tip_geometry
from ..kernels.layout import B_LO, B_PT
from . import tuning as T
from .mesh import graded_nodes
from .state import interpolate_state
from .supports import line_height, line_span, surface_heights

if TYPE_CHECKING:
    from ..input.case import Case
    from .state import Problem


def follow_boundaries(case: Case, pb: Problem, s_focus: float):
    """Map the mesh onto touchdown at the node nearest ``s_focus`` (on a rigid
    seabed: an elastic one is a foundation, with no contact boundary) and, in
    S-lay, onto lift-off and the material point over the stinger's tip."""
    s = pb.s
    pb.contacts.bed_active[:] = 0
    k = -1
    if case.seabed.is_rigid:
        k = int(np.argmin(np.abs(s[1:-1] - s_focus))) + 1
        pb.contacts.bed_active[1:k + 1] = 1
    lift = pb.stats.get("stinger_foci") or []
    if case.lay.stinger is None:
        follow_nodes(case, pb, (k, -1))
        return
    # lift-off: the guess's (at the tip at the lowest: bearing on it, Newton's
    # step past the tip finds the gap span, :func:`bear_on_tip`), above
    # touchdown's node and below the top's
    k0 = max(k, 0)
    kl = int(np.argmin(np.abs(s[k0 + 1:-1] - lift[0]))) + k0 + 1
    pb.contacts.st_active[:] = 0
    pb.contacts.st_active[kl:-1] = 1
    follow_nodes(case, pb, (k, kl, -1))
    # lifting off at the upper end: held there alone (tip_regime's switch), but where the
    # regimes part (a pinned top's EI kappa_U falls to 0 across the pin while conforming)
    if at_upper_end(pb) and pb.ends.pin_jump == 0.0:
        conform_from(case, pb, -1)


def follow_nodes(case: Case, pb: Problem, nodes, share_overlaps: bool = True):
    """The mesh follows the boundaries on ``nodes`` (touchdown, lift-off, then
    one per rigid point, the stinger's tip first; -1: none), each with a zone
    of DECAY_LENGTHS flexural lengths either side (one that reaches past an
    end or another boundary ends there, :meth:`.Problem.follow`). Bearing on
    the tip, the gap span between the tip and re-contact above it is one
    zone, both boundaries' (each one's zone reaches the other), and so is,
    with ``share_overlaps``, the span between two neighbouring boundaries
    whose zones overlap: a zone's edge inside it would be a node that stays
    put near the other boundary, past which that one could not move,
    whereas the span's length is
    what the solve finds (the gap span's, from re-contact's first estimate,
    :func:`regained_span`, to the answer's is often more than its three
    flexural lengths). A graded mesh's zones, kept for the current's path
    (:func:`.problem.remesh`), are each boundary's own (``share_overlaps``
    False): the current's path moves each boundary's zone on its own (and
    touchdown over its spans, :func:`touchdown_spans`), so the friction
    springs between boundaries keep their nodes."""
    zone = T.DECAY_LENGTHS * pb.stats["flexural_length"]
    zones = [[zone, zone] for _ in nodes]
    if len(nodes) > B_PT and nodes[B_LO] >= 0 and nodes[B_PT] >= 0:
        zones[B_LO][0] = zones[B_PT][1] = math.inf
    order = sorted((k, b) for b, k in enumerate(nodes) if k >= 0) if share_overlaps else []
    for (k1, b1), (k2, b2) in zip(order, order[1:], strict=False):
        if pb.s[k2] - pb.s[k1] < zones[b1][1] + zones[b2][0]:  # the zones overlap
            zones[b1][1] = zones[b2][0] = math.inf
    pb.mesh.follow(nodes, zones)


def touchdown_spans(pb: Problem, rates) -> np.ndarray:
    """The map's rates ``rates`` (nb, nn) [-] (:meth:`.MeshMap.follow_rates`)
    with touchdown's row spanning from the lower end to the next boundary
    above it (or the top): node i at s_i + r_i (s_T' - s_T) as touchdown moves
    from s_T to s_T', r_i = s_i / s_T below it and (s_u - s_i) / (s_u - s_T)
    above it, s_u that boundary's (the top's) arc length. The current's path
    moves touchdown along the pipe by many flexural lengths (the drag bows
    the suspended span, which takes up or pays out laid pipe); a zone's
    edge, a node that stays put, would stop it there, the elements between
    squeezed until the axial rows' round-off lies above the tolerance. Over
    the two spans the mesh near touchdown moves with it,
    and touchdown runs on until the laid pipe is short (SHORT_LAID, more
    laid pipe)."""
    rates = np.array(rates, dtype=float)
    k = pb.td_node
    if k <= 0:
        return rates
    s = pb.s
    above = [int(j) for j in pb.bnodes if j > k]
    up = min(above, default=s.size - 1)
    rates[L.B_TD, :] = 0.0
    rates[L.B_TD, :k + 1] = s[:k + 1] / s[k]
    rates[L.B_TD, k:up] = (s[up] - s[k:up]) / (s[up] - s[k])
    return rates


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
                          pb.stats["h_max"], pb.stats["h_min"], nodes=over_rollers(pb))
    return (graded.size == pb.s.size
            and float(np.abs(graded - pb.s).max()) <= T.ON_FOCUS * pb.stats["h_min"])


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
    found, _gap, s_tip = tip_geometry(pb.nd, pb.s_el, pb.u, *pb.curve_support)
    if not found or s_tip > pb.s[pb.lo_node] - T.HOLD_SPLIT * pb.stats["h_min"]:
        return None
    return float(s_tip)


def touchdown_position(pb: Problem) -> float:
    """Arc length of touchdown [m]: its node's on a rigid seabed; on an
    elastic one, where the pipe rises out of the foundation for the last
    time: its clearance x - x_b(z) above the seabed's surface (the flat
    seabed, the slope's plane or the profile,
    :func:`.supports.surface_heights`) changes sign in the element after
    the last node below the seabed, found along the element's cubic Hermite
    x(s), z(s) (:func:`.state.interpolate_state`; not its chord, which would
    move touchdown with the mesh's nodes by a share of their move); the
    lower end's when no node is below it."""
    if pb.td_node >= 0:
        return float(pb.s[pb.td_node])
    nd, ndn, u, s = pb.nd, pb.ndn, pb.u, pb.s
    gap = u[0::ndn] - surface_heights(pb.props, pb.bed, u[nd - 1::ndn])[0]
    below = np.flatnonzero(gap < 0.0)
    if below.size == 0:
        return float(s[0])
    k = int(below[-1])
    if k + 1 >= s.size:
        return float(s[k])
    le = float(s[k + 1] - s[k])
    pair = s[k:k + 2]
    state = u[k * ndn:(k + 2) * ndn]

    def clearance(xi):
        at = interpolate_state(pair, state, nd, np.array([s[k] + le * xi]))
        return at[0] - float(surface_heights(pb.props, pb.bed, at[nd - 1:nd])[0][0])

    return float(s[k] + le * brentq(clearance, 0.0, 1.0, xtol=T.REL_ROUNDOFF))


def conform_end(pb: Problem):
    """Arc length [m] where the pipe leaves (or regains) the stinger's curve:
    lift-off's node; None without a stinger."""
    return float(pb.s[pb.lo_node]) if pb.lo_node >= 0 else None


def tip_position(pb: Problem):
    """Arc length [m] of the material point on the stinger's tip when it bears."""
    if not pb.has_curve or pb.tip[0] == 0.0 or pb.tip_node < 0:
        return None
    return float(pb.s[pb.tip_node])


def over_rollers(pb: Problem) -> np.ndarray:
    """Arc lengths [m] of the nodes over a roller stinger's rollers (empty
    without rollers)."""
    nodes = pb.roller_nodes
    return pb.s[nodes[nodes >= 0]]


def liftoff_position(case: Case, pb: Problem):
    """Arc length of lift-off [m]: the tip when it bears, else where the pipe
    leaves the stinger's curve; on a roller stinger the last roller it bears
    on (the top when none); None without a stinger."""
    if case.lay.has_rollers:
        j = last_roller_in_contact(pb)
        return float(pb.s[pb.roller_nodes[j]]) if j >= 0 else float(pb.s[-1])
    if not pb.has_curve:
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


def passes_below_tip(pb: Problem) -> bool:
    """True when, lifting off with no node over the tip, the pipe passes below
    the stinger's tip (the complementarity at the tip then asks it to bear)."""
    if pb.lo_node < 0 or pb.tip_node >= 0:
        return False
    found, gap, s_tip = tip_geometry(pb.nd, pb.s_el, pb.u, *pb.curve_support)
    return bool(found and s_tip < pb.s[pb.lo_node] and gap < -T.REL_ROUNDOFF * pb.settings.href)


def tip_released(pb: Problem) -> bool:
    """True when a node follows the point over the stinger's tip but the
    tip's complementarity has released it (it carries nothing): the pipe
    then lifts off above the tip, and the node over the tip is not a
    boundary of the answer (:func:`lift_off_above_tip`)."""
    return pb.tip_node >= 0 and pb.tip[0] == 0.0


# :func:`tip_regime`'s switches at the curve's upper end (negative: no kernel status)
TO_UPPER_END = -1  # the contact on the curve shrank to its upper end
ONTO_STINGER = -2  # clear of the curve, the pipe lies below it


def at_upper_end(pb: Problem) -> bool:
    """Whether lift-off (or re-contact above a bearing tip) lies within the top's
    element, or h_min, of the top (the map squeezes the elements between them)."""
    k = pb.lo_node
    return k >= 0 and pb.s[-1] - pb.s[k] <= max(pb.s[-1] - pb.s[-2], pb.stats["h_min"])


def below_stinger(pb: Problem) -> int:
    """Clear of the stinger (:attr:`.Problem.clear_of_stinger`): the lowest
    node over the curve's z range, the top and the node over the tip
    excepted, that lies below the curve by more than round-off (a contact
    the answer is missing); -1 none."""
    nd, ndn = pb.nd, pb.ndn
    kind, g = pb.curve_support
    z_tip, z_top = line_span(kind, g)
    x, z = pb.u[0:-ndn:ndn], pb.u[nd - 1:-ndn:ndn]
    over = (z > z_tip) & (z < z_top)
    over[:pb.tip_node + 1] = False
    gap = x - line_height(kind, g, z)[0]
    below = np.flatnonzero(over & (gap < -T.REL_ROUNDOFF * pb.settings.href))
    return int(below[0]) if below.size else -1


def conform_from(case: Case, pb: Problem, k: int):
    """The regime switches at the stinger's upper end: the pipe conforms to
    the curve from node ``k`` (lift-off, or re-contact above a bearing tip)
    up to the top, or, ``k`` -1, the curve holds it at its upper end alone,
    the top, as the tip's point holds it at the curve's lower end: its
    contact set empty and lift-off no unknown, a bearing tip keeping its
    node (the gap span reaching the top). To that regime as lift-off reaches
    the top (:func:`at_upper_end`), back from it where the pipe lies below
    the curve, from there (:func:`below_stinger`). A pinned top, held along
    the curve's tangent while the pipe conforms up to it, is a pin clear of
    the stinger (:meth:`.Problem.kernel_supports`)."""
    pb.contacts.st_active[:] = 0
    if k >= 0:
        pb.contacts.st_active[k:-1] = 1
    follow_nodes(case, pb, (pb.td_node, k, *pb.bnodes[B_PT:].tolist()))


def tip_regime(pb: Problem, status: int, can_switch: bool) -> int:
    """The regime at the stinger's tip after a Newton call that ended with the
    kernel's ``status``: PAST_TIP (the pipe is to bear on the tip), SPAN_CLOSED
    (to lift off above it) or ``status`` itself (stay). The kernel stops with
    PAST_TIP or SPAN_CLOSED at a change of regime it meets while it iterates;
    at its answer, a pipe lifting off that passes below the tip
    (:func:`passes_below_tip`) is to bear on it, and a node over the tip that
    its complementarity released (:func:`tip_released`), or a tip whose branch
    cycles (TIP_CYCLE), lifts off above it. ``can_switch``: the solve may
    still switch (it lifts off somewhere, and has switched fewer than
    MAX_TIP_SWITCHES times, :mod:`.tuning`); if not, ``status`` stands.

    Then at the curve's upper end: a call that fails with lift-off (or
    re-contact) there (:func:`at_upper_end`) asks TO_UPPER_END, the contact
    shrunk to the end point; an answer clear of the stinger that lies below
    its curve asks ONTO_STINGER (:func:`conform_from`)."""
    if not can_switch:
        return status
    if status == L.OK and passes_below_tip(pb):
        return L.PAST_TIP
    if status == L.OK and tip_released(pb):
        return L.SPAN_CLOSED
    if status == L.TIP_CYCLE and pb.tip_node >= 0:
        return L.SPAN_CLOSED
    if status not in (L.OK, L.PAST_TIP, L.SPAN_CLOSED) and at_upper_end(pb):
        return TO_UPPER_END
    if status == L.OK and pb.clear_of_stinger and below_stinger(pb) >= 0:
        return ONTO_STINGER
    return status


def check_final_regime(case: Case, pb: Problem):
    """Refuse an answer whose lift-off the boundaries' unknowns put below the
    stinger's tip, on the curve continued past it: there the pipe bears on
    the tip, but the solve ended lifting off after its MAX_TIP_SWITCHES
    switches. SolveError."""
    if pb.lo_node < 0:
        return
    z_lo = float(pb.u[pb.lo_node * pb.ndn + pb.nd - 1])
    z_tip = line_span(*pb.curve_support)[0]
    if z_lo < z_tip:
        raise SolveError(
            f"case {case.name!r}: the pipe bears on the stinger's tip (its lift-off, "
            f"z = {z_lo:.3f} m, would lie below the tip, z = {z_tip:.3f} m), but the solve "
            f"ended lifting off (it switches between bearing on the tip and lifting off "
            f"at most {T.MAX_TIP_SWITCHES} times)")


def _gap_closure(ell: float) -> float:
    """g(l) - 1 of :func:`regained_span`, as l^2 p(l) / q(l) with p and q
    power series of positive terms, so without cancellation at any l > 0:
    g - 1 = (e^l - 1 - l) + c (e^l - 1) = [4 (cosh l - 1) - 2 l (cosh l - 1)
    - 4 l sinh l + l^2 (cosh l + sinh l + 1)] / (2 (sinh l - l)), whose
    numerator is l^5 p(l), p = sum_{n>=5} a_n l^(n-5) with a_n = (n-1)(n-4)
    / n! (n even) and (n-3) n / n! (n odd), and denominator l^3 q(l), q =
    sum_{k>=1} 2 l^(2k-2) / (2k+1)!. Each sum runs until its terms no longer
    change it (finite to l of about 700)."""
    p, t, n = 0.0, 1.0 / 120.0, 5  # t = l^(n-5) / n!
    while True:
        a = (n - 1) * (n - 4) if n % 2 == 0 else (n - 3) * n
        last, p = p, p + a * t
        if p == last and n > 5:
            break
        n += 1
        t *= ell / n
    q, u, k = 0.0, 1.0 / 6.0, 1  # u = l^(2k-2) / (2k+1)!
    while True:
        last, q = q, q + 2.0 * u
        if q == last:
            break
        k += 1
        u *= ell * ell / ((2 * k) * (2 * k + 1))
    return ell * ell * p / q


def regained_span(lam: float, past: float) -> float:
    """The gap span L [m] from a bearing tip up to where the pipe regains the
    stinger, from ``past`` [m] > 0, how far lift-off would go past the tip on
    the stinger's curve continued (Newton's step there), and the flexural
    length ``lam`` = sqrt(EI/T) [m] at the tip. ValueError when either is not
    positive and finite.

    Small deflections w(s) of a tensioned beam from the stinger's curve over
    the gap 0 < s < L from re-contact: EI w'''' - T w'' = T kappa + w_n
    (kappa the stinger's curvature, w_n the weight across it: the support
    both took), with w, w' and w'' zero at re-contact (on the stinger,
    tangent, its curvature) and w(L) = 0 at the tip. Below the tip the pipe
    joins the cable through a boundary layer, so its curvature at the tip is
    the cable's, -w_n / T, plus (k - w'(L)) / lam, k the cable's kink at the
    tip (its angle less the stinger's). With sig = s / lam and kappa_e =
    kappa + w_n / T: w = kappa_e lam^2 f(sig), f = cosh sig - 1 - sig^2 / 2
    + c (sinh sig - sig), c = -(cosh l - 1 - l^2 / 2) / (sinh l - l) (so
    that f(l) = 0), and the tip's condition reads g(l) = 1 + f''(l) + f'(l)
    = k / (kappa_e lam), l = L / lam. Lifting off, the pipe leaves the
    stinger lam above the cable's tangent point (the same boundary layer),
    so lift-off at ``past`` beyond the tip puts that point lam + past below
    it and k = kappa_e (lam + past): g(l) - 1 = past / lam. g - 1 = l^2 p /
    q (:func:`_gap_closure`) rises from l^2 / 4 (l -> 0: p / q -> 1 / 4) to
    l^2 - 3 l + 2 (l -> inf), between l^2 / 4 and l^2 throughout, so the
    root is l = m sqrt(past / lam) with m between 1 and 2: brentq's bracket
    (on m, so that its tolerance is relative to l).
    """
    if not (0.0 < past < math.inf and 0.0 < lam < math.inf):
        raise ValueError(f"regained_span: past = {past!r} m and lam = {lam!r} m must be "
                         "positive and finite")
    r = past / lam
    root = math.sqrt(r)
    return lam * root * brentq(lambda m: _gap_closure(m * root) - r, 1.0, 2.0)


def bear_on_tip(case: Case, pb: Problem, past: float | None = None):
    """The regime switch the complementarity at the tip makes as lift-off
    reaches it from above: the pipe now bears on the tip and regains the
    stinger further up, with the gap span between free: :func:`regained_span`
    above it when ``past`` [m] is known, how far past the tip Newton's step
    took lift-off (or the first guess's lift-off lies,
    :func:`.guess.slay_liftoff`). Without it (a solve that lifted off but
    ended passing below the tip: :func:`passes_below_tip`) the pipe keeps
    its shape, re-contact on lift-off's node (:func:`_bear_in_place`), or,
    where the pipe crosses the tip's height too near lift-off for a node of
    its own, re-contact one flexural length above.

    Re-contact's boundary is put on the node nearest there, which is then
    moved onto the estimate, the mesh following it
    (:meth:`.Problem.move_boundary`, the state interpolated), when that lies
    more than HOLD_SPLIT h_min above the tip and below the top's element.
    The nearest node rather than the next one above: measured by the cold
    iterations on the grid, benchmarks/bench_contact.py part 1."""
    s = pb.s
    if (past is None or past <= 0.0) and _bear_in_place(case, pb):
        return
    kt = pb.tip_node
    if kt < 0:  # lifting off there was none: lift-off's node, now at the tip
        kt = pb.lo_node
    span = pb.stats["flexural_length"]
    # Te at the tip, less EI kappa^2: the multiplier one flexural length below
    # lift-off (at lift-off's node, stopped past the tip out of balance, it
    # can be far from the tension, of either sign)
    k_te = int(np.searchsorted(s, s[pb.lo_node] - span))
    te = pb.u[k_te * pb.ndn + 2 * pb.nd]
    if past is not None and past > 0.0 and te > 0.0:
        span = regained_span(math.sqrt(case.pipe.bending_stiffness / te), past)
    target = s[pb.lo_node] + span
    k = int(np.argmin(np.abs(s - target)))
    k = min(max(k, pb.lo_node + 1, kt + 1), pb.nn - 2)
    pb.contacts.st_active[:] = 0
    pb.contacts.st_active[k:-1] = 1
    pb.tip[0], pb.tip[1] = 1.0, 0.0
    follow_nodes(case, pb, (pb.td_node, k, kt))
    if s[kt] + T.HOLD_SPLIT * pb.stats["h_min"] < target < s[pb.nn - 2]:
        pb.move_boundary(B_LO, target)


def _bear_in_place(case: Case, pb: Problem) -> bool:
    """Bearing on the tip from a state lifting off that passes below it (no
    step past the tip to measure): the pipe keeps its shape, re-contact
    stays on lift-off's node and the tip's boundary goes on the node below
    it nearest the material point over the tip, moved onto that point (the
    mesh following it, :meth:`.Problem.move_boundary`). That start is off
    balance only by the pipe's clearance below the tip, which the bearing
    answer closes. False (nothing changed) when the pipe does not cross the
    tip's height, or crosses it within HOLD_SPLIT h_min of lift-off or
    below touchdown's node."""
    if pb.lo_node < 0 or pb.tip_node >= 0:
        return False
    found, _gap, s_tip = tip_geometry(pb.nd, pb.s_el, pb.u, *pb.curve_support)
    s = pb.s
    k_lo = pb.lo_node
    if not found or s_tip > s[k_lo] - T.HOLD_SPLIT * pb.stats["h_min"]:
        return False
    kt = min(int(np.argmin(np.abs(s[:k_lo] - s_tip))), k_lo - 1)
    if kt <= max(pb.td_node, 0):
        return False
    pb.contacts.st_active[:] = 0
    pb.contacts.st_active[k_lo:-1] = 1
    pb.tip[0], pb.tip[1] = 1.0, 0.0
    follow_nodes(case, pb, (pb.td_node, k_lo, kt))
    pb.move_boundary(B_PT, float(s_tip))
    return True


def lift_off_above_tip(case: Case, pb: Problem):
    """The regime switch back: bearing on the tip, Newton closes the gap span
    (status SPAN_CLOSED), or the tip carries nothing at the answer
    (:func:`tip_released`), so the pipe lifts off the stinger above the tip,
    at re-contact's node, with no node over the tip."""
    pb.tip[0], pb.tip[1] = 0.0, 0.0
    follow_nodes(case, pb, (pb.td_node, pb.lo_node, -1))


def last_roller_in_contact(pb) -> int:
    """The index of the last roller (from the vessel down) the pipe bears
    on; -1 when it bears on none or there are no rollers."""
    nodes = pb.roller_nodes
    bearing = np.flatnonzero((pb.contacts.points[:nodes.size, L.PT_BEAR] != 0.0) & (nodes >= 0))
    return int(bearing[-1]) if bearing.size else -1


def roller_gaps(pb) -> np.ndarray:
    """The pipe's clearance [m] above each roller of a roller stinger: its
    axis at the node over the roller, along the pipe's normal there, the
    Newton kernel's gap (:func:`.kernels.newton._point_gap`, in the frame
    of the pipe's tangent there, :func:`.kernels.newton.point_gaps`);
    negative: below it."""
    nodes = np.ascontiguousarray(pb.roller_nodes, dtype=np.int64)
    gaps = np.empty(nodes.size)
    point_gaps(pb.nd, pb.u, pb.contacts.points, nodes, gaps)
    return gaps

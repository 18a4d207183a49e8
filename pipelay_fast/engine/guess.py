"""First guess of a lay (engine layer): laid pipe, natural catenary, and the
stinger for S-lay; and the quadratic guide a roller stinger's solve starts from.

The catenary leaves the stinger where its tangent matches the stinger's: on a
frictionless stinger the effective tension falls by the weight of the height
climbed, Te(x) = T_top - (W(x_top) - W(x)) with W(x) = int_0^x w dx, and a
catenary touching the seabed has Te = h + W(x) and cos(theta) = h / Te, so
lift-off is the root z of  Te(x(z)) (1 - cos psi(z)) = W(x(z))  (psi the stinger
angle). The root may lie on the stinger's curve continued below its tip: the
pipe then leaves from the tip, bearing on it (:attr:`Guess.tip_past`). With
none (the catenary flatter than the stinger at its top) the guess leaves from
the tip too. The guess is only a starting point: Newton corrects
the bending boundary layers, which shift touchdown by about sqrt(EI/h).
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq

from ..input.case import Case
from ..input.profile import bed_heights, bed_knots
from . import tuning as T
from .beam import BeamSpan, ElasticaSpan, bending_guessed, bending_span
from .bed_guess import laid_on_foundation, on_seabed, seabed_span
from .catenary import Catenary, from_top_tension
from .model import pin_jump
from .supports import seabed_height


@dataclass
class Guess:
    """A first shape along unstretched arc length from the lower end.

    Attributes
    ----------
    cat : Catenary
        The free span, touchdown to lift-off (J-lay: to the top).
    laid : float
        Laid length before touchdown [m].
    s_liftoff : float or None
        Arc length of lift-off from the stinger [m] (S-lay).
    total : float
        Total modelled length [m].
    liftoff_z : float or None
        z of lift-off [m] (S-lay).
    tip_past : float or None
        S-lay where the pipe would leave below the stinger's tip: how far [m]
        along the stinger's curve continued below the tip it would lift off
        (the guess then leaves from the tip; the pipe bears on it,
        :func:`pipelay_fast.engine.boundaries.bear_on_tip`). None otherwise.
    x_tdp : float
        Height of touchdown [m] on a sloped seabed or a profile whose
        catenary ``cat`` touches down on it (:func:`.bed_guess.seabed_span`;
        heights from there), else 0.
    knots : ndarray
        The seabed profile's knots (:func:`..input.profile.bed_knots`; (0, 3)
        without a profile), built once for the guess and the problem.
    """

    cat: Catenary
    laid: float
    s_liftoff: float | None
    total: float
    liftoff_z: float | None = None
    tip_past: float | None = None
    x_tdp: float = 0.0
    knots: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))


def weights(case: Case):
    """(w1, w2): effective weight at the seabed and just above the water
    surface [N/m] (w(x) steps at the surface and the contents level, each
    step x < level, so w at the surface is that just above it). ValueError
    when the pipe floats (w1 <= 0)."""
    depth = case.environment.water_depth
    w1 = float(case.effective_weight(0.0))
    w2 = float(case.effective_weight(depth))
    if w1 <= 0.0:
        raise ValueError(
            f"the pipe floats: its submerged effective weight is {w1:.1f} N/m; "
            "increase pipe.steel_density or pipe.coating_density"
        )
    return w1, w2


def _rise(w1, w2, depth, x):
    """W(x) = int_0^x w dx [N]; x a float or an array."""
    return w1 * np.minimum(x, depth) + w2 * np.maximum(x - depth, 0.0)


def free_span(case: Case) -> Catenary:
    """The J-lay catenary from the lay's tension keys (top tension, bottom
    tension, or pipe length with the lower end at the origin). ValueError
    when the tension cannot hold the pipe or the length cannot reach the
    top."""
    lay = case.lay
    depth = case.environment.water_depth
    x_top = lay.top[0]
    w1, w2 = weights(case)
    if lay.top_tension is not None:
        return from_top_tension(lay.top_tension, w1, w2, depth, x_top)
    if lay.bottom_tension is not None:
        return Catenary(lay.bottom_tension, w1, w2, depth, x_top)
    length, z_top = lay.pipe_length, lay.top[1]

    def gap(h):
        cat = Catenary(h, w1, w2, depth, x_top)
        return (z_top - cat.span) - (length - cat.length)

    # h -> 0: a vertical hang (span 0, length x_top); h -> inf: a flat pipe
    # (length - span -> 0)
    h = _tension_root(gap, _rise(w1, w2, depth, x_top), z_top + x_top - length, z_top - length)
    if h is None:
        raise ValueError(
            f"lay.pipe_length = {length:g} m cannot reach the top {lay.top} from a lower end "
            f"at (0, 0) along a catenary: it must lie between {z_top:g} m (the pipe flat) "
            f"and {z_top + x_top:g} m (hanging vertically from the top)"
        )
    return Catenary(h, w1, w2, depth, x_top)


def _height_error(case: Case, h: float) -> float:
    """The guess's error [m] in touchdown's height on a sloped seabed:
    touchdown a flexural length sqrt(EI/h) off (``h`` [N] the catenary's
    tension) along the seabed, times tan(slope)."""
    return abs(math.tan(case.seabed.slope)) * math.sqrt(case.pipe.bending_stiffness / h)


def _tension_root(gap, weight, slack, taut):
    """The horizontal tension h [N] at which ``gap(h)`` = 0, over 0 < h < inf,
    or None when ``gap``'s limits ``slack`` (h -> 0) and ``taut`` (h -> inf),
    in closed form, have the same sign, or the root is one of them (a length
    within round-off of a limit). Solved by brentq over c = h / (h +
    ``weight``) in [0, 1], ``weight`` [N] that of a vertical hang to the top
    (c is then the cosine of the catenary's top angle): the ends are the two
    limits, so the bracket holds every tension."""
    if not slack * taut < 0.0:
        return None

    def of_c(c):
        if c <= 0.0:
            return slack
        if c >= 1.0:
            return taut
        return gap(weight * c / (1.0 - c))

    c = brentq(of_c, 0.0, 1.0)
    h = weight * c / (1.0 - c) if c < 1.0 else math.inf
    return h if 0.0 < h < math.inf else None


def slay_liftoff(case: Case, bottom_tension: float | None = None, x_td: float = 0.0,
                 tan0: float = 0.0):
    """(z of lift-off [m], horizontal tension h [N], how far [m] below the
    tip on the stinger's curve continued the pipe would lift off, None when
    it lifts off above the tip or no lift-off is found) for S-lay.

    The tension comes from the lay's keys, or from ``bottom_tension`` [N] when
    given (the pipe-length case searches over it); the catenary touches down
    at height ``x_td`` [m] at the slope ``tan0`` (a sloped seabed, there
    Te = h sqrt(1 + tan0^2)). Where the pipe would leave
    below the stinger's tip, the guess leaves from the tip, and the third
    value says how far below: the pipe bears on the tip, and
    :func:`.boundaries.regained_span` gives the gap span from it
    (:func:`.boundaries.bear_on_tip`). Within tuning.GUESS_LIFTOFF_ERROR flexural
    lengths of the tip it is None: the guess leaves from the tip, lifting
    off, and Newton's step past the tip tells how far above the tip a pipe
    bearing on it regains the stinger. ValueError when the tension left at
    lift-off cannot hold the pipe hanging from it.
    """
    lay, st = case.lay, case.lay.stinger
    depth = case.environment.water_depth
    w1, w2 = weights(case)
    z_l, (x_u, z_u) = st.lower[1], st.upper

    def tension(x):
        if bottom_tension is None and lay.top_tension is not None:
            below_top = lay.top_tension - pin_jump(case)  # the conforming pipe's at the top
            return below_top - (_rise(w1, w2, depth, x_u) - _rise(w1, w2, depth, x))
        bottom = lay.bottom_tension if bottom_tension is None else bottom_tension
        return bottom + _rise(w1, w2, depth, x)

    sec0 = math.sqrt(1.0 + tan0 * tan0)
    rise_td = _rise(w1, w2, depth, x_td)

    def mismatch(z):
        x = float(st.height(z))
        cos_psi = 1.0 / math.sqrt(1.0 + float(st.slope(z)) ** 2)
        return tension(x) * (1.0 - cos_psi * sec0) - (_rise(w1, w2, depth, x) - rise_td)

    # The cable's lift-off, on the stinger or on its curve continued below
    # the tip, down to the seabed or TIP_PAST_REACH stinger z ranges below
    # the tip. With H = tension - W, constant, the mismatch is H - tension
    # cos psi: down the curve where it rises (dx/dz > 0; a <= 0) x and W fall
    # and psi steepens, so it grows strictly, to H (1 - cos psi) > 0 at the
    # seabed (x = 0, W = 0). One root, when it is negative at the top of the
    # rise (the upper end, or where the curve is level: -W there) and
    # positive at the lower end; none otherwise (the cable flatter than the
    # stinger at its top, or steeper than the curve that far below the tip).
    z_low, z_top = _search_range(st)
    z_lo = z_l
    past = None
    if mismatch(z_top) < 0.0 < mismatch(z_low):
        z_c = brentq(mismatch, z_low, z_top)
        # a stiff pipe leaves about one flexural length sqrt(EI/Te) further up
        # the stinger (boundary-layer asymptotics, EI -> 0)
        t_c = tension(float(st.height(z_c)))
        lam = math.sqrt(case.pipe.bending_stiffness / t_c) if t_c > 0.0 else math.inf
        z_s = float(st.z_at_arc(z_c, min(lam, float(st.arc_length(z_c, z_u)))))
        z_lo = max(z_s, z_l)
        if z_s < z_l:
            past = float(st.arc_length(z_s, z_l))
            if past < T.GUESS_LIFTOFF_ERROR * lam:
                past = None  # within the guess's error of the tip: Newton decides
    x_lo = float(st.height(z_lo))
    t_lo = tension(x_lo)
    h = float(t_lo - (_rise(w1, w2, depth, x_lo) - rise_td)) / sec0
    if h <= 0.0:
        raise ValueError(
            f"lay.top_tension = {lay.top_tension:g} N cannot hold the pipe off the stinger: "
            f"the tension left at lift-off (x = {x_lo:.1f} m) is below the weight hanging from it"
        )
    return z_lo, h, past


def _search_range(st):
    """(lowest z [m] searched for lift-off: where the quadratic stinger's
    curve continued below its tip meets the seabed (x = 0), or
    tuning.TIP_PAST_REACH times the stinger's z range below the tip when
    that is higher; z [m] where the curve's rise ends: the upper end, or
    where it is level when that lies below)."""
    (z_l, z_u) = st.lower[1], st.upper[1]
    z_top = z_u
    if float(st.slope(z_top)) <= 0.0:
        z_top = st.level_z()  # (a < 0: the mean slope of the stinger is positive)
    return max(st.seabed_z(), z_l - T.TIP_PAST_REACH * (z_u - z_l)), z_top


def _slay_span(case: Case, bottom_tension=None):
    """Lift-off, catenary, stinger arc, how far past the tip
    (:func:`slay_liftoff`) and touchdown's height [m] of an S-lay guess. On a
    sloped seabed (the top tension given) the catenary touches down tangent
    to it: touchdown's height is the seabed's under the catenary that starts
    there (:func:`.bed_guess.on_seabed`)."""
    w1, w2 = weights(case)
    st = case.lay.stinger
    depth = case.environment.water_depth
    sloped = case.seabed.slope != 0.0 and bottom_tension is None
    tan0 = math.tan(case.seabed.slope) if sloped else 0.0

    def under(x_td):
        z_lo, h, past = slay_liftoff(case, bottom_tension, x_td, tan0)
        cat = Catenary(h, w1, w2, depth - x_td, float(st.height(z_lo)) - x_td, tan0)
        if past is None and not sloped and bending_guessed(case, cat):
            # bending-dominated: the elastica, tangent to the stinger at lift-off
            cat = bending_span(case, cat, math.atan(float(st.slope(z_lo))))
        return float(seabed_height(case, z_lo - cat.span)), (z_lo, cat, past)

    x_td = 0.0
    first = under(0.0)
    z_lo, cat, past = first[1]
    if sloped:
        x_td, (z_lo, cat, past) = on_seabed(0.0, first, under, _height_error(case, cat.h))
    return z_lo, cat, float(st.arc_length(z_lo, st.upper[1])), past, x_td


def _slay_bottom_tension(case: Case) -> float:
    """The bottom tension [N] at which an S-lay pipe of ``lay.pipe_length``,
    its lower end at z = 0, reaches the vessel: laid pipe, catenary and stinger
    arc add up to the length."""
    length = case.lay.pipe_length
    st = case.lay.stinger
    (x_u, z_u), z_l = st.upper, st.lower[1]
    w1, w2 = weights(case)

    def gap(h):
        z_lo, cat, arc, _past, _x = _slay_span(case, h)
        return (z_lo - cat.span) - (length - cat.length - arc)

    # h -> 0: lift-off at the seabed, one flexural length (-> inf) up the
    # stinger, so at its top, when the search reaches the seabed (else from
    # the tip), and a vertical hang from there; h -> inf: the cable flatter
    # than the stinger's top (lift-off from the tip, the guess's fallback)
    # or, on a stinger level below its top, lift-off where it is level, and
    # a flat catenary (length - span -> 0)
    z_low, z_rise = _search_range(st)
    z_s = z_u if z_low > z_l - T.TIP_PAST_REACH * (z_u - z_l) else z_l  # (reaches the seabed)
    slack = z_s + float(st.height(z_s)) + float(st.arc_length(z_s, z_u)) - length
    z_t = z_l if float(st.slope(z_u)) > 0.0 else z_rise
    flat = z_t + float(st.arc_length(z_t, z_u))
    h = _tension_root(gap, _rise(w1, w2, case.environment.water_depth, x_u),
                      slack, flat - length)
    if h is None:
        raise ValueError(
            f"lay.pipe_length = {length:g} m cannot reach the vessel {case.lay.top} over the "
            f"stinger from a lower end at (0, 0): it must lie between {flat:g} m "
            f"(the pipe flat to the tip, then along the stinger) and {slack + length:g} m "
            "(hanging vertically from the stinger)")
    return h


def first_guess(case: Case, laid_of) -> Guess:
    """The first shape; ``laid_of(cat, z_td)`` gives the laid length [m]
    behind the suspended span's natural catenary ``cat`` touching down at
    ``z_td`` [m] (not called when ``lay.pipe_length`` sets it). ValueError
    as :func:`free_span` and :func:`slay_liftoff`."""
    lay = case.lay
    knots = bed_knots(case.seabed.profile, case.environment.water_depth)
    if lay.method == "J":
        cat, x_tdp = free_span(case), 0.0
        bed = case.seabed
        if (bed.slope != 0.0 or bed.profile is not None) and lay.top_tension is not None:
            cat, x_tdp = seabed_span(case, cat, knots)
        elif bending_guessed(case, cat):
            cat = bending_span(case, cat)
        susp = cat.length
        if lay.pipe_length is not None:
            laid = lay.pipe_length - susp
        else:
            laid = laid_of(cat, lay.top[1] - cat.span)
        return Guess(cat, laid, None, laid + susp, x_tdp=x_tdp, knots=knots)
    if lay.pipe_length is not None:
        z_lo, cat, arc, past, x_tdp = _slay_span(case, _slay_bottom_tension(case))
        laid = lay.pipe_length - cat.length - arc
    else:
        z_lo, cat, arc, past, x_tdp = _slay_span(case)
        laid = laid_of(cat, z_lo - cat.span)
    s_lo = laid + cat.length
    return Guess(cat, laid, s_lo, s_lo + arc, liftoff_z=z_lo, tip_past=past, x_tdp=x_tdp,
                 knots=knots)


def shape(case: Case, g: Guess, s):
    """x, z [m], theta [rad], Te [N], curvature [1/m] of the guess ``g`` at
    arc lengths ``s`` [m] from the lower end (arrays like ``s``); over a
    seabed profile, x and theta moved onto it (:func:`_on_profile`)."""
    lay = case.lay
    cat = g.cat
    z_top = lay.top[1]
    span_end = z_top if g.s_liftoff is None else g.liftoff_z
    z_tdp = span_end - cat.span
    x, z, th, te = cat.at(np.clip(s - g.laid, 0.0, cat.length))
    on_bed = s < g.laid
    z = np.where(on_bed, z_tdp - (g.laid - s), z_tdp + z)
    x = np.where(on_bed, 0.0, x)
    th = np.where(on_bed, 0.0, th)
    te = np.where(on_bed, cat.h, te)
    if isinstance(cat, (BeamSpan, ElasticaSpan)):
        kappa = np.where(on_bed, 0.0, cat.curvature(np.clip(s - g.laid, 0.0, cat.length)))
    else:
        kappa = np.where(on_bed, 0.0,
                         np.cos(th) ** 2 * np.asarray(case.effective_weight(x)) / cat.h)
    if case.seabed.slope != 0.0:
        x, z, th = _onto_slope(case, g, s, x, z, th, z_tdp)
    if g.s_liftoff is not None:
        st = lay.stinger
        on_st = s >= g.s_liftoff
        along = np.minimum(s[on_st] - g.s_liftoff, float(st.arc_length(g.liftoff_z, st.upper[1])))
        zz = np.asarray(st.z_at_arc(g.liftoff_z, along))
        slope = np.asarray(st.slope(zz))
        z[on_st] = zz
        x[on_st] = np.asarray(st.height(zz))
        th[on_st] = np.arctan(slope)
        # frictionless stinger: Te = h + W(x), continuing the catenary's law
        depth = case.environment.water_depth
        te[on_st] = cat.h + _rise(cat.w1, cat.w2, depth, x[on_st])
        kappa[on_st] = st.curvature(zz)
    if case.seabed.profile is not None:
        x, th = _on_profile(case, g, s, x, z, th)
    return x, z, th, te, kappa


def _on_profile(case: Case, g: Guess, s, x, z, th):
    """The guess's shape (``x``, ``z``, ``th`` at ``s``) moved onto the
    seabed profile (its knots ``g.knots``): the suspended span lifted by the
    height its catenary touches down at (``g.x_tdp``,
    :func:`.bed_guess.seabed_span`), and by the rest of x_b at the guess's
    touchdown in proportion to the arc length left up to the fixed top;
    from the lower end to a flexural length sqrt(EI/H) past touchdown (the
    boundary layer over which the pipe leaves the seabed; at most half way
    to the top), the tensioned beam on the foundation
    (:func:`.bed_guess.laid_on_foundation`, the guess's tension H) that ends
    there on that lifted span, with its height and slope."""
    knots = g.knots
    x_td = float(bed_heights(knots, np.array([np.interp(g.laid, s, z)]))[0][0])
    x = x + g.x_tdp + (x_td - g.x_tdp) * np.clip((g.total - s) / (g.total - g.laid), 0.0, 1.0)
    lam = math.sqrt(case.pipe.bending_stiffness / g.cat.h)
    s1 = min(g.laid + lam, 0.5 * (g.laid + g.total))
    near = s <= s1
    beam_x, beam_th = laid_on_foundation(
        knots, float(z[0]), float(np.interp(s1, s, z)), float(np.interp(s1, s, x)),
        math.tan(float(np.interp(s1, s, th))), case.pipe.bending_stiffness, g.cat.h,
        float(case.effective_weight(0.0)), case.seabed.stiffness, z)
    return np.where(near, beam_x, x), np.where(near, beam_th, th)


def _onto_slope(case: Case, g: Guess, s, x, z, th, z_tdp):
    """The guess (x, z [m], theta [rad] at arc lengths ``s`` [m], touchdown
    at ``z_tdp`` [m]) onto a sloped seabed: the laid pipe on the slope's
    line; the suspended span of a catenary touching down on the slope
    (:func:`.bed_guess.seabed_span`) raised to touchdown's height, and the seabed's
    height there off it (the miss :func:`.bed_guess.on_seabed` leaves) sheared in as
    below, so that the span meets the laid pipe; a flat seabed's
    sheared (its heights moved by the seabed's height under them, in full at
    touchdown and not at the span's upper end; Newton corrects the rest).
    The stinger's part is kept."""
    angle = case.seabed.slope
    on_bed = s < g.laid
    z = np.where(on_bed, z_tdp - (g.laid - s) * math.cos(angle), z)
    span = ~on_bed if g.s_liftoff is None else (~on_bed) & (s < g.s_liftoff)
    x_end = float(g.cat.at(g.cat.length)[0])
    share = np.clip(1.0 - x / x_end, 0.0, 1.0)
    if g.cat.tan0 != 0.0:  # the catenary touches down on the slope: its heights from there,
        # and the seabed's height at touchdown off its own (:func:`.bed_guess.on_seabed`'s r)
        # sheared in, in full at touchdown and not at the span's upper end
        miss = float(seabed_height(case, z_tdp)) - g.x_tdp
        tan_t = np.tan(th) * (1.0 - miss / x_end)
        x = np.where(on_bed, seabed_height(case, z), np.where(span, x + g.x_tdp + miss * share, x))
        return x, z, np.where(on_bed, angle, np.where(span, np.arctan(tan_t), th))
    f = seabed_height(case, z)
    tan_t = np.tan(th) * (1.0 - f / x_end) + math.tan(angle) * share
    x = np.where(on_bed, f, np.where(span, x + f * share, x))
    th = np.where(on_bed, angle, np.where(span, np.arctan(tan_t), th))
    return x, z, th


_GUIDES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def guide_case(case: Case) -> Case:
    """A roller stinger's guide: the case with its rollers replaced by a
    quadratic stinger x = x_U + m (z - z_U) + a (z - z_U)^2 from ``lay.top``
    (x_U, z_U), held at the top along the curve (its slope m that of
    ``lay.top_angle``), through the last roller (a <= 0, concave down;
    pinned, m and a the least-squares fit of the rollers' heights), with
    elements tuning.GUIDE_COARSENING times the case's. Its answer is where a
    roller stinger's solve starts
    (:func:`pipelay_fast.engine.problem.roller_problem`, which takes the
    case's own element sizes): where that answer bears on its tip, the pipe
    then bears on the last roller. The curve passes through the last roller
    so that the start's contact at the tip is the roller's (a fit to every
    roller's height can put the tip off the last roller), and is held to
    the top angle so that it follows the rollers of a long radius (a
    curve through the last roller that ignores the top angle can lie well
    above them); both measured on random roller stingers,
    benchmarks/bench_rollers.py part 3. Its heights are in the seabed frame
    (``lay.frame`` the default) and trimmed (no ``lay.trim_deg``), as the
    engine reads them; built once while ``case`` lives (the solve and its
    warm starts ask for it again). Raises ValueError as
    :meth:`pipelay_fast.input.case.Case.with_changes` does."""
    guide = _GUIDES.get(case)
    if guide is None:
        guide = _GUIDES[case] = _guide(case)
    return guide


def _guide(case: Case) -> Case:
    """:func:`guide_case`, built."""
    lay = case.lay
    pts = lay.roller_positions()
    x_u, z_u = lay.top
    dz = pts[:, 1] - z_u
    rise = pts[:, 0] - x_u
    if lay.top_angle == "pinned":  # slope and curvature fitted
        (m, a), *_ = np.linalg.lstsq(np.stack([dz, dz * dz], axis=1), rise, rcond=None)
        a = min(float(a), 0.0)
        if a == 0.0:
            m = float(rise @ dz / (dz @ dz))
    else:
        m = math.tan(math.radians(lay.top_angle))
        a = min(float((rise[-1] - m * dz[-1]) / dz[-1] ** 2), 0.0)
    x_l, z_l = (float(v) for v in pts[-1])
    angle = None if lay.top_angle == "pinned" else lay.top_angle
    solver = case.solver
    coarse = {"solver.element_length": T.GUIDE_COARSENING * solver.element_length}
    if solver.min_element_length is not None:
        coarse["solver.min_element_length"] = T.GUIDE_COARSENING * solver.min_element_length
    return case.with_changes({"lay.stinger": {"a": a, "lower": [x_l, z_l], "upper": [x_u, z_u]},
                              "lay.top": None, "lay.top_angle": angle, "lay.frame": None,
                              "lay.trim_deg": None, "lay.trim_pivot": None, **coarse})

"""The first guess's roots against independent solutions: the J-lay and S-lay
catenaries of a given pipe length (the reference catenary of
tests/reference/catenary.py), the pipe-length range in closed form, and the
S-lay lift-off where the reference catenary's tangent meets the stinger's,
on the stinger's curve continued below its tip too."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

import pipelay_fast as pf
from pipelay_fast.engine.bed_guess import seabed_span
from pipelay_fast.engine.guess import first_guess, free_span, slay_liftoff, weights
from pipelay_fast.engine.tuning import TIP_PAST_REACH
from pipelay_fast.input.profile import bed_heights, bed_knots
from tests.helpers import EXAMPLES
from tests.reference.catenary import natural_catenary_two_weights


def _reference(case, h, x_top):
    w1, w2 = weights(case)
    return natural_catenary_two_weights(w1, w2, case.environment.water_depth, x_top,
                                        T_bottom=h)


@pytest.mark.parametrize("share", [0.05, 0.5, 0.95])
def test_jlay_pipe_length_lands_the_lower_end_at_the_origin(j125, share):
    """A given pipe length between z_top (flat) and z_top + x_top (a vertical
    hang): the reference catenary of the tension found puts touchdown where
    the laid pipe, the length less the suspended span, ends (z = 0)."""
    x_top, z_top = j125.lay.top
    length = z_top + share * x_top
    case = j125.with_changes({"lay.top_tension": None, "lay.pipe_length": length})
    ref = _reference(case, free_span(case).h, x_top)
    laid = length - ref["suspended_length"]
    assert z_top - ref["horizontal_span"] == pytest.approx(laid, abs=1e-9 * length)


@pytest.mark.parametrize("past_end", [-1.0, 1.0])
def test_jlay_pipe_length_outside_the_catenary_range_is_refused(j125, past_end):
    """Shorter than the flat pipe (z_top) or longer than the vertical hang
    (z_top + x_top): no catenary reaches the top."""
    x_top, z_top = j125.lay.top
    length = z_top - 1.0 if past_end < 0 else z_top + x_top + 1.0
    case = j125.with_changes({"lay.top_tension": None, "lay.pipe_length": length})
    with pytest.raises(ValueError, match="cannot reach the top"):
        free_span(case)


def _tangent_point(case, h):
    """z [m] where the reference catenary of bottom tension ``h``, rising to
    the stinger's height there, has the stinger's angle (the stinger's
    rising curve, continued below its tip, scanned then refined)."""
    st = case.lay.stinger
    a, b, c = st.a, st.b, st.c
    z_bed = min(r.real for r in np.roots([a, b, c]) if 2 * a * r.real + b > 0)

    def mismatch(z):
        x = a * z * z + b * z + c
        return (_reference(case, h, x)["top_angle_deg"]
                - math.degrees(math.atan(2 * a * z + b)))

    zs = np.linspace(z_bed, st.upper[1], 4001)[1:]
    f = np.array([mismatch(z) for z in zs])
    k = np.flatnonzero(np.sign(f[:-1]) != np.sign(f[1:]))[-1]
    return brentq(mismatch, zs[k], zs[k + 1], xtol=1e-12)


S67_STINGER = {"a": -0.0012, "lower": [41.5, 265.0], "upper": [72.0, 400.0]}
SHORT_STINGER = {"a": -0.0012, "lower": [56.0, 350.0], "upper": [72.0, 400.0]}


@pytest.mark.parametrize(("stinger", "h", "where"), [
    (S67_STINGER, 1e6, "above"), (S67_STINGER, 3e4, "below"), (S67_STINGER, 3e3, "below"),
    (SHORT_STINGER, 3e4, "beyond")])
def test_slay_liftoff_where_the_catenary_is_tangent_to_the_stinger(stinger, h, where):
    """Lift-off is the reference catenary's tangent point, one flexural
    length sqrt(EI/Te) up the curve (a soft pipe, so within the stinger).
    Below the tip the guess leaves from the tip and says how far below; more
    than tuning.TIP_PAST_REACH stinger z ranges below it, it leaves from the
    tip lifting off (no distance)."""
    case = pf.load_case(EXAMPLES / "s67.toml").with_changes(
        {"lay.top_tension": None, "lay.bottom_tension": h,
         "pipe.youngs_modulus": 2e8, "pipe.extensible": False, "lay.stinger": stinger})
    st = case.lay.stinger
    (z_l, z_u) = st.lower[1], st.upper[1]
    z_c = _tangent_point(case, h)
    lam = math.sqrt(case.pipe.bending_stiffness
                    / _reference(case, h, float(st.height(z_c)))["T_top"])
    z_lo, h_lo, past = slay_liftoff(case)
    assert h_lo == pytest.approx(h, rel=1e-12)
    if where == "above":
        assert z_c > z_l
        assert float(st.arc_length(z_c, z_lo)) == pytest.approx(lam, rel=1e-6)
        assert past is None
    elif where == "below":
        assert z_l - TIP_PAST_REACH * (z_u - z_l) < z_c < z_l
        assert z_lo == z_l
        assert past == pytest.approx(float(st.arc_length(z_c, z_l)) - lam, rel=1e-6)
    else:
        assert z_c < z_l - TIP_PAST_REACH * (z_u - z_l)
        assert (z_lo, past) == (z_l, None)


@pytest.mark.parametrize("extra", [5.0, 40.0])
def test_slay_pipe_length_lands_the_lower_end_at_the_origin(extra):
    """S-lay with a given pipe length: laid pipe, the reference catenary to
    lift-off's height and the stinger's arc from there add up to it, with the
    lower end at z = 0 (the laid pipe as long as touchdown's z)."""
    base = pf.load_case(EXAMPLES / "s67.toml")
    st = base.lay.stinger
    length = st.upper[1] + extra + 30.0
    case = base.with_changes({"lay.top_tension": None, "lay.pipe_length": length})
    g = first_guess(case, None)
    ref = _reference(case, g.cat.h, float(st.height(g.liftoff_z)))
    arc = float(st.arc_length(g.liftoff_z, st.upper[1]))
    assert g.laid == pytest.approx(length - ref["suspended_length"] - arc, abs=1e-9 * length)
    assert g.liftoff_z - ref["horizontal_span"] == pytest.approx(g.laid, abs=1e-6)


@pytest.mark.parametrize("lam_over_span", [0.01, 0.3, 30.0])
def test_beam_span_solves_the_beam_column(lam_over_span):
    """The beam-column guess of a bending-dominated J-lay solves
    EI y'''' - h y'' = -w (the second difference of EI y'' - h y is -w),
    touches down with y = y' = y'' = 0 and reaches the top's height with
    y'' = 0 (pinned); its span tends to the weightless beam's
    (24 EI x_top / w)^(1/4) for lam >> L and to the catenary's
    lam + sqrt(2 h x_top / w) for lam << L (no overflow there)."""

    from pipelay_fast.engine.beam import BeamSpan

    w, x_top, ei = 600.0, 70.0, 2.7e12
    beam_span = (24.0 * ei * x_top / w) ** 0.25
    h = ei / (lam_over_span * beam_span) ** 2
    b = BeamSpan(h, w, w, 1e9, x_top, ei)
    xi = np.linspace(0.0, b.span, 4001)
    y, dy, ddy = b._y(xi)
    assert (y[0], dy[0], ddy[0]) == pytest.approx((0.0, 0.0, 0.0), abs=1e-9 * x_top)
    assert y[-1] == pytest.approx(x_top, rel=1e-9)
    assert ddy[-1] == pytest.approx(0.0, abs=1e-9 * np.abs(ddy).max())
    # EI y'''' - h y'' + w = 0: the second difference of EI y'' - h y is -w
    q = ei * ddy - h * y
    d2 = (q[2:] - 2.0 * q[1:-1] + q[:-2]) / (xi[1] - xi[0]) ** 2
    assert d2 == pytest.approx(-w * np.ones_like(d2), rel=1e-3)
    lam = math.sqrt(ei / h)
    if lam_over_span > 1.0:
        assert b.span == pytest.approx(beam_span, rel=1e-2)
    elif lam_over_span < 0.1:
        assert b.span == pytest.approx(lam + math.sqrt(2.0 * h * x_top / w), rel=1e-2)


@pytest.mark.parametrize("rise", [-2.0, 1.5])
def test_seabed_span_on_a_level_profile_is_the_shallower_catenary(j125, rise):
    """A profile level at ``rise`` m above the reference level is a seabed
    that much shallower: the J-lay catenary from the top tension touches
    down at that height, and its span is the reference catenary's over the
    water depth and top height less ``rise``."""
    depth = j125.environment.water_depth
    x_top, z_top = j125.lay.top
    case = j125.with_changes({"seabed.stiffness": 1e6,
                              "seabed.profile": [[-500.0, depth - rise], [900.0, depth - rise]]})
    cat, x_td = seabed_span(case, free_span(case), bed_knots(case.seabed.profile, depth))
    w1, w2 = weights(case)
    ref = natural_catenary_two_weights(w1, w2, depth - rise, x_top - rise,
                                       T_top=case.lay.top_tension)
    assert x_td == pytest.approx(rise, abs=1e-12)
    assert cat.span == pytest.approx(ref["horizontal_span"], rel=1e-9)


@pytest.mark.parametrize("tilt", [-1.0, 1.0])
def test_seabed_span_touches_down_on_a_ramp(j125, tilt):
    """On a profile rising (or falling) 12 m over 600 m across the flat
    seabed's touchdown, the catenary touches down where the profile's
    height is its own (the reference catenary over the water depth and top
    height less it), to within the profile's slope there times the
    flexural length sqrt(EI/H), the guess's own error; the flat catenary's
    touchdown misses by more."""
    depth = j125.environment.water_depth
    x_top, z_top = j125.lay.top
    flat = free_span(j125)
    z_f = z_top - flat.span
    rows = [[z_f - 200.0, depth + 4.0 * tilt], [z_f + 100.0, depth],
            [z_f + 400.0, depth - 8.0 * tilt]]
    case = j125.with_changes({"seabed.stiffness": 1e6, "seabed.profile": rows})
    cat, x_td = seabed_span(case, flat, bed_knots(rows, depth))
    w1, w2 = weights(case)
    ref = natural_catenary_two_weights(w1, w2, depth - x_td, x_top - x_td,
                                       T_top=case.lay.top_tension)
    knots = bed_knots(rows, depth)
    x_b, slope = bed_heights(knots, np.array([z_top - ref["horizontal_span"]]))
    enough = abs(slope[0]) * math.sqrt(case.pipe.bending_stiffness / ref["H"])
    assert abs(x_b[0] - x_td) <= enough
    x_flat = bed_heights(knots, np.array([z_f]))[0][0]
    assert abs(x_flat) > enough

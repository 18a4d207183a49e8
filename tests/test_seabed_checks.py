"""The vessel against the seabed's surface (:func:`pipelay_fast.input.surface.check_vessel`):
one check in the seabed frame after the frame and the trim, against the
flat seabed, the slope's plane or the profile, naming the key, its value as
given and the frame; and the seabed below the still water along the
modelled pipe (:func:`pipelay_fast.input.surface.check_water`)."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

import pipelay_fast as pf
from pipelay_fast.input.surface import check_water
from tests.helpers import load
from tests.reference.profile import profile_depth


def refused(name, **changes) -> str:
    with pytest.raises(ValueError) as info:
        load(name, **changes)
    return str(info.value)


def seabed_x(message: str) -> float:
    """The seabed's height x [m] the message names."""
    return float(re.search(r"puts? the seabed at x = (-?[0-9.e+-]+) m", message).group(1))


def test_a_top_on_the_flat_seabed_is_refused_a_tip_on_it_accepted():
    """The boundary: the top must hang above the seabed; a stinger tip may
    rest on it."""
    message = refused("j125", **{"lay.top": [0.0, 440.0]})
    assert message.startswith("lay.top = [0.0, 440.0] is not above the seabed: the seabed "
                              "is at x = 0 m in the seabed frame (lay.frame = 'seabed')")
    case = load("s67", **{"lay.stinger.lower": [0.0, 265.0]})
    assert case.lay.stinger.lower == (0.0, 265.0)
    message = refused("s67", **{"lay.stinger.lower": [-1e-9, 265.0]})
    assert message.startswith("lay.stinger.lower = [-1e-09, 265.0] is below the seabed")


@pytest.mark.parametrize("slope", [10.0, 25.0])
def test_a_tip_below_the_slope_is_refused_with_the_planes_height(slope):
    """S67's tip (41.5, 265) lies below the plane 265 tan(slope) (46.7 m at
    10 deg) though its top (72, 400) is above it (70.5 m at 10 deg)."""
    message = refused("s67", **{"seabed.slope_deg": slope})
    assert message.startswith("lay.stinger.lower = [41.5, 265.0] is below the seabed: "
                              f"seabed.slope_deg = {slope!r}")
    assert "at z = 265 m in the seabed frame" in message
    assert seabed_x(message) == pytest.approx(265.0 * math.tan(math.radians(slope)), rel=1e-5)


def test_a_waterline_tip_below_the_slope_names_the_waterline_heights():
    """In the waterline frame the seabed's height is given as an elevation:
    265 tan(10 deg) - 67 = -20.27 m, the tip as given (-25.5 m)."""
    case = load("s67")
    tables = case.to_dict()
    tables["lay"]["frame"] = "waterline"
    del tables["lay"]["top"]
    tables["lay"]["stinger"]["lower"] = [41.5 - 67.0, 265.0]
    tables["lay"]["stinger"]["upper"] = [72.0 - 67.0, 400.0]
    tables["seabed"]["slope_deg"] = 10.0
    with pytest.raises(ValueError) as info:
        pf.load_case(tables)
    message = str(info.value)
    assert message.startswith("lay.stinger.lower = [-25.5, 265.0] is below the seabed")
    assert "environment.water_depth = 67.0 m" in message and "'waterline'" in message
    assert seabed_x(message) == pytest.approx(265.0 * math.tan(math.radians(10.0)) - 67.0,
                                              rel=1e-5)


def test_a_top_below_the_rising_slope_is_refused():
    """J125's top (130, 440) against 20 deg: the plane is 440 tan(20 deg) =
    160.1 m there."""
    base = load("j125_2d").with_changes({"environment.current.speed": 0.0})
    with pytest.raises(ValueError) as info:
        base.with_changes({"seabed.slope_deg": 20.0})
    message = str(info.value)
    assert message.startswith("lay.top = [130.0, 440.0] is not above the seabed")
    assert seabed_x(message) == pytest.approx(440.0 * math.tan(math.radians(20.0)), rel=1e-5)


def test_a_roller_below_the_slope_is_refused_the_lowest_named():
    case = load("s67_rollers")
    last = [float(v) for v in case.given_lay.stinger.rollers[-1]]
    message = refused("s67_rollers", **{"seabed.slope_deg": 10.0})
    assert message.startswith(f"lay.stinger.rollers[22] = {last} is below the seabed")
    assert seabed_x(message) == pytest.approx(last[1] * math.tan(math.radians(10.0)), rel=1e-5)


def test_a_tip_below_a_profile_is_refused():
    """A profile 20 m deep from z = 200 to 300 m puts the seabed at 67 - 20
    = 47 m under S67's tip (41.5 m): constant between equal knots."""
    message = refused("s67", **{"seabed.stiffness": 1e6,
                                "seabed.profile": [[200.0, 20.0], [300.0, 20.0]]})
    assert message.startswith("lay.stinger.lower = [41.5, 265.0] is below the seabed: "
                              "seabed.profile and environment.water_depth = 67.0 m put")
    assert seabed_x(message) == pytest.approx(47.0, rel=1e-12)
    assert load("s67", **{"seabed.stiffness": 1e6,
                          "seabed.profile": [[200.0, 30.0], [300.0, 30.0]]}).seabed.profile


def test_a_trim_that_lowers_the_tip_below_the_seabed_names_the_trim_and_the_point():
    """10 deg about (70, 1000) lowers S67's tip to (41.5 - 70) cos + (265 -
    1000) sin + 70 < 0; the message names the tip as given and the trim."""
    message = refused("s67", **{"lay.trim_deg": 10.0, "lay.trim_pivot": [70.0, 1000.0]})
    t = math.radians(10.0)
    x = 70.0 + math.cos(t) * (41.5 - 70.0) + math.sin(t) * (265.0 - 1000.0)
    z = 1000.0 + math.cos(t) * (265.0 - 1000.0) - math.sin(t) * (41.5 - 70.0)
    turned = re.search(r"to \[(-?[0-9.e+-]+), (-?[0-9.e+-]+)\]", message)
    assert message.startswith("lay.stinger.lower = [41.5, 265.0], turned by lay.trim_deg = "
                              "10.0 deg about lay.trim_pivot = [70.0, 1000.0]")
    assert float(turned.group(1)) == pytest.approx(x, rel=1e-12)
    assert float(turned.group(2)) == pytest.approx(z, rel=1e-12)


# ------------------------------------------------------------------ the water


def test_a_slope_reaching_the_water_along_the_mesh_is_refused():
    """-5 deg through z = 0 reaches 67 m at z = 67 / tan(-5 deg) = -765.8 m;
    a mesh from -1500 m is refused at its lowest node, 1500 tan(5 deg) =
    131.2 m."""
    case = load("s67", **{"seabed.slope_deg": -5.0})
    with pytest.raises(ValueError) as info:
        check_water(case, np.linspace(-1500.0, 400.0, 50))
    message = str(info.value)
    assert message.startswith("seabed.slope_deg = -5.0")
    assert "at z = -1500 m" in message
    assert seabed_x(message) == pytest.approx(1500.0 * math.tan(math.radians(5.0)), rel=1e-5)
    cross = float(re.search(r"water level at z = (-?[0-9.e+-]+) m", message).group(1))
    assert cross == pytest.approx(67.0 / math.tan(math.radians(-5.0)), rel=1e-5)
    check_water(case, np.linspace(-700.0, 400.0, 50))  # short of the crossing


def test_a_profile_never_reaches_the_water():
    """Positive depths and an interpolant that does not overshoot them: a
    profile 1 mm deep at its shallowest stays below the water."""
    case = load("s67", **{"seabed.stiffness": 1e6,
                          "seabed.profile": [[-500.0, 0.001], [-300.0, 80.0],
                                                             [-100.0, 0.001], [0.0, 67.0]]})
    check_water(case, np.linspace(-1000.0, 400.0, 2001))


def test_s67_on_a_falling_slope_with_a_current_is_refused_by_the_solve():
    """The slope2 helper's case: S67 3D with 1 m/s of current on -5 deg laid
    its lower end 58 m above the water and solved "ok"; now the solve
    refuses the mesh, naming the key."""
    case = load("s67_3d", **{"seabed.slope_deg": -5.0})
    with pytest.raises(ValueError, match=r"seabed\.slope_deg = -5\.0 .* at or above the still "
                                         r"water level"):
        pf.solve(case)


def test_a_generated_roller_turned_below_the_slope_names_the_path_and_the_trim():
    """A radius path's rollers are named by their index; turned by a trim,
    the message gives the turned point and the plane's height at its z."""
    case = load("s67_radius")
    last = case.given_lay.roller_positions()[-1].tolist()
    message = refused("s67_radius", **{"seabed.slope_deg": 10.0, "lay.trim_deg": 1.0,
                                       "lay.trim_pivot": [70.0, 400.0]})
    n = case.lay.roller_count - 1
    assert message.startswith(f"lay.stinger (generated rollers)[{n}] = {last}, turned by "
                              "lay.trim_deg = 1.0 deg about lay.trim_pivot = [70.0, 400.0]")
    z = float(re.search(r"to \[[^,]+, (-?[0-9.e+-]+)\]", message).group(1))
    assert seabed_x(message) == pytest.approx(z * math.tan(math.radians(10.0)), rel=1e-5)


# ------------------------------------------------------------------ the stinger's length


def shoal(top: float, z: float = 300.0) -> list[list[float]]:
    """A profile for S67 (67 m of water) level but for a shoal 20 m wide whose
    crest, at ``z`` [m], is ``top`` [m] above the reference seabed."""
    return [[200.0, 67.0], [z - 10.0, 67.0], [z, 67.0 - top], [z + 10.0, 67.0], [500.0, 67.0]]


def parabola_x(case, u):
    """The height x [m] at z = ``u`` [m] of the case's quadratic stinger as
    given (seabed frame, untrimmed), from its keys: x = x_l + m (u - z_l) +
    a (u - z_l) (u - z_u), m the chord's slope."""
    st = case.given_lay.stinger
    (x_l, z_l), (x_u, z_u) = st.lower, st.upper
    return x_l + (x_u - x_l) / (z_u - z_l) * (u - z_l) + st.a * (u - z_l) * (u - z_u)


def stinger_clearance(case, rows, deg=0.0, pivot=(0.0, 0.0)):
    """The least height [m] of the case's stinger (turned by ``deg`` about
    ``pivot``) above the profile ``rows`` (scipy's PCHIP in 67 m of water),
    densely sampled strictly between its ends."""
    st = case.given_lay.stinger
    u = np.linspace(st.lower[1], st.upper[1], 400001)[1:-1]
    x = parabola_x(case, u)
    t = math.radians(deg)
    xt = pivot[0] + math.cos(t) * (x - pivot[0]) + math.sin(t) * (u - pivot[1])
    zt = pivot[1] + math.cos(t) * (u - pivot[1]) - math.sin(t) * (x - pivot[0])
    return float(np.min(xt - (67.0 - profile_depth(rows, zt))))


def test_a_shoal_under_the_stingers_middle_is_refused_naming_the_stinger():
    """S67's stinger is 53.6 m above the reference seabed at z = 300 m. A
    shoal there rising to 54 m, level seabed (x = 0) under the tip (41.5 m at
    265 m) and the upper end (72 m at 400 m), cuts the stinger between its
    ends: refused, naming the stinger's keys and a point below the seabed
    (the heights checked here with the parabola and scipy's PCHIP). A crest
    0.1 m lower clears the stinger by less than 0.1 m (the dense check
    here) and is accepted."""
    base = load("s67", **{"seabed.stiffness": 1e6})
    rows = shoal(54.0)
    assert stinger_clearance(base, rows) < 0.0
    message = refused("s67", **{"seabed.stiffness": 1e6, "seabed.profile": rows})
    assert message.startswith("lay.stinger.a = -0.0012 with lay.stinger.lower = [41.5, 265.0] "
                              "and lay.stinger.upper = [72.0, 400.0] passes, between its ends, "
                              "at x = ")
    assert "seabed.profile and environment.water_depth = 67.0 m put" in message
    z = float(re.search(r"m at z = (-?[0-9.e+-]+) m in the", message).group(1))
    x = float(re.search(r"between its ends, at x = (-?[0-9.e+-]+) m", message).group(1))
    assert 290.0 < z < 310.0
    # (to the message's 6 digits: z to 5e-4 m, on slopes up to 0.3 and 8)
    assert x == pytest.approx(parabola_x(base, z), abs=1e-3)
    assert seabed_x(message) == pytest.approx(67.0 - float(profile_depth(rows, z)), abs=1e-2)
    assert seabed_x(message) > x
    clear = shoal(53.6074 - 0.1)
    assert 0.0 < stinger_clearance(base, clear) < 0.1
    assert load("s67", **{"seabed.stiffness": 1e6, "seabed.profile": clear}).seabed.profile


def test_a_trim_that_lowers_the_stinger_onto_a_shoal_is_refused_naming_it():
    """The shoal's crest 0.3 m under the untrimmed S67 stinger at z = 300 m;
    a trim of +1 deg about (70, 330) lowers the stinger there by about
    30 sin(1 deg) = 0.52 m onto it: refused, naming the trim; the point named lies on the
    vessel's parabola turned by the trim (turned back here)."""
    rows = shoal(53.6074 - 0.3)
    base = load("s67", **{"seabed.stiffness": 1e6, "seabed.profile": rows})
    assert stinger_clearance(base, rows) > 0.2
    trim = {"lay.trim_deg": 1.0, "lay.trim_pivot": [70.0, 330.0]}
    assert stinger_clearance(base, rows, 1.0, (70.0, 330.0)) < 0.0
    message = refused("s67", **{"seabed.stiffness": 1e6, "seabed.profile": rows, **trim})
    assert message.startswith("lay.stinger.a = -0.0012 with lay.stinger.lower = [41.5, 265.0] "
                              "and lay.stinger.upper = [72.0, 400.0], turned by lay.trim_deg = "
                              "1.0 deg about lay.trim_pivot = [70.0, 330.0] passes, between its "
                              "ends, at x = ")
    z = float(re.search(r"m at z = (-?[0-9.e+-]+) m in the", message).group(1))
    x = float(re.search(r"between its ends, at x = (-?[0-9.e+-]+) m", message).group(1))
    t = math.radians(-1.0)  # back into the vessel's frame
    xv = 70.0 + math.cos(t) * (x - 70.0) + math.sin(t) * (z - 330.0)
    zv = 330.0 + math.cos(t) * (z - 330.0) - math.sin(t) * (x - 70.0)
    assert xv == pytest.approx(parabola_x(base, zv), abs=1e-3)
    assert seabed_x(message) == pytest.approx(67.0 - float(profile_depth(rows, z)), abs=1e-2)
    assert seabed_x(message) > x

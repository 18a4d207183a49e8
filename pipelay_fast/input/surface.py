"""The seabed's surface in the seabed frame (the frame a case holds its lay
in, :mod:`.frame`), and the checks of the geometry against it.

The surface's height x_b(z) [m] above the reference level x = 0, where
``environment.water_depth`` d is measured, is 0 on the flat seabed, the
plane (z - slope_origin) tan(slope_deg) on a slope, and d - depth(z) on a
``seabed.profile`` (:mod:`.profile`); :func:`heights` gives it.

:func:`check_vessel` refuses a vessel whose geometry, in the seabed frame
and trimmed (what the engine solves), lies below the surface: the top
(``lay.top``, a quadratic stinger's ``lay.stinger.upper``), the stinger's
tip (``lay.stinger.lower``) and every roller. The message names the key,
its value as given, the frame it was given in, the trim that turned it and
what puts the seabed there. A point exactly on the surface: the top is
refused (the pipe's upper end must hang above the seabed, or there is no
lay), a tip or a roller is accepted (a support resting on the seabed still
holds the pipe from below; the pipe then touches down where it leaves it).
A quadratic stinger between its tip and upper end is not checked point by
point: concave down (or straight) against a plane, it lies above the plane
where both its ends do (against a profile's hump it may not).

:func:`check_water` refuses a seabed that reaches the still water level
(x_b >= d) at a z of the modelled pipe, which only the engine knows (the
laid length is its choice): it checks the nodes of a mesh. Only a slope can
fail it: a profile's depths are positive and its interpolant does not
overshoot them (:mod:`.profile`), so x_b < d everywhere.
"""

from __future__ import annotations

import math

import numpy as np

from .profile import bed_heights, bed_knots


def heights(seabed, depth: float, z) -> np.ndarray:
    """The surface's height x_b [m] above the reference level at ``z`` [m]
    (any shape) of ``seabed`` (:class:`.environment.Seabed`) in ``depth``
    [m] of water (``environment.water_depth``)."""
    z = np.asarray(z, dtype=float)
    if seabed.profile is not None:
        return bed_heights(bed_knots(seabed.profile, depth), z)[0]
    if seabed.slope_deg == 0.0:
        return np.zeros(z.shape)
    return (z - seabed.slope_origin) * math.tan(seabed.slope)


def _cause(case) -> str:
    """The keys that place the seabed, as given."""
    bed, depth = case.seabed, case.environment.water_depth
    keys = []
    if bed.profile is not None:
        keys.append("seabed.profile")
    elif bed.slope_deg != 0.0:
        keys.append(f"seabed.slope_deg = {bed.slope_deg!r} with seabed.slope_origin = "
                    f"{bed.slope_origin!r} m")
    if case.given_lay.frame != "seabed" or bed.profile is not None:
        keys.append(f"environment.water_depth = {depth!r} m")
    return " and ".join(keys)


def _points(case):
    """(key, value as given, seabed-frame point, strict) of the vessel's
    points, the rollers from the last (the lowest) up, then the tip, then
    the top; ``strict``: a point on the surface is refused too."""
    given, lay = case.given_lay, case.lay
    points = []
    if lay.has_rollers:
        named = given.stinger.rollers is not None
        shown, placed = given.roller_positions(), lay.roller_positions()
        for i in range(lay.roller_count - 1, -1, -1):
            key = f"lay.stinger.rollers[{i}]" if named else f"lay.stinger (generated rollers)[{i}]"
            points.append((key, shown[i].tolist(), placed[i], False))
    elif lay.curve is not None:
        points.append(("lay.stinger.lower", list(given.stinger.lower), lay.curve.lower, False))
    if lay.curve is not None:
        points.append(("lay.stinger.upper", list(given.stinger.upper), lay.top, True))
    else:
        points.append(("lay.top", list(given.top), lay.top, True))
    return points


def check_vessel(case) -> None:
    """Refuse (ValueError) a ``case`` whose vessel's top, stinger tip or a
    roller lies below the seabed's surface, the top on it as well (the
    module docstring), naming the key and its value as given."""
    given, depth = case.given_lay, case.environment.water_depth
    shift = depth if given.frame == "waterline" else 0.0  # seabed frame -> given frame
    points = _points(case)
    surface = heights(case.seabed, depth, [float(point[1]) for _key, _value, point, _s in points])
    for (key, value, (x, z), strict), x_b in zip(points, surface.tolist(), strict=True):
        if not (x < x_b or (strict and x <= x_b)):
            continue
        turned = ""
        if given.trim_deg != 0.0:
            turned = (f", turned by lay.trim_deg = {given.trim_deg!r} deg about lay.trim_pivot "
                      f"= {list(given.trim_pivot)} to {[float(x) - shift, float(z)]},")
        verb = "is not above" if strict else "is below"
        cause = _cause(case)
        puts = "put" if " and " in cause else "puts"
        where = (f"{cause} {puts} the seabed at x = {x_b - shift:.6g} m" if cause
                 else "the seabed is at x = 0 m")
        if case.seabed.slope_deg != 0.0 or case.seabed.profile is not None:
            where += f" at z = {float(z):.6g} m"
        raise ValueError(f"{key} = {value}{turned} {verb} the seabed: {where} in the "
                         f"{given.frame} frame (lay.frame = {given.frame!r})")


def check_water(case, z) -> None:
    """Refuse (ValueError) a seabed whose surface reaches the still water
    level (x_b >= ``environment.water_depth``) at any of the points ``z``
    [m] (a mesh's nodes), naming the keys, the highest such point and,
    on a slope, the z where the plane crosses the water level."""
    bed, depth = case.seabed, case.environment.water_depth
    if bed.slope_deg == 0.0 and bed.profile is None:
        return
    z = np.asarray(z, dtype=float)
    x_b = heights(bed, depth, z)
    k = int(np.argmax(x_b))
    if x_b[k] < depth:
        return
    span = f"the modelled pipe's z from {z.min():.6g} m to {z.max():.6g} m"
    if bed.profile is not None:
        head = "seabed.profile"
    else:
        cross = bed.slope_origin + depth / math.tan(bed.slope)
        head = (f"seabed.slope_deg = {bed.slope_deg!r} with seabed.slope_origin = "
                f"{bed.slope_origin!r} m (the plane crosses the still water level at "
                f"z = {cross:.6g} m)")
    raise ValueError(f"{head} puts the seabed at x = {x_b[k]:.6g} m at z = {z[k]:.6g} m, at "
                     f"or above the still water level (environment.water_depth = {depth!r} m), "
                     f"within {span}: the seabed must lie below the water along the modelled "
                     "pipe (a smaller slope, another seabed.slope_origin or a shorter "
                     "solver.laid_length)")

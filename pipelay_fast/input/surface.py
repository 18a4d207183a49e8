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
A quadratic stinger is also checked along its length, strictly between its
ends (:func:`_dip`): concave down or straight, turned or not, it lies above
its chord between any two of its points, and the surface is monotone
between two knots of a profile (its interpolant's) and along a plane, so on
a stretch [p, q] with neither end below the surface the clearance is at
least min(x(p), x(q)) - max(x_b(p), x_b(q)) (x(z) the stinger's height).
Stretches where that bound is negative are halved until it is not, a point
of the curve below the surface is found, or the stretch is shorter than the
round-off of its z (``limits.ROUNDOFF``): exact to round-off, whatever the
profile's humps under the stinger.

:func:`check_water` refuses a seabed that reaches the still water level
(x_b >= d) at a z of the modelled pipe, which only the engine knows (the
laid length is its choice): it checks the nodes of a mesh. Only a slope can
fail it: a profile's depths are positive and its interpolant does not
overshoot them (:mod:`.profile`), so x_b < d everywhere.
"""

from __future__ import annotations

import math

import numpy as np

from .limits import ROUNDOFF
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


def _dip(case) -> tuple[float, float, float] | None:
    """(z, x, x_b) [m], seabed frame, of a point of the quadratic stinger's
    curve strictly between its ends that lies below the surface (the
    lowest such point sampled, the module docstring's halving), or None;
    its ends are checked as points (:func:`_points`)."""
    curve, bed, depth = case.lay.curve, case.seabed, case.environment.water_depth
    if curve is None:
        return None
    z_l, z_u = float(curve.lower[1]), float(curve.upper[1])
    knots = [] if bed.profile is None else [z for z, _d in bed.profile if z_l < z < z_u]
    edges = np.array([z_l, *knots, z_u])
    p, q = edges[:-1], edges[1:]
    shortest = ROUNDOFF * max(abs(z_l), abs(z_u))
    while p.size:
        z = np.concatenate([p, q])
        x, x_b = np.asarray(curve.height(z), dtype=float), heights(bed, depth, z)
        k = int(np.argmin(x - x_b))
        if x[k] < x_b[k]:
            return float(z[k]), float(x[k]), float(x_b[k])
        n = p.size
        bound = np.minimum(x[:n], x[n:]) - np.maximum(x_b[:n], x_b[n:])
        keep = (bound < 0.0) & (q - p > shortest)
        p, q = p[keep], q[keep]
        middle = 0.5 * (p + q)
        p, q = np.concatenate([p, middle]), np.concatenate([middle, q])
    return None


def _refuse(case, head: str, x_b: float, z: float, shift: float) -> None:
    """Raise the ValueError of :func:`check_vessel`: ``head`` (the key, its
    value as given and what it does), then where the seabed is, at ``x_b``
    [m] and ``z`` [m] in the seabed frame, and the frame."""
    frame = case.given_lay.frame
    cause = _cause(case)
    puts = "put" if " and " in cause else "puts"
    where = (f"{cause} {puts} the seabed at x = {x_b - shift:.6g} m" if cause
             else "the seabed is at x = 0 m")
    if case.seabed.slope_deg != 0.0 or case.seabed.profile is not None:
        where += f" at z = {z:.6g} m"
    raise ValueError(f"{head} the seabed: {where} in the {frame} frame (lay.frame = {frame!r})")


def _trim_words(given) -> str:
    """How the trim turned the vessel's geometry, as given ('' untrimmed)."""
    if given.trim_deg == 0.0:
        return ""
    return (f", turned by lay.trim_deg = {given.trim_deg!r} deg about lay.trim_pivot = "
            f"{list(given.trim_pivot)}")


def check_vessel(case) -> None:
    """Refuse (ValueError) a ``case`` whose vessel's top, stinger tip or a
    roller lies below the seabed's surface, the top on it as well, or whose
    quadratic stinger passes below it between its ends (the module
    docstring), naming the keys and their values as given."""
    given, depth = case.given_lay, case.environment.water_depth
    shift = depth if given.frame == "waterline" else 0.0  # seabed frame -> given frame
    points = _points(case)
    surface = heights(case.seabed, depth, [float(point[1]) for _key, _value, point, _s in points])
    for (key, value, (x, z), strict), x_b in zip(points, surface.tolist(), strict=True):
        if not (x < x_b or (strict and x <= x_b)):
            continue
        turned = _trim_words(given)
        if turned:
            turned += f" to {[float(x) - shift, float(z)]},"
        verb = "is not above" if strict else "is below"
        _refuse(case, f"{key} = {value}{turned} {verb}", x_b, float(z), shift)
    dip = _dip(case)
    if dip is not None:
        z, x, x_b = dip
        st = given.stinger
        _refuse(case, f"lay.stinger.a = {st.a!r} with lay.stinger.lower = {list(st.lower)} and "
                f"lay.stinger.upper = {list(st.upper)}{_trim_words(given)} passes, between its "
                f"ends, at x = {x - shift:.6g} m, below", x_b, z, shift)


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

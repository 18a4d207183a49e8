"""The vessel's trim (``lay.trim_deg`` about ``lay.trim_pivot``): the lay's
vessel geometry turned as one rigid body.

A trim t turns ``lay.top``, the firing line ``lay.top_angle``, the quadratic
stinger and the rollers about the pivot (xp, zp), counter-clockwise seen
with z to the right and x up: a point (x', z') goes to
x - xp = cos(t) (x' - xp) + sin(t) (z' - zp), z - zp = cos(t) (z' - zp) -
sin(t) (x' - xp), and every angle above horizontal grows by t. The stinger
(the stern) lies towards -z, where the pipe leaves the vessel, so t > 0
lowers it: the stern down. :func:`trimmed` builds the turned lay once the
case's lay is in the seabed frame (:func:`.frame.to_seabed`, so that a
waterline case and its seabed-frame twin turn the same numbers); a trim of
0 returns the lay itself.

The trimmed lay is refused, naming ``lay.trim_deg``, where its geometry
leaves the range the model solves (the checks the untrimmed geometry
passes): a stinger whose upper end no longer lies above and ahead of its
tip, or whose tangent reaches 90 deg from horizontal (at its tip, the
steepest point of a concave-down curve, or its upper end); a firing line
``lay.top_angle`` + trim outside (0, 90] deg; rollers no longer falling
from one to the next in x and z (:class:`.lay.Lay`'s check). The case
then checks the trimmed geometry against the seabed as it does an
untrimmed one (:func:`.surface.check_vessel`, its message naming the
trim). No other bound: a trim is whatever keeps the vessel's geometry a
lay.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from . import parabola
from .validate import fail, vectorised


class TrimmedStinger:
    """A quadratic stinger (:class:`.lay.Stinger`, ``vessel``, in the seabed
    frame) turned by ``turn`` [rad] about ``pivot`` (x, z) [m], with the
    methods of a :class:`.lay.Stinger` in the global frame: ``lower`` and
    ``upper`` the turned ends, and ``a``, ``b``, ``c`` the coefficients of
    the parabola in the frame turned by ``turn`` about the origin (layout
    ``ST_*``; :func:`.parabola.turned`), where the vessel's parabola is
    moved by R(-t) p - p, p the pivot."""

    __slots__ = ("vessel", "turn", "pivot", "a", "b", "c", "lower", "upper")

    def __init__(self, vessel, turn: float, pivot):
        self.vessel, self.turn, self.pivot = vessel, float(turn), tuple(pivot)
        cs, sn = math.cos(turn), math.sin(turn)
        xp, zp = self.pivot
        dx, dz = (cs * xp - sn * zp) - xp, (sn * xp + cs * zp) - zp
        (x_l, z_l), (x_u, z_u) = vessel.lower, vessel.upper
        a = vessel.a
        z_l, z_u, x_l, x_u = z_l + dz, z_u + dz, x_l + dx, x_u + dx
        self.a = a
        self.b = (x_u - x_l) / (z_u - z_l) - a * (z_u + z_l)
        self.c = x_l - a * z_l**2 - self.b * z_l
        self.lower = parabola.rotate(vessel.lower, turn, pivot)
        self.upper = parabola.rotate(vessel.upper, turn, pivot)

    def _key(self):
        return (self.vessel, self.turn, self.pivot)

    def __eq__(self, other):
        return isinstance(other, TrimmedStinger) and self._key() == other._key()

    def __hash__(self):
        return hash(self._key())

    def __repr__(self):
        return f"TrimmedStinger({self.vessel!r}, turn={self.turn!r}, pivot={self.pivot!r})"

    def _at(self, z):
        """:func:`.parabola.turned` at z [m]: (x, dx/dz, d2x/dz2, u)."""
        return parabola.turned(self.a, self.b, self.c, self.turn, z)

    def _z_of(self, u):
        """z [m] of the point of the vessel's parabola at its abscissa ``u``
        [m], turned (the pivot is in the coefficients)."""
        return math.cos(self.turn) * u - math.sin(self.turn) * ((self.a * u + self.b) * u
                                                                + self.c)

    def height(self, z):
        """Stinger height x(z) [m] at z [m]; vectorised."""
        return vectorised(z, lambda z: self._at(z)[0])

    def slope(self, z):
        """dx/dz [-] at z [m]; vectorised."""
        return vectorised(z, lambda z: self._at(z)[1])

    def angle(self, z):
        """Tangent angle from horizontal [deg] at z [m]; vectorised."""
        return vectorised(z, lambda z: np.degrees(np.arctan(self._at(z)[1])))

    def curvature(self, z):
        """Signed curvature d(theta)/ds [1/m] at z [m] (negative: hogging),
        the vessel's parabola's at the same point; vectorised."""
        def kappa(z):
            p = 2.0 * self.a * self._at(z)[3] + self.b
            return 2.0 * self.a / (1.0 + p * p) ** 1.5
        return vectorised(z, kappa)

    def arc_length(self, z0: float, z1):
        """The curve's arc length [m] from z0 to z1 [m], negative when z1 <
        z0: the turned frame's (:func:`.parabola.arc`); vectorised in z1."""
        u0 = float(self._at(z0)[3])
        return parabola.arc(self.a, self.b, u0, self._at(np.asarray(z1, dtype=float))[3])

    def z_at_arc(self, z0: float, s):
        """z [m] where the curve's arc length from z0 [m] is ``s`` [m]
        (negative: towards lower z); vectorised in s."""
        return self._z_of(parabola.at_arc(self.a, self.b, float(self._at(z0)[3]), s))

    def level_z(self) -> float:
        """z [m] where the curve is level: the turned frame's slope
        p = -tan(turn) there."""
        return self._z_of((-math.tan(self.turn) - self.b) / (2.0 * self.a))

    def seabed_z(self) -> float:
        """z [m] where the curve continued below the tip meets x = 0: the
        root of cos(t) (a u^2 + b u + c) + sin(t) u = 0 on the branch where the
        curve rises, 2 a u cos(t) + b cos(t) + sin(t) = +sqrt(disc), in the form
        without cancellation (the tip above x = 0: a real root below it)."""
        cs, sn = math.cos(self.turn), math.sin(self.turn)
        return self._z_of(float(parabola.root(-cs * self.a, -(cs * self.b + sn), -cs * self.c)))

    def support_row(self) -> np.ndarray:
        """Its row of the supports' table (layout ``ST_*``: a, b, c, zL, zU, turn)."""
        return np.array([self.a, self.b, self.c, self.lower[1], self.upper[1], self.turn])


def _angle(key: str, value, turn_deg: float):
    """A firing line's angle [deg] turned by ``turn_deg``; "pinned" and None stay."""
    if value is None or isinstance(value, str):
        return value
    turned = value + turn_deg
    if not 0.0 < turned <= 90.0:
        fail("lay.trim_deg", turn_deg, f"turns {key} = {value!r} deg to {turned:.6g} deg, "
             "outside (0, 90] deg")
    return turned


def _check_curve(st: TrimmedStinger, trim_deg: float) -> None:
    """Refuse a turned stinger that is no longer a lay's (the module docstring)."""
    (x_l, z_l), (x_u, z_u) = st.lower, st.upper
    if not (z_u > z_l and x_u > x_l):
        fail("lay.trim_deg", trim_deg, f"turns the stinger's upper end to {[x_u, z_u]} "
             f"and its tip to {[x_l, z_l]}: the upper end must lie above and ahead of the tip")
    v = st.vessel
    tip, top = (float(v.angle(v.lower[1])) + trim_deg, float(v.angle(v.upper[1])) + trim_deg)
    if not (tip < 90.0 and top > -90.0):
        fail("lay.trim_deg", trim_deg, f"turns the stinger's tangent to {tip:.6g} deg at its "
             f"tip and {top:.6g} deg at its upper end: it must stay within 90 deg of horizontal")


def trimmed(lay):
    """``lay`` (seabed frame) with its trim applied (the module docstring):
    the top, firing line, stinger and rollers turned by ``lay.trim_deg``
    about ``lay.trim_pivot``, the trim then 0; the lay itself at trim 0."""
    if lay.trim_deg == 0.0:
        return lay
    turn, pivot = math.radians(lay.trim_deg), lay.trim_pivot
    changes = {"trim_deg": 0.0, "trim_pivot": None,
               "top_angle": _angle("lay.top_angle", lay.top_angle, lay.trim_deg)}
    st = lay.stinger
    if lay.has_rollers:
        pts = [parabola.rotate(p, turn, pivot) for p in lay.roller_positions()]
        changes["stinger"] = dataclasses.replace(
            st, rollers=tuple(pts), radius=None, arc_length=None, spacing=None,
            straight_length=0.0, height_step=None, height_shift=0.0, shifted=None)
    elif st is not None:
        turned = TrimmedStinger(st, turn, pivot)
        _check_curve(turned, lay.trim_deg)
        changes["stinger"] = turned
        changes["top"] = turned.upper
    if "top" not in changes:
        changes["top"] = parabola.rotate(lay.top, turn, pivot)
    try:
        return dataclasses.replace(lay, **changes)
    except ValueError as err:
        raise ValueError(f"lay.trim_deg = {lay.trim_deg!r} turns the vessel's geometry "
                         f"about lay.trim_pivot = {list(pivot)} into one refused: {err}") from None

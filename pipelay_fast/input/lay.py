"""The ``lay`` table: the lay method, the top, the tensions and the
stinger (``lay.stinger``: a quadratic curve or a roller stinger,
:mod:`.rollers`), validated on construction; a trim turns them
(:mod:`.trim`). Heights ``x`` are measured from the seabed, or from the still
water level with ``lay.frame = "waterline"`` (:mod:`.frame`); ``z`` along the
lay."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import parabola
from .frame import FRAMES
from .limits import MAX_STINGER_TURN, ROUNDOFF
from .rollers import RollerStinger
from .trim import TrimmedStinger
from .validate import (
    assign,
    choice,
    fail,
    instance,
    set_numbers,
    vector,
    vectorised,
)

METHODS = ("S", "J")


@dataclass(frozen=True, slots=True)
class Stinger:
    """Rigid stinger x = a z^2 + b z + c on z_L <= z <= z_U, table ``[lay.stinger]``.

    Attributes
    ----------
    a : float
        Curvature parameter [1/m]; d^2x/dz^2 = 2a. Concave down (a < 0), or a
        straight ramp (a = 0).
    lower, upper : (float, float)
        End points (x, z) [m]: the tip (x_L, z_L) and the vessel end (x_U, z_U);
        b [-] and c [m] follow from them. x in the frame of ``lay.frame``
        (above the seabed by default).

    The geometry is checked up front: a concave-up stinger (a > 0) would hold
    the pipe at its ends only, not along the one contiguous stretch the model
    solves for; the upper end must lie above the tip (z_U > z_L, x_U > x_L;
    with a <= 0 the whole stinger is then above its tip; the case checks
    it against the seabed along its length, :func:`.surface.check_vessel`);
    and the stinger may turn the pipe by at most 90 deg between its ends (tangent angle
    at the tip minus that at the upper end): more, and the stinger overhangs,
    its tip pointing back under the pipe that comes from the vessel. The
    bending strain of a pipe conforming to it is checked with the pipe
    (:func:`pipelay_fast.input.limits.check_case`).
    """

    a: float
    lower: tuple[float, float]
    upper: tuple[float, float]

    def __post_init__(self):
        p = "lay.stinger"
        set_numbers(self, p, finite=("a",))
        assign(self, "lower", vector(f"{p}.lower", self.lower, 2))
        assign(self, "upper", vector(f"{p}.upper", self.upper, 2))
        (x_l, z_l), (x_u, z_u) = self.lower, self.upper
        if self.a > 0:
            fail(f"{p}.a", self.a, "must not be positive: the stinger must be concave down "
                 "(a < 0; a = 0 a straight ramp) to support an overbend")
        if z_l >= z_u:
            fail(f"{p}.lower", self.lower, f"must have z below that of {p}.upper = {self.upper!r}")
        if x_u <= x_l:
            fail(f"{p}.upper", self.upper, f"lies below the stinger's lower end "
                 f"{p}.lower = {self.lower!r}: the stinger must rise from its tip to the vessel")
        tip, top = float(self.angle(z_l)), float(self.angle(z_u))
        if tip - top > MAX_STINGER_TURN:
            fail(f"{p}.a", self.a,
                 f"turns the stinger through {tip - top:.4g} deg between its ends "
                 f"({top:.4g} deg at the upper end, {tip:.4g} deg at the tip): more than "
                 f"{MAX_STINGER_TURN:g} deg, it overhangs the pipe coming from the vessel")

    @property
    def b(self) -> float:
        """Linear coefficient [-]."""
        (x_l, z_l), (x_u, z_u) = self.lower, self.upper
        return (x_u - x_l) / (z_u - z_l) - self.a * (z_u + z_l)

    @property
    def c(self) -> float:
        """Constant coefficient [m]."""
        x_l, z_l = self.lower
        return x_l - self.a * z_l**2 - self.b * z_l

    def height(self, z):
        """Stinger height x(z) [m] at z [m]; vectorised."""
        return vectorised(z, lambda z: (self.a * z + self.b) * z + self.c)

    def slope(self, z):
        """dx/dz [-] at z [m]; vectorised."""
        return vectorised(z, lambda z: 2.0 * self.a * z + self.b)

    def angle(self, z):
        """Tangent angle from horizontal [deg] at z [m]; vectorised."""
        return vectorised(z, lambda z: np.degrees(np.arctan(2.0 * self.a * z + self.b)))

    def curvature(self, z):
        """Signed curvature d(theta)/ds [1/m] at z [m] (negative: hogging); vectorised."""
        return vectorised(
            z, lambda z: 2.0 * self.a / (1.0 + (2.0 * self.a * z + self.b) ** 2) ** 1.5)

    def arc_length(self, z0: float, z1):
        """The curve's arc length [m] from z0 to z1 [m], negative when z1 < z0,
        in closed form (:func:`.parabola.arc`); vectorised in z1."""
        return parabola.arc(self.a, self.b, z0, np.asarray(z1, dtype=float))

    def z_at_arc(self, z0: float, s):
        """z [m] where the curve's arc length from z0 [m] is ``s`` [m]
        (negative: towards lower z), :func:`.parabola.at_arc`; vectorised in s."""
        return parabola.at_arc(self.a, self.b, z0, s)

    def level_z(self) -> float:
        """z [m] where the curve is level (its vertex; a < 0)."""
        return -self.b / (2.0 * self.a)

    def seabed_z(self) -> float:
        """z [m] where the curve continued below the tip meets x = 0: the
        root of a z^2 + b z + c where 2 a z + b = +sqrt(disc), without
        cancellation (:func:`.parabola.root`; x >= 0 at the tip: a real root
        below it)."""
        return float(parabola.root(-self.a, -self.b, -self.c))

    @property
    def vessel(self) -> Stinger:
        """The stinger in the vessel's frame: itself (a trimmed vessel's,
        :class:`.trim.TrimmedStinger`, turns it)."""
        return self

    def support_row(self) -> np.ndarray:
        """Its row of the supports' table (layout ``ST_*``: a, b, c, zL, zU,
        the turn 0)."""
        return np.array([self.a, self.b, self.c, self.lower[1], self.upper[1], 0.0])

    def roller_positions(self, spacing: float) -> list[list[float]]:
        """Rollers on this curve for a roller stinger's ``rollers``: evenly
        along its arc from the upper end down, about ``spacing`` [m] apart
        (the arc divided into the nearest whole number of spans), the last
        on the tip; (x, z) [m] pairs, from the vessel down."""
        if not spacing > 0.0:
            fail("spacing", spacing, "must be positive")
        total = float(self.arc_length(self.lower[1], self.upper[1]))
        n = max(1, round(total / spacing))
        zr = self.z_at_arc(self.upper[1], -total / n * np.arange(1, n + 1))
        zr[-1] = self.lower[1]  # the last on the tip, exactly
        return [[float(a), float(b)] for a, b in zip(self.height(zr), zr, strict=True)]


@dataclass(frozen=True, slots=True)
class Lay:
    """Lay method, top end and tension, table ``[lay]``.

    Attributes
    ----------
    method : str
        "S" (stinger) or "J"; default "S" with a stinger, else "J".
    top_tension : float or None
        Effective tension at the top [N].
    bottom_tension : float or None
        Effective (residual) tension at a lower end sliding along z [N].
        On a sloped seabed (``seabed.slope_deg`` not 0) the bottom tension
        is defined as the effective tension at touchdown (the result's
        ``bottom_tension`` there): along the laid pipe the tension changes
        by the weight's component w sin(slope_deg) per metre, so the
        tension at the modelled lower end is not a property of the lay. As
        an input it is refused there (give ``top_tension`` or
        ``pipe_length``): holding it at touchdown would make the lower
        end's load depend on touchdown's position, an unknown of the solve.
    pipe_length : float or None
        Unstretched length with a fixed lower end [m].
        Exactly one of the three tension keys is given.
    top : (float, float)
        (x, z) of the pipe's upper end [m], x in the frame of ``frame``; for
        S-lay on a quadratic stinger its upper end; required with a roller
        stinger (where the vessel holds the pipe, above the rollers). It must
        lie above the seabed's surface (flat, sloped or profiled), the
        stinger's tip and rollers on it at the lowest, once the frame and
        the trim are applied (:func:`pipelay_fast.input.surface.check_vessel`).
    top_angle : float, "pinned" or None
        Prescribed top angle from horizontal [deg], in (0, 90], or "pinned".
        Omitted: pinned for J-lay; for S-lay the firing line, the pipe held
        along the stinger's tangent at its upper end. A pinned S-lay top frees
        the end's slope and moment, but the pipe still conforms to the stinger
        up to the pin (a moment-free end on a convex support cannot lift off
        it): the moment falls from the stinger's EI kappa_U to zero at the pin
        itself, and across that fall the effective tension rises by
        (EI kappa_U)^2 / (2 EI), the first integral Te + M^2/(2 EI) - W(x) =
        const of the rod. The engine solves it so, as the firing line with the
        tension below the pin that much lower (:func:`pipelay_fast.engine.model.pin_jump`);
        the profile's top node reports the pin's values (zero moment, the
        tension above the jump). Required with a roller stinger: degrees (the
        firing line; a radius path starts along it), or "pinned" with
        explicit rollers (the top then simply pinned: no conforming pipe).
    stinger : Stinger, RollerStinger or None
        Required for S-lay, forbidden for J-lay: the quadratic curve
        (``a``, ``lower``, ``upper``) or rollers (:class:`RollerStinger`).
    torque : float
        Torque at the ends H [N m]; default 0.
    distributed_moment : (float, float, float)
        Distributed moment (mx, my, mz) [N m/m]; default 0.
    frame : str
        The frame of the heights x of ``top`` and the stinger's ``lower``,
        ``upper`` and ``rollers`` [-]: "seabed" (default), the height above
        the seabed [m]; or "waterline", the elevation above the still water
        level [m] (negative below it), so that ``environment.water_depth``
        moves the seabed and not the vessel. z is the same in both. A case
        holds its lay in the seabed frame (:mod:`pipelay_fast.input.frame`).
    trim_deg : float
        The vessel's trim [deg], default 0: ``top``, ``top_angle``, the stinger
        and its rollers turned as one body about ``trim_pivot``, positive
        trimming the stern (the stinger's end, towards -z) down: a point's
        (x - xp, z - zp) turned counter-clockwise seen with z to the right and x
        up, angles above horizontal growing by the trim. Within (-90, 90),
        and refused where the turned geometry is not a lay
        (:mod:`pipelay_fast.input.trim`).
    trim_pivot : (float, float) or None
        The point (xp, zp) [m] the trim turns about, x in the frame of
        ``frame``; required with a trim.
    """

    method: str | None = None
    top_tension: float | None = None
    bottom_tension: float | None = None
    pipe_length: float | None = None
    top: tuple[float, float] | None = None
    top_angle: float | None = None
    stinger: Stinger | RollerStinger | None = None
    torque: float = 0.0
    distributed_moment: tuple[float, float, float] = (0.0, 0.0, 0.0)
    frame: str = "seabed"
    trim_deg: float = 0.0
    trim_pivot: tuple[float, float] | None = None

    def __post_init__(self):
        choice("lay.frame", self.frame, FRAMES)
        self._check_trim()
        if self.stinger is not None:
            instance("lay.stinger", self.stinger, (Stinger, RollerStinger, TrimmedStinger))
        if self.method is None:
            assign(self, "method", "J" if self.stinger is None else "S")
        choice("lay.method", self.method, METHODS)
        self._check_tension()
        self._check_top()
        set_numbers(self, "lay", finite=("torque",))
        assign(self, "distributed_moment",
              vector("lay.distributed_moment", self.distributed_moment, 3))

    def _check_trim(self):
        set_numbers(self, "lay", finite=("trim_deg",))
        if not -90.0 < self.trim_deg < 90.0:
            fail("lay.trim_deg", self.trim_deg, "must lie in (-90, 90) deg (a quarter turn "
                 "stands the vessel's deck on end)")
        if self.trim_pivot is not None:
            assign(self, "trim_pivot", vector("lay.trim_pivot", self.trim_pivot, 2))
        elif self.trim_deg != 0.0:
            fail("lay.trim_pivot", None, f"is required with lay.trim_deg = {self.trim_deg!r}")

    def _check_tension(self):
        keys = ("top_tension", "bottom_tension", "pipe_length")
        given = [key for key in keys if getattr(self, key) is not None]
        names = ", ".join(f"lay.{key}" for key in keys)
        if not given:
            raise ValueError(f"no tension given: set exactly one of {names}")
        if len(given) > 1:
            both = " and ".join(f"lay.{key}" for key in given)
            raise ValueError(f"{both} are given together: set exactly one of {names}")
        set_numbers(self, "lay", positive=given)

    def _check_top(self):
        if self.method == "S" and isinstance(self.stinger, RollerStinger):
            self._check_rollers()
        elif self.method == "S":
            if self.stinger is None:
                raise ValueError("missing table lay.stinger: S-lay needs a [lay.stinger]")
            upper = self.stinger.upper
            if self.top is not None:
                top = vector("lay.top", self.top, 2)
                scale = ROUNDOFF * max(map(abs, upper))
                if not all(math.isclose(t, u, rel_tol=ROUNDOFF, abs_tol=scale)
                           for t, u in zip(top, upper, strict=True)):
                    fail("lay.top", top, f"must be the stinger upper end "
                         f"lay.stinger.upper = {upper!r} for S-lay (or be omitted)")
            assign(self, "top", upper)
        else:
            if self.stinger is not None:
                fail("lay.stinger", self.stinger, "is given but lay.method = 'J' (no stinger)")
            if self.top is None:
                raise ValueError("missing required key lay.top: (x, z) of the J-lay hang-off [m]")
            assign(self, "top", vector("lay.top", self.top, 2))
        self._check_top_angle()

    def _check_top_angle(self):
        if isinstance(self.top_angle, str):
            if self.top_angle != "pinned":
                fail("lay.top_angle", self.top_angle, 'must be a number of degrees or "pinned"')
        elif self.top_angle is not None:
            set_numbers(self, "lay", finite=("top_angle",))
            if not 0.0 < self.top_angle <= 90.0:
                fail("lay.top_angle", self.top_angle, "must lie in (0, 90] degrees")

    def _check_rollers(self):
        """A roller stinger's top, top angle and rollers: the rollers below
        and behind the top, falling from one to the next (the seabed below
        them: :func:`.surface.check_vessel`)."""
        st, p = self.stinger, "lay.stinger"
        if self.top is None:
            raise ValueError("missing required key lay.top: (x, z) [m] where the vessel holds "
                             "the pipe, above the roller stinger")
        assign(self, "top", vector("lay.top", self.top, 2))
        if self.top_angle is None:
            raise ValueError("missing required key lay.top_angle: with a roller stinger give "
                             "the firing line's angle [deg] (or \"pinned\" with "
                             "lay.stinger.rollers)")
        self._check_top_angle()
        if st.rollers is None:
            if self.top_angle == "pinned":
                fail("lay.top_angle", self.top_angle, f"gives no direction for the roller path "
                     f"({p}.radius starts along lay.top_angle): give it in degrees")
            turn = self.top_angle + math.degrees(st.arc_length / st.radius)
            if turn > MAX_STINGER_TURN:
                fail(f"{p}.arc_length", st.arc_length,
                     f"turns the pipe to {turn:.4g} deg from lay.top_angle = {self.top_angle!r} "
                     f"deg with {p}.radius = {st.radius!r} m: beyond {MAX_STINGER_TURN:g} deg the "
                     "stinger overhangs the pipe coming from the vessel")
        pts = self.roller_positions()
        where = f"{p}.rollers" if st.rollers is not None else f"{p} (generated rollers)"
        x_top, z_top = self.top
        if not (pts[0, 0] < x_top and pts[0, 1] < z_top):
            fail(f"{where}[0]", pts[0].tolist(), f"must lie below and behind lay.top = "
                 f"{list(self.top)} (the vessel holds the pipe above the stinger)")
        for i in range(1, len(pts)):
            if not (pts[i, 0] < pts[i - 1, 0] and pts[i, 1] < pts[i - 1, 1]):
                fail(f"{where}[{i}]", pts[i].tolist(),
                     f"must lie below and behind roller {i - 1} at {pts[i - 1].tolist()} (x and "
                     "z falling from the vessel down; a coarse height_step can merge heights)")

    def roller_positions(self) -> np.ndarray | None:
        """(n, 2) roller positions (x, z) [m] of a roller stinger; None otherwise."""
        if not isinstance(self.stinger, RollerStinger):
            return None
        angle = 0.0 if self.top_angle == "pinned" else self.top_angle
        return self.stinger.positions(self.top, angle)

    @property
    def has_rollers(self) -> bool:
        """True when the stinger is a :class:`RollerStinger`."""
        return isinstance(self.stinger, RollerStinger)

    @property
    def curve(self) -> Stinger | None:
        """The quadratic stinger's curve; None for a J-lay or a roller stinger
        (whose rollers are points, not a curve)."""
        return None if self.has_rollers else self.stinger

    @property
    def roller_count(self) -> int:
        """The number of rollers (0 without a roller stinger)."""
        return self.stinger.count if self.has_rollers else 0

"""The ``lay`` table: the lay method, the top, the tensions and the
stinger (``lay.stinger``: a quadratic curve or a roller stinger), validated
on construction. Heights ``x`` are measured from the seabed, or from the still
water level with ``lay.frame = "waterline"`` (:mod:`.frame`); ``z`` along the
lay."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .frame import FRAMES
from .limits import MAX_STINGER_TURN, ROUNDOFF
from .validate import (
    assign,
    choice,
    fail,
    instance,
    integer,
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
    with a <= 0 the whole stinger is then above its tip, which :class:`Lay`
    checks against the seabed); and the
    stinger may turn the pipe by at most 90 deg between its ends (tangent angle
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
        """The curve's arc length [m] from z0 to z1 [m], negative when z1 < z0;
        in closed form (with p = 2 a z + b, 4 a s = [p sqrt(1 + p^2) +
        asinh p] between the ends); vectorised in z1."""
        return self._arc(self.a, self.b, z0, np.asarray(z1, dtype=float))

    @staticmethod
    def _arc(a: float, b: float, z0: float, z1):
        """:meth:`arc_length` of the curve with coefficients ``a``, ``b``."""
        if a == 0.0:
            return math.sqrt(1.0 + b * b) * (z1 - z0)
        p0, p1 = 2.0 * a * z0 + b, 2.0 * a * z1 + b
        return ((p1 * np.sqrt(1.0 + p1 * p1) + np.arcsinh(p1))
                - (p0 * math.sqrt(1.0 + p0 * p0) + math.asinh(p0))) / (4.0 * a)

    def z_at_arc(self, z0: float, s):
        """z [m] where the curve's arc length from z0 [m] is ``s`` [m]
        (negative: towards lower z): the inverse of :meth:`arc_length`, by
        Newton from the chord along the tangent at z0 (ds/dz = sqrt(1 + p^2)
        >= 1, so the iteration converges quadratically) until its step stops
        shrinking, at round-off; vectorised in s."""
        a, b = self.a, self.b
        s = np.asarray(s, dtype=float)
        z = z0 + s / math.sqrt(1.0 + (2.0 * a * z0 + b) ** 2)
        last = math.inf
        while True:
            p = 2.0 * a * z + b
            dz = (self._arc(a, b, z0, z) - s) / np.sqrt(1.0 + p * p)
            z = z - dz
            step = float(np.max(np.abs(dz), initial=0.0))
            if not step < last:
                return z
            last = step

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


ROLLER_TYPES = ("v", "flat")


@dataclass(frozen=True, slots=True)
class RollerStinger:
    """Roller stinger: rigid rollers at discrete stations, table
    ``[lay.stinger]`` with ``rollers`` (or ``radius``) instead of ``a``.

    The pipe spans freely between the rollers and bears on each one it
    reaches (a unilateral, frictionless point contact,
    :mod:`pipelay_fast.kernels.newton`). The positions are those of the
    pipe's axis over each roller, as the quadratic stinger's curve is the
    axis's path: a roller top raised by the pipe's outer radius (coating
    included) along the pipe's normal.

    Attributes
    ----------
    rollers : list of (float, float) or None
        (x, z) [m] of each roller, from the vessel down: z falling and x
        falling from one to the next, all above the seabed and below and
        behind ``lay.top``; x in the frame of ``lay.frame``.
    radius, arc_length, spacing : float or None
        Or the rollers placed on a path from ``lay.top`` along
        ``lay.top_angle``: ``straight_length`` [m] straight, then a circular
        arc of ``radius`` [m] turning the pipe down over ``arc_length`` [m],
        a roller every ``spacing`` [m] of the path from its start (the first
        at ``spacing``, the last at or before the arc's end).
    straight_length : float
        The path's straight part [m]; default 0.
    height_step : float or None
        Roller heights rounded to multiples of it [m] (the pin holes of a
        roller box set heights in steps); None: not rounded. With
        ``rollers`` given it is not allowed (round them yourself).
    roller_type : str or list of str
        "v" (default): a roller box with side rollers, which in 3D holds the
        pipe laterally (y = 0) while it bears; "flat": it does not. One for
        all rollers, or one per roller.
    height_shift : float
        Added to the heights x of the rollers ``shifted`` [m] (after any
        rounding); default 0. The sweep axis ``roller_shift`` varies it.
    shifted : list of int or None
        The rollers ``height_shift`` moves (indices [-] from the vessel down,
        from 0); None (default): all of them.

    A roller stinger needs ``lay.top`` (where the vessel holds the pipe) and
    ``lay.top_angle`` (degrees, or "pinned" with ``rollers`` given).
    """

    rollers: tuple[tuple[float, float], ...] | None = None
    radius: float | None = None
    arc_length: float | None = None
    spacing: float | None = None
    straight_length: float = 0.0
    height_step: float | None = None
    roller_type: str | tuple[str, ...] = "v"
    height_shift: float = 0.0
    shifted: tuple[int, ...] | None = None

    def __post_init__(self):
        p = "lay.stinger"
        set_numbers(self, p, finite=("height_shift",))
        if self.shifted is not None:
            if not isinstance(self.shifted, (list, tuple)) or not self.shifted:
                fail(f"{p}.shifted", self.shifted, "must be a non-empty list of roller indices")
            picks = tuple(integer(f"{p}.shifted[{i}]", k, 0) for i, k in enumerate(self.shifted))
            if len(set(picks)) != len(picks):
                fail(f"{p}.shifted", list(picks), "names a roller twice")
            assign(self, "shifted", picks)
        path_keys = ("radius", "arc_length", "spacing")
        given = [k for k in path_keys if getattr(self, k) is not None]
        if self.rollers is not None:
            if given or self.straight_length != 0.0:
                key = given[0] if given else "straight_length"
                fail(f"{p}.{key}", getattr(self, key),
                     f"is given with {p}.rollers: give the rollers, or the path "
                     "(radius, arc_length, spacing, straight_length), not both")
            if self.height_step is not None:
                fail(f"{p}.height_step", self.height_step,
                     f"rounds generated rollers only; {p}.rollers are taken as given")
            if not isinstance(self.rollers, (list, tuple)) or not self.rollers:
                fail(f"{p}.rollers", self.rollers, "must be a non-empty list of [x, z] pairs")
            pts = tuple(vector(f"{p}.rollers[{i}]", r, 2) for i, r in enumerate(self.rollers))
            assign(self, "rollers", pts)  # (their order and the seabed: Lay._check_rollers)
        else:
            if len(given) != 3:
                missing = [k for k in path_keys if k not in given]
                raise ValueError(f"{p}: a roller stinger needs {p}.rollers, or {p}.radius, "
                                 f"{p}.arc_length and {p}.spacing (missing "
                                 f"{', '.join(p + '.' + k for k in missing)})")
            set_numbers(self, p, positive=path_keys, non_negative=("straight_length",))
            if self.height_step is not None:
                set_numbers(self, p, positive=("height_step",))
            if self.spacing > self.straight_length + self.arc_length:
                fail(f"{p}.spacing", self.spacing, "is longer than the roller path "
                     f"(straight_length + arc_length = "
                     f"{self.straight_length + self.arc_length:g} m): no roller on it")
        kinds = self.roller_type
        if isinstance(kinds, (list, tuple)):
            kinds = tuple(choice(f"{p}.roller_type[{i}]", k, ROLLER_TYPES)
                          for i, k in enumerate(kinds))
            if len(kinds) != self.count:
                fail(f"{p}.roller_type", list(kinds), f"has {len(kinds)} entries for the "
                     f"{self.count} rollers: give one per roller, or one for all")
        else:
            kinds = choice(f"{p}.roller_type", kinds, ROLLER_TYPES)
        assign(self, "roller_type", kinds)
        if self.shifted is not None and max(self.shifted) >= self.count:
            fail(f"{p}.shifted", list(self.shifted),
                 f"names a roller past the last of the {self.count}")

    @property
    def count(self) -> int:
        """The number of rollers (on a path: one every ``spacing`` of it)."""
        if self.rollers is not None:
            return len(self.rollers)
        length = self.straight_length + self.arc_length
        return int(math.floor(length / self.spacing * (1.0 + ROUNDOFF)))

    def positions(self, top, top_angle) -> np.ndarray:
        """(n, 2) roller positions (x, z) [m]: ``rollers``, or placed on the
        path from ``top`` (x, z) [m] along ``top_angle`` [deg]."""
        if self.rollers is not None:
            return self._shift(np.array(self.rollers, dtype=float))
        sigma = self.spacing * np.arange(1, self.count + 1)
        theta0 = math.radians(top_angle)
        arc = np.clip(sigma - self.straight_length, 0.0, None)
        straight = sigma - arc
        theta = theta0 + arc / self.radius
        # along the straight, then the arc (the angle grows at 1/radius per m)
        x = top[0] - straight * math.sin(theta0) - self.radius * (
            np.cos(theta0) - np.cos(theta))
        z = top[1] - straight * math.cos(theta0) - self.radius * (
            np.sin(theta) - np.sin(theta0))
        if self.height_step is not None:
            x = self.height_step * np.round(x / self.height_step)
        return self._shift(np.stack([x, z], axis=1))

    def _shift(self, pts: np.ndarray) -> np.ndarray:
        """``pts`` with ``height_shift`` added to the heights of the ``shifted`` rollers."""
        if self.height_shift != 0.0:
            rows = slice(None) if self.shifted is None else list(self.shifted)
            pts[rows, 0] += self.height_shift
        return pts

    def lateral_hold(self) -> np.ndarray:
        """1.0 for each roller that holds the pipe laterally (a V roller), else 0."""
        kinds = self.roller_type
        if isinstance(kinds, str):
            return np.full(self.count, 1.0 if kinds == "v" else 0.0)
        return np.array([1.0 if k == "v" else 0.0 for k in kinds])


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
    pipe_length : float or None
        Unstretched length with a fixed lower end [m].
        Exactly one of the three tension keys is given.
    top : (float, float)
        (x, z) of the pipe's upper end [m], x in the frame of ``frame``; for
        S-lay on a quadratic stinger its upper end; required with a roller
        stinger (where the vessel holds the pipe, above the rollers).
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

    def __post_init__(self):
        choice("lay.frame", self.frame, FRAMES)
        if self.stinger is not None:
            instance("lay.stinger", self.stinger, (Stinger, RollerStinger))
        if self.method is None:
            assign(self, "method", "J" if self.stinger is None else "S")
        choice("lay.method", self.method, METHODS)
        self._check_tension()
        self._check_top()
        set_numbers(self, "lay", finite=("torque",))
        assign(self, "distributed_moment",
              vector("lay.distributed_moment", self.distributed_moment, 3))

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
        if self.frame == "seabed" and self.top[0] <= 0:
            fail("lay.top", self.top, "must be above the seabed (x > 0)")
        if self.frame == "seabed" and self.curve is not None and self.stinger.lower[0] < 0:
            fail("lay.stinger.lower", self.stinger.lower, "is below the seabed (x < 0)")
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
        and behind the top, falling from one to the next, above the seabed."""
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
        if self.frame == "seabed" and pts[-1, 0] < 0.0:
            fail(f"{where}[{len(pts) - 1}]", pts[-1].tolist(), "is below the seabed (x < 0)")

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

"""The ``environment`` table (water depth and density, the ``current``
subtable) and the ``seabed`` table, validated on construction."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .profile import check_profile
from .validate import (
    assign,
    choice,
    fail,
    instance,
    set_numbers,
    vector,
)

PROFILES = ("uniform", "linear", "power", "table")
MAX_SLOPE_DEG = 30.0  # the steepest seabed.slope_deg either way [deg]


@dataclass(frozen=True, slots=True)
class Current:
    """Current, table ``[environment.current]``.

    Attributes
    ----------
    speed : float
        Surface speed, the largest in the water column [m/s]; 0: no current.
        For ``profile = "table"`` it is the table's largest speed (may be omitted).
    heading : float
        Direction in the y-z plane [deg]: 0 = +z, 90 = +y; in [-180, 360]
        (one turn either way of the two usual conventions; a value beyond is
        refused rather than taken modulo 360).
    profile : str
        "uniform" | "linear" | "power" (from the seabed, the default) | "table".
    exponent : float
        Power-law exponent [-]: V(x) = speed (x/d)^exponent; default 1/7.
    table : tuple of (float, float)
        (height x [m], speed [m/s]) pairs, x strictly ascending, for "table";
        the end values hold beyond the table.
    """

    speed: float = 0.0
    heading: float = 0.0
    profile: str = "power"
    exponent: float = 1.0 / 7.0
    table: tuple[tuple[float, float], ...] = ()

    def __post_init__(self):
        p = "environment.current"
        set_numbers(self, p, non_negative=("speed",), positive=("exponent",),
                    finite=("heading",))
        if not -180.0 <= self.heading <= 360.0:
            fail(f"{p}.heading", self.heading, "must be in [-180, 360] deg")
        choice(f"{p}.profile", self.profile, PROFILES)
        if isinstance(self.table, (str, bytes)) or not isinstance(self.table, (list, tuple)):
            fail(f"{p}.table", self.table, "must be a list of [height, speed] pairs")
        table = tuple(vector(f"{p}.table[{i}]", row, 2) for i, row in enumerate(self.table))
        assign(self, "table", table)
        if self.profile != "table":
            if table:
                fail(f"{p}.table", table, f"is given but {p}.profile = {self.profile!r}")
            return
        heights, speeds = np.array(table).reshape(-1, 2).T
        if len(table) < 2:
            fail(f"{p}.table", table, 'needs at least two rows for profile = "table"')
        if heights[0] < 0 or np.any(np.diff(heights) <= 0):
            fail(f"{p}.table", table, "heights must be >= 0 and strictly ascending")
        if np.any(speeds < 0):
            fail(f"{p}.table", table, "speeds must not be negative")
        top = float(speeds.max())
        if self.speed == 0.0:
            assign(self, "speed", top)
        elif self.speed != top:
            fail(f"{p}.speed", self.speed,
                 f"must equal the largest speed of {p}.table ({top!r}) or be omitted")


@dataclass(frozen=True, slots=True)
class Environment:
    """Sea, table ``[environment]``.

    Attributes
    ----------
    water_depth : float
        d [m], required.
    water_density : float
        rho_w [kg/m^3]; default 1025.
    gravity : float
        g [m/s^2]; default 9.81.
    current : Current
        Table ``[environment.current]``; default none.
    """

    water_depth: float
    water_density: float = 1025.0
    gravity: float = 9.81
    current: Current = field(default_factory=Current)

    def __post_init__(self):
        set_numbers(self, "environment",
                    positive=("water_depth", "water_density", "gravity"))
        instance("environment.current", self.current, Current)


@dataclass(frozen=True, slots=True)
class Seabed:
    """The seabed, table ``[seabed]``: a plane through the reference level
    x = 0 (where ``environment.water_depth`` is measured), flat or sloped
    along z.

    Attributes
    ----------
    lateral_friction, axial_friction : float
        Coulomb coefficients mu_y, mu_z [-]; defaults 0.5 and 0. Friction is
        mobilised by the current, from the pipe as laid under gravity.
    friction_slip : float
        Displacement that mobilises full friction [m], default 0.01: a contact
        moves elastically up to it (force mu W d / friction_slip), then slides
        carrying mu W. The rigid-plastic Coulomb law is its limit as it tends to 0.
    stiffness : float or None
        Elastic support [N/m per m of pipe]; None (TOML ``"rigid"``): rigid.
    slope_deg : float
        Slope of the seabed along z [deg], default 0 (flat): positive rises
        toward the vessel (+z). The seabed is the plane x = (z - slope_origin)
        tan(slope_deg); at most MAX_SLOPE_DEG = 30 either way. The pipe
        touches down on it tangent to it, its normal reaction is the
        ``seabed_reaction`` column, and the laid pipe's tension changes along
        it by the weight's component w sin(slope_deg) per metre; the
        result's ``bottom_tension`` is then the effective tension at
        touchdown, and ``lay.bottom_tension`` is refused (give
        ``lay.top_tension`` or ``lay.pipe_length``). The elastic seabed
        (``stiffness`` a number) pushes along the plane's normal, with
        ``stiffness`` times the normal penetration of the pipe's axis
        (vertically on the flat seabed and on a ``profile``). Friction
        acts in the plane with the normal force N from the plane: lateral
        along y, at most mu_y N, axial along the plane's line in the
        (x, z) plane, at most mu_z N, each spring on its own (a rectangular
        cone in the plane, not an elliptic one). A plane that reaches the still water level (x >=
        ``environment.water_depth``) along the modelled pipe, laid pipe
        included, is refused when the mesh is built
        (:func:`pipelay_fast.input.surface.check_water`); the vessel must
        lie above it (:func:`pipelay_fast.input.surface.check_vessel`).
    slope_origin : float
        z [m] where the sloped seabed passes through the reference level
        x = 0, default 0.
    profile : list of [z, depth] or None
        The seabed along the route [m]: water depth ``depth`` (positive) at
        ``z`` (strictly ascending), default None (the flat seabed). The
        seabed lies at x = water_depth - depth(z) above the reference level,
        depth(z) the monotone C1 piecewise-cubic Hermite (PCHIP) interpolant
        of the table, held at its end values beyond it; in 3D it is the same
        across y. It needs the elastic seabed (``stiffness`` a number),
        which pushes vertically: q_x = k (x_b(z) - x) where the pipe's axis
        x lies at or below the seabed's height x_b(z), so the pipe may rest
        on several stretches with free spans between them (the summary's
        ``n_spans``, ``Result.spans``). Not with ``slope_deg`` (a profile can
        describe a slope).
    """

    lateral_friction: float = 0.5
    axial_friction: float = 0.0
    friction_slip: float = 0.01
    stiffness: float | None = None
    slope_deg: float = 0.0
    slope_origin: float = 0.0
    profile: tuple | None = None

    def __post_init__(self):
        set_numbers(self, "seabed", non_negative=("lateral_friction", "axial_friction"),
                    positive=("friction_slip",), finite=("slope_deg", "slope_origin"))
        if abs(self.slope_deg) > MAX_SLOPE_DEG:
            fail("seabed.slope_deg", self.slope_deg,
                 f"is steeper than {MAX_SLOPE_DEG:g} deg either way")
        if self.stiffness is None or self.stiffness == "rigid":
            assign(self, "stiffness", None)
        elif isinstance(self.stiffness, str):
            fail("seabed.stiffness", self.stiffness, 'must be "rigid" or a positive number')
        else:
            set_numbers(self, "seabed", positive=("stiffness",))
        if self.profile is None:
            return
        assign(self, "profile", check_profile(self.profile))
        if self.stiffness is None:
            fail("seabed.profile", [list(row) for row in self.profile],
                 "needs the elastic seabed (seabed.stiffness a number, not rigid): the "
                 "pipe may rest on several stretches of the profile")
        if self.slope_deg != 0.0:
            fail("seabed.profile", [list(row) for row in self.profile],
                 f"cannot be combined with seabed.slope_deg = {self.slope_deg!r} (a "
                 "profile can describe the slope)")

    @property
    def slope(self) -> float:
        """The slope's angle [rad] above horizontal along z."""
        return math.radians(self.slope_deg)

    @property
    def is_rigid(self) -> bool:
        """True for a rigid seabed (``stiffness`` None)."""
        return self.stiffness is None


def check_slope(case) -> None:
    """Refuse what a sloped seabed (``seabed.slope_deg`` not 0) does not
    support, naming the key: a given bottom tension (on a
    slope the laid pipe's tension changes along it, so the tension at the
    modelled lower end is not a property of the lay). The vessel against
    the plane: :func:`.surface.check_vessel`."""
    bed = case.seabed
    if bed.slope_deg == 0.0:
        return
    head = f"seabed.slope_deg = {bed.slope_deg!r}"
    if case.lay.bottom_tension is not None:
        raise ValueError(f"{head}: lay.bottom_tension = {case.lay.bottom_tension!r} N is "
                         "refused on a slope (the laid pipe's tension changes along it); "
                         "give lay.top_tension or lay.pipe_length")

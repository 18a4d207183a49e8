"""Validated, immutable description of one static pipelay case.

A case is read by :func:`load_case` from a TOML file (or a dict with the same
tables: ``pipe``, ``environment`` (+ ``current``), ``seabed``, ``lay``
(+ ``stinger``), ``solver``, and optionally ``checks``, the code-check inputs of
:class:`pipelay_fast.checks.Checks`). Every value is in SI units; coordinates follow the
paper: ``x`` is the height above the seabed, ``y`` lateral, ``z`` along the lay.

Every dataclass checks itself on construction, so a case built in Python, loaded
from a file or modified with :meth:`Case.with_changes` is always valid. A bad
value raises :class:`ValueError` naming the key by its dotted path and its value;
nothing is clamped. A case outside the model is refused the same way: a
stinger that is concave up, falls towards the vessel or overhangs
(:class:`Stinger`), and inputs that alone imply a strain beyond
``solver.max_strain`` (the tension at a given end over EA, the bending strain on
the stinger: :func:`pipelay_fast.limits.check_case`).
"""

from __future__ import annotations

import copy
import dataclasses
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from pathlib import Path

import numpy as np

from pipelay_fast._validate import (
    assign,
    choice,
    fail,
    flag,
    from_toml,
    get_path,
    instance,
    integer,
    plain,
    put_path,
    reject_unknown,
    set_numbers,
    vector,
    vectorised,
)
from pipelay_fast.checks import Checks, check_inputs
from pipelay_fast.grades import DEFAULT_GRADE, grade_strengths
from pipelay_fast.limits import check_case

__all__ = [
    "Case",
    "Current",
    "Environment",
    "Lay",
    "Pipe",
    "Seabed",
    "Solver",
    "RollerStinger",
    "Stinger",
    "load_case",
]

METHODS = ("S", "J")
PROFILES = ("uniform", "linear", "power", "table")
DIMENSIONS = ("auto", "2d", "3d")
_PLANAR_TOL = 1e-12
MAX_STINGER_TURN = 90.0  # deg, the most a stinger may turn the pipe (Stinger)


# --------------------------------------------------------------------------- tables


@dataclass(frozen=True, slots=True)
class Pipe:
    """Pipe section, table ``[pipe]``. EA, EI, GJ come from the steel alone.

    Attributes
    ----------
    outer_diameter : float
        Steel outer diameter Do [m].
    inner_diameter : float
        Steel inner diameter Di [m].
    coating_outer_diameter : float
        Coating outer diameter Dc [m]; default Do (no coating). Sets buoyancy.
    steel_density, coating_density : float
        [kg/m^3]; defaults 7900 and 0.
    youngs_modulus : float
        E [Pa]; default 207e9.
    poisson_ratio : float
        nu [-], in (-1, 0.5); default 0.3.
    grade : str or None
        Linepipe steel grade, API 5L ("B", "X42" ... "X80") or ISO 3183
        ("L245" ... "L555"): SMYS and SMTS from API 5L (2018) Table 7, PSL 2
        (:mod:`pipelay_fast.grades`). Default "X65" (450 and 535 MPa) when
        none of grade, smys and smts is given; None when smys (and smts) are.
    smys : float
        Specified minimum yield strength [Pa]; default the grade's. Given
        with ``grade``, it must equal the grade's.
    smts : float or None
        Specified minimum tensile strength [Pa], not below smys; default the
        grade's; None when smys is given without it (then ``[checks]``
        refuse the pipe). Given with ``grade``, it must equal the grade's.
    contents_density : float
        rho_i [kg/m^3]; default 0 (empty).
    contents_level : float
        Height x of the internal free surface Hi [m]; default 0.
    drag_coefficient : float
        Morison drag coefficient C_D [-]; default 1.0.
    hydrodynamic_diameter : float
        Drag diameter D_h [m]; default Dc.
    extensible : bool
        False: inextensible rod (strain held at zero).
    """

    outer_diameter: float
    inner_diameter: float
    coating_outer_diameter: float | None = None
    steel_density: float = 7900.0
    coating_density: float = 0.0
    youngs_modulus: float = 207e9
    poisson_ratio: float = 0.3
    grade: str | None = None
    smys: float | None = None
    smts: float | None = None
    contents_density: float = 0.0
    contents_level: float = 0.0
    drag_coefficient: float = 1.0
    hydrodynamic_diameter: float | None = None
    extensible: bool = True

    def __post_init__(self):
        set_numbers(
            self, "pipe",
            positive=("outer_diameter", "inner_diameter", "steel_density",
                      "youngs_modulus"),
            non_negative=("coating_density", "contents_density", "contents_level",
                          "drag_coefficient"),
            finite=("poisson_ratio",),
        )
        if self.coating_outer_diameter is None:
            assign(self, "coating_outer_diameter", self.outer_diameter)
        set_numbers(self, "pipe", positive=("coating_outer_diameter",))
        self._set_strengths()
        if self.hydrodynamic_diameter is None:
            assign(self, "hydrodynamic_diameter", self.coating_outer_diameter)
        set_numbers(self, "pipe", positive=("hydrodynamic_diameter",))
        assign(self, "extensible", flag("pipe.extensible", self.extensible))
        do = self.outer_diameter
        if self.inner_diameter >= do:
            fail("pipe.inner_diameter", self.inner_diameter,
                 f"must be smaller than pipe.outer_diameter = {do!r}")
        if self.coating_outer_diameter < do:
            fail("pipe.coating_outer_diameter", self.coating_outer_diameter,
                 f"must not be smaller than pipe.outer_diameter = {do!r}")
        if not -1.0 < self.poisson_ratio < 0.5:
            fail("pipe.poisson_ratio", self.poisson_ratio, "must lie in (-1, 0.5)")

    def _set_strengths(self):
        """smys and smts from ``grade`` (X65 when none of the three is given);
        a given strength that differs from the grade's is refused."""
        given = [name for name in ("smys", "smts") if getattr(self, name) is not None]
        if self.grade is None and not given:
            assign(self, "grade", DEFAULT_GRADE)
        if self.grade is not None:
            smys, smts = grade_strengths(self.grade)
            set_numbers(self, "pipe", positive=given)
            for name, value in (("smys", smys), ("smts", smts)):
                if getattr(self, name) is None:
                    assign(self, name, value)
                elif getattr(self, name) != value:
                    fail(f"pipe.{name}", getattr(self, name),
                         f"disagrees with pipe.grade = {self.grade!r} (its {name.upper()} "
                         f"is {value!r} Pa): give pipe.grade or pipe.{name}, not both")
            return
        if self.smys is None:
            raise ValueError("missing key pipe.smys: pipe.smts is given without it "
                             "(give pipe.smys too, or pipe.grade instead)")
        set_numbers(self, "pipe", positive=given)
        if self.smts is not None and self.smts < self.smys:
            fail("pipe.smts", self.smts, f"is below pipe.smys = {self.smys!r}")

    @property
    def wall_thickness(self) -> float:
        """t = (Do - Di)/2 [m]."""
        return 0.5 * (self.outer_diameter - self.inner_diameter)

    @property
    def steel_area(self) -> float:
        """As = pi (Do^2 - Di^2)/4 [m^2]."""
        return math.pi * (self.outer_diameter**2 - self.inner_diameter**2) / 4.0

    @property
    def inner_area(self) -> float:
        """Ai = pi Di^2/4 [m^2]."""
        return math.pi * self.inner_diameter**2 / 4.0

    @property
    def outer_area(self) -> float:
        """Ae = pi Do^2/4 [m^2] (steel outer diameter: the pressure area)."""
        return math.pi * self.outer_diameter**2 / 4.0

    @property
    def displaced_area(self) -> float:
        """pi Dc^2/4 [m^2], the area that sets buoyancy."""
        return math.pi * self.coating_outer_diameter**2 / 4.0

    @property
    def second_moment(self) -> float:
        """I = pi (Do^4 - Di^4)/64 [m^4]."""
        return math.pi * (self.outer_diameter**4 - self.inner_diameter**4) / 64.0

    @property
    def polar_moment(self) -> float:
        """J = 2 I [m^4]."""
        return 2.0 * self.second_moment

    @property
    def bending_stiffness(self) -> float:
        """EI [N m^2]."""
        return self.youngs_modulus * self.second_moment

    @property
    def axial_stiffness(self) -> float:
        """EA [N], steel only."""
        return self.youngs_modulus * self.steel_area

    @property
    def shear_modulus(self) -> float:
        """G = E / (2 (1 + nu)) [Pa]."""
        return self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))

    @property
    def torsional_stiffness(self) -> float:
        """GJ [N m^2]."""
        return self.shear_modulus * self.polar_moment

    @property
    def steel_mass(self) -> float:
        """Steel mass per length [kg/m]."""
        return self.steel_density * self.steel_area

    @property
    def coating_mass(self) -> float:
        """Coating mass per length, rho_c pi (Dc^2 - Do^2)/4 [kg/m]."""
        return self.coating_density * (self.displaced_area - self.outer_area)

    @property
    def contents_mass(self) -> float:
        """Contents mass per length where filled, rho_i Ai [kg/m]."""
        return self.contents_density * self.inner_area


@dataclass(frozen=True, slots=True)
class Current:
    """Current, table ``[environment.current]``.

    Attributes
    ----------
    speed : float
        Surface speed, the largest in the water column [m/s]; 0: no current.
        For ``profile = "table"`` it is the table's largest speed (may be omitted).
    heading : float
        Direction in the y-z plane [deg]: 0 = +z, 90 = +y.
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
    """Flat seabed at x = 0, table ``[seabed]``.

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
    """

    lateral_friction: float = 0.5
    axial_friction: float = 0.0
    friction_slip: float = 0.01
    stiffness: float | None = None

    def __post_init__(self):
        set_numbers(self, "seabed", non_negative=("lateral_friction", "axial_friction"),
                    positive=("friction_slip",))
        if self.stiffness is None or self.stiffness == "rigid":
            assign(self, "stiffness", None)
            return
        if isinstance(self.stiffness, str):
            fail("seabed.stiffness", self.stiffness, 'must be "rigid" or a positive number')
        set_numbers(self, "seabed", positive=("stiffness",))

    @property
    def is_rigid(self) -> bool:
        return self.stiffness is None


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
        b [-] and c [m] follow from them.

    The geometry is checked up front: a concave-up stinger (a > 0) would hold
    the pipe at its ends only, not along the one contiguous stretch the model
    solves for; the upper end must lie above the tip (z_U > z_L, x_U > x_L,
    x_L >= 0: with a <= 0 the whole stinger is then above the seabed); and the
    stinger may turn the pipe by at most 90 deg between its ends (tangent angle
    at the tip minus that at the upper end): more, and the stinger overhangs,
    its tip pointing back under the pipe that comes from the vessel. The
    bending strain of a pipe conforming to it is checked with the pipe
    (:func:`pipelay_fast.limits.check_case`).
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
        if x_l < 0:
            fail(f"{p}.lower", self.lower, "is below the seabed (x < 0)")
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

    def roller_positions(self, spacing: float) -> list[list[float]]:
        """Rollers on this curve for a roller stinger's ``rollers``: evenly
        along its arc from the upper end down, about ``spacing`` [m] apart
        (the arc divided into the nearest whole number of spans), the last
        on the tip; (x, z) [m] pairs, from the vessel down. The arc is
        :func:`pipelay_fast.guess.stinger_arc`'s, on 200 000 intervals."""
        from .guess import stinger_arc

        if not spacing > 0.0:
            fail("spacing", spacing, "must be positive")
        z, arc = stinger_arc(self, self.upper[1], self.lower[1], 200001)
        arc = -arc  # (z falls from the vessel down: the arc from the upper end)
        n = max(1, round(arc[-1] / spacing))
        zr = np.interp(arc[-1] / n * np.arange(1, n + 1), arc, z)
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
        behind ``lay.top``.
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
        The rollers ``height_shift`` moves (indices from the vessel down,
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
        return int(math.floor(length / self.spacing * (1.0 + 1e-12)))

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
        (x, z) of the pipe's upper end [m]; for S-lay on a quadratic stinger
        its upper end; required with a roller stinger (where the vessel
        holds the pipe, above the rollers).
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
        tension below the pin that much lower (:func:`pipelay_fast.model.pin_jump`);
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
    """

    method: str | None = None
    top_tension: float | None = None
    bottom_tension: float | None = None
    pipe_length: float | None = None
    top: tuple[float, float] | None = None
    top_angle: float | None = None
    stinger: Stinger | None = None
    torque: float = 0.0
    distributed_moment: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self):
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
                if not all(math.isclose(t, u, rel_tol=1e-12, abs_tol=1e-9)
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
        if self.top[0] <= 0:
            fail("lay.top", self.top, "must be above the seabed (x > 0)")
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
        if pts[-1, 0] < 0.0:
            fail(f"{where}[{len(pts) - 1}]", pts[-1].tolist(), "is below the seabed (x < 0)")

    def roller_positions(self) -> np.ndarray | None:
        """(n, 2) roller positions (x, z) [m] of a roller stinger; None otherwise."""
        if not isinstance(self.stinger, RollerStinger):
            return None
        angle = 0.0 if self.top_angle == "pinned" else self.top_angle
        return self.stinger.positions(self.top, angle)

    @property
    def has_rollers(self) -> bool:
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


@dataclass(frozen=True, slots=True)
class Solver:
    """Numerical settings, table ``[solver]``.

    Attributes
    ----------
    dimension : str
        "auto" (2D when the case is planar), "2d" or "3d".
    element_length : float
        Target element length [m]; default 4.0 (on the speed-against-error
        front of the paper's scenes at 0.1 % stress error or better:
        benchmarks/speed_vs_error.md).
    min_element_length : float or None
        Finest graded element [m], <= element_length; None: the solver picks.
    grading : bool
        Grade the mesh at touchdown and lift-off; default true. Ungraded, the
        elements are about element_length long, with a node on each contact
        boundary (touchdown, lift-off, the tip) and, in 3D, one where the
        stinger's lateral hold ends.
    laid_length : float or None
        Length of pipe modelled on the seabed [m]; None: the solver picks.
    tolerance : float
        Relative convergence tolerance [-], in (0, 1e-2); default 1e-8.
    max_iterations, max_load_steps : int
        Newton iterations per step and load steps; defaults 100 and 64.
    max_iterations_total : int
        Newton iterations of one solve in all [-], over load steps, current
        steps, remeshing passes and laid-length doublings (a warm start that
        fails leaves the cold start a budget of its own); default 1000. The
        paper's scenes take 5 to 65, the hardest solved case of the tests 163,
        J125 held vertical at 200 kN on 1 m elements 474; a case that needs
        more is following its load path in fragments. Past it a SolveError
        names the key.
    max_elements : int
        Largest mesh [-], counted before any array is built; default 20000.
        The paper's scenes have about 120 elements at the default
        element_length, 4000 to 4800 at 0.1 m and 8000 to 9500 at 0.05 m;
        20000 is their mesh at about 0.02 m, and a 3D Newton iteration there
        takes about a second. Past it a ValueError names solver.element_length,
        the laid length (solver.laid_length or what set its default) and the
        count.
    max_strain : float
        Largest extreme-fibre strain |Tw/EA| + (Do/2) kappa [-] the
        small-strain model is trusted to (bending alone for an inextensible
        pipe), in (0, 0.1]; default 0.02, where the strain measures the linear
        law could be written in give forces 1 % apart (the reasoning:
        :mod:`pipelay_fast.limits`). Inputs that imply more are refused with a
        ValueError naming their keys, answers with a SolveError naming the
        strain, where it is and the limit.
    """

    dimension: str = "auto"
    element_length: float = 4.0
    min_element_length: float | None = None
    grading: bool = True
    laid_length: float | None = None
    tolerance: float = 1e-8
    max_iterations: int = 100
    max_load_steps: int = 64
    max_iterations_total: int = 1000
    max_elements: int = 20000
    max_strain: float = 0.02

    def __post_init__(self):
        choice("solver.dimension", self.dimension, DIMENSIONS)
        optional = [name for name in ("min_element_length", "laid_length")
                    if getattr(self, name) is not None]
        set_numbers(self, "solver", positive=("element_length", "tolerance", *optional))
        if self.min_element_length is not None and self.min_element_length > self.element_length:
            fail("solver.min_element_length", self.min_element_length,
                 f"must not exceed solver.element_length = {self.element_length!r}")
        if self.tolerance >= 1e-2:
            fail("solver.tolerance", self.tolerance, "must be below 1e-2")
        assign(self, "grading", flag("solver.grading", self.grading))
        assign(self, "max_iterations", integer("solver.max_iterations", self.max_iterations, 1))
        assign(self, "max_load_steps", integer("solver.max_load_steps", self.max_load_steps, 1))
        assign(self, "max_iterations_total",
               integer("solver.max_iterations_total", self.max_iterations_total, 1))
        assign(self, "max_elements", integer("solver.max_elements", self.max_elements, 2))
        set_numbers(self, "solver", positive=("max_strain",))
        if self.max_strain > 0.1:
            fail("solver.max_strain", self.max_strain, "must not exceed 0.1: beyond it the "
                 "strain measures of the small-strain model differ by over 5 %")


# --------------------------------------------------------------------------- case


@dataclass(frozen=True, slots=True)
class Case:
    """One static pipelay case: the tables of a case file, validated.

    Heights ``x`` [m] below are above the seabed; loads are per unit length.

    Attributes
    ----------
    name : str
        Case name (file stem by default).
    pipe, environment, seabed, lay, solver
        The tables.
    checks : Checks or None
        Table ``[checks]``, the code-check inputs; None: no code checks (their
        summary columns are NaN).
    """

    name: str
    pipe: Pipe
    environment: Environment
    seabed: Seabed
    lay: Lay
    solver: Solver
    checks: Checks | None = None

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            fail("name", self.name, "must be a non-empty string")
        for part, cls in _TABLES.items():
            instance(part, getattr(self, part), cls)
        if self.checks is not None:
            instance("checks", self.checks, Checks)
        if self.solver.dimension == "2d" and not self.is_planar:
            fail("solver.dimension", "2d", "cannot be used: the case has lateral loads "
                 "(lateral current, torque or distributed moment about x or z)")
        check_case(self)  # the model's limits first, then what the code checks need
        check_inputs(self.pipe, self.checks)

    @property
    def weight_dry(self) -> float:
        """Weight of steel and coating in air [N/m]."""
        return self.environment.gravity * (self.pipe.steel_mass + self.pipe.coating_mass)

    @property
    def weight_contents(self) -> float:
        """Weight of the contents where x < contents_level [N/m]."""
        return self.environment.gravity * self.pipe.contents_mass

    @property
    def buoyancy(self) -> float:
        """rho_w g pi Dc^2/4 where x < water_depth [N/m]."""
        env = self.environment
        return env.water_density * env.gravity * self.pipe.displaced_area

    def effective_weight(self, x):
        """Effective weight w(x) [N/m] at height x [m]; vectorised."""
        level, depth = self.pipe.contents_level, self.environment.water_depth
        return vectorised(x, lambda x: self.weight_dry + self.weight_contents * (x < level)
                           - self.buoyancy * (x < depth))

    def external_pressure(self, x):
        """pe(x) = rho_w g (d - x) below the surface, else 0 [Pa]; vectorised."""
        env = self.environment
        d = env.water_depth
        return vectorised(x, lambda x: np.where(
            x < d, env.water_density * env.gravity * (d - x), 0.0))

    def internal_pressure(self, x):
        """pi(x) = rho_i g (Hi - x) where positive, else 0 [Pa]; vectorised."""
        pipe, g = self.pipe, self.environment.gravity
        return vectorised(x, lambda x: np.maximum(
            pipe.contents_density * g * (pipe.contents_level - x), 0.0))

    def wall_tension(self, effective_tension, x):
        """Tw = Te + pi Ai - pe Ae [N] from effective tension Te [N] at height x [m]."""
        te = np.asarray(effective_tension, dtype=np.float64)
        return (te + self.internal_pressure(x) * self.pipe.inner_area
                - self.external_pressure(x) * self.pipe.outer_area)[()]

    def effective_tension(self, wall_tension, x):
        """Te = Tw - pi Ai + pe Ae [N] from wall tension Tw [N] at height x [m]."""
        tw = np.asarray(wall_tension, dtype=np.float64)
        return (tw - self.internal_pressure(x) * self.pipe.inner_area
                + self.external_pressure(x) * self.pipe.outer_area)[()]

    def current_speed_at(self, x):
        """Current speed [m/s] at height x [m]: 0 above the surface and below the
        seabed; vectorised."""
        cur, d = self.environment.current, self.environment.water_depth

        def profile(x):
            if cur.profile == "uniform":
                v = np.full_like(x, cur.speed)
            elif cur.profile == "linear":
                v = cur.speed * x / d
            elif cur.profile == "power":
                v = cur.speed * np.power(np.clip(x / d, 0.0, None), cur.exponent)
            else:
                heights, speeds = np.array(cur.table).T
                v = np.interp(x, heights, speeds)
            return np.where((x >= 0.0) & (x <= d), v, 0.0)

        return vectorised(x, profile)

    @property
    def current_direction(self) -> tuple[float, float]:
        """Unit vector (ey, ez) [-] of the current in the y-z plane."""
        heading = math.radians(self.environment.current.heading)
        return (math.sin(heading), math.cos(heading))

    @property
    def is_planar(self) -> bool:
        """True when every load lies in the x-z plane (the 2D reduction is exact)."""
        lateral_current = (self.environment.current.speed > 0.0
                           and abs(self.current_direction[0]) >= _PLANAR_TOL)
        mx, _, mz = self.lay.distributed_moment
        return not lateral_current and self.lay.torque == 0.0 and mx == 0.0 and mz == 0.0

    @property
    def resolved_dimension(self) -> str:
        """The dimension to solve in, "2d" or "3d" ("auto" resolved by :attr:`is_planar`)."""
        if self.solver.dimension != "auto":
            return self.solver.dimension
        return "2d" if self.is_planar else "3d"

    def to_dict(self) -> dict:
        """Nested dict of TOML-able values; ``load_case(case.to_dict()) == case``."""
        tables = {"name": self.name} | {part: plain(getattr(self, part)) for part in _TABLES}
        tables["seabed"].setdefault("stiffness", "rigid")
        if self.checks is not None:
            tables["checks"] = plain(self.checks)
        return tables

    def with_changes(self, changes: Mapping[str, object] | None = None, /, **dotted) -> Case:
        """A new, re-validated case with dotted keys replaced.

        ``case.with_changes({"lay.stinger.a": -0.0011})``; a value of None removes
        the key (its default applies). A derived default follows its source when
        it was equal to it and is not itself changed: coating_outer_diameter
        follows outer_diameter, hydrodynamic_diameter follows
        coating_outer_diameter, lay.top follows lay.stinger.upper; pipe.smys
        and pipe.smts follow pipe.grade, and changing either of them without
        the grade drops the grade (the steel is then the given strengths).
        """
        updates = {**(changes or {}), **dotted}
        old = self.to_dict()
        new = copy.deepcopy(old)
        for path, value in updates.items():
            put_path(new, path, plain(value))
        rederived = set()  # keys removed so that their default is derived afresh
        for dependent, source in _FOLLOWERS:
            touched = any(dependent == p or dependent.startswith(p + ".") for p in updates)
            moved = source in rederived or get_path(new, source) not in (
                None, get_path(old, source))
            if moved and not touched and get_path(old, dependent) == get_path(old, source):
                put_path(new, dependent, None)
                rederived.add(dependent)
        _follow_grade(new, updates)
        return load_case(new)


def _follow_grade(tables: dict, updates: Mapping) -> None:
    """In ``tables`` changed by ``updates``: a new pipe.grade re-derives the
    strengths not changed with it; a strength changed without the grade
    drops the grade."""
    if "pipe" in updates:
        return
    strengths = ("pipe.smys", "pipe.smts")
    if "pipe.grade" in updates:
        for key in strengths:
            if key not in updates:
                put_path(tables, key, None)
    elif any(key in updates for key in strengths):
        put_path(tables, "pipe.grade", None)


_TABLES = {"pipe": Pipe, "environment": Environment, "seabed": Seabed, "lay": Lay,
           "solver": Solver}
_OPTIONAL_TABLES = {"checks": Checks}  # absent: None
_SUBTABLES = {"current": Current, "stinger": Stinger}
_FOLLOWERS = (
    ("pipe.coating_outer_diameter", "pipe.outer_diameter"),
    ("pipe.hydrodynamic_diameter", "pipe.coating_outer_diameter"),
    ("lay.top", "lay.stinger.upper"),
)


# --------------------------------------------------------------------------- loading


def _build(cls, table, path):
    """Construct ``cls`` from a TOML table after checking its key names."""
    if not isinstance(table, Mapping):
        fail(path, table, "must be a table")
    names = [f.name for f in fields(cls)]
    reject_unknown(table, names, f"{path}.")
    for f in fields(cls):
        required = f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
        if required and f.name not in table:
            raise ValueError(f"missing required key {path}.{f.name}")
    kwargs = dict(table)
    for key, sub in _SUBTABLES.items():
        if key in names and key in kwargs:
            if key == "stinger":
                sub = _stinger_class(kwargs[key], f"{path}.{key}")
            kwargs[key] = _build(sub, kwargs[key], f"{path}.{key}")
    return cls(**kwargs)


def _stinger_class(table, path):
    """The quadratic stinger (key ``a``) or the roller stinger (``rollers`` or
    ``radius``) a ``[lay.stinger]`` table describes."""
    if not isinstance(table, Mapping):
        fail(path, table, "must be a table")
    rollers = [k for k in table if k in _ROLLER_KEYS]
    if "a" in table and rollers:
        fail(f"{path}.{rollers[0]}", table[rollers[0]], f"is given with {path}.a: a stinger is "
             "the quadratic curve (a, lower, upper) or rollers (rollers, or radius), not both")
    return RollerStinger if rollers else Stinger


# the keys that make a [lay.stinger] table a roller stinger
_ROLLER_KEYS = {f.name for f in fields(RollerStinger)}


def load_case(source: str | os.PathLike | Mapping) -> Case:
    """Read and validate a case from a TOML file path or a dict of tables.

    Raises
    ------
    ValueError
        For any bad value, naming the key by its dotted path (prefixed by the
        file name when reading a file).
    """
    if isinstance(source, Mapping):
        return _case_from_tables(source, "case")
    if not isinstance(source, (str, os.PathLike)):
        raise TypeError(f"load_case needs a path or a dict, not {type(source).__name__}")
    path = Path(source)
    return from_toml(path, lambda tables: _case_from_tables(tables, path.stem))


def with_tables(base: Case, tables: Mapping, changed) -> Case:
    """The case of ``tables``: ``base.to_dict()`` with keys of the top-level
    tables named in ``changed`` replaced (no key a derived default follows).
    Those tables are validated anew, the others are ``base``'s (already
    valid), then the case as a whole: the case :func:`load_case` gives for
    ``tables``, in less time (a sweep builds one per axis value: S67's
    paper sweep 99 -> 40 us a case)."""
    parts = {part: _build(cls, tables.get(part, {}), part) if part in changed
             else getattr(base, part) for part, cls in _TABLES.items()}
    for part, cls in _OPTIONAL_TABLES.items():
        if part not in changed:
            parts[part] = getattr(base, part)
        elif part in tables:
            parts[part] = _build(cls, tables[part], part)
    return Case(name=tables.get("name", base.name), **parts)


def _case_from_tables(tables: Mapping, default_name: str) -> Case:
    reject_unknown(tables, ["name", *_TABLES, *_OPTIONAL_TABLES], "")
    parts = {part: _build(cls, tables.get(part, {}), part) for part, cls in _TABLES.items()}
    parts |= {part: _build(cls, tables[part], part)
              for part, cls in _OPTIONAL_TABLES.items() if part in tables}
    return Case(name=tables.get("name", default_name), **parts)

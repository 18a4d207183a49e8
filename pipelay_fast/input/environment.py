"""The ``environment`` table (water depth and density, the ``current``
subtable) and the ``seabed`` table, validated on construction."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .validate import (
    assign,
    choice,
    fail,
    instance,
    set_numbers,
    vector,
)

PROFILES = ("uniform", "linear", "power", "table")


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
        """True for a rigid seabed (``stiffness`` None)."""
        return self.stiffness is None

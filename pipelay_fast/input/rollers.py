"""The roller stinger, table ``[lay.stinger]`` with ``rollers`` (or a
``radius`` path) instead of the quadratic curve's ``a``: validated on
construction (:class:`.lay.Lay` checks the rollers against its top and the
seabed)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .limits import ROUNDOFF
from .validate import assign, choice, fail, integer, set_numbers, vector

__all__ = ["ROLLER_TYPES", "RollerStinger"]

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

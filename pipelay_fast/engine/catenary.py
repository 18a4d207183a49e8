"""The natural catenary: the zero-stiffness estimate and the solver's first guess
(engine layer).

A cable of effective weight ``w1`` per length below the water surface (height
``depth``) and ``w2`` above it touches the seabed tangentially at the touchdown
point (s = 0, x = 0, z = 0), at the seabed's slope ``tan0`` (0: flat), and rises
with constant horizontal tension ``h``. With V(s) the weight of the span below
s, tan(theta) = tan0 + V/h and, on each stretch of constant weight w from a
point (x0, z0) where tan(theta) = tan1,

    x = x0 + (h/w) (sqrt(1 + tan^2) - sqrt(1 + tan1^2)),
    z = z0 + (h/w) (asinh tan - asinh tan1),     Te = h sqrt(1 + tan^2).

Heights are from touchdown (a sloped seabed's caller passes ``depth`` and
``x_top`` less the touchdown's height).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Catenary:
    """A natural catenary from the touchdown point up to height ``x_top``.

    Attributes
    ----------
    h : float
        Horizontal (= bottom effective) tension [N].
    w1, w2 : float
        Effective weight below / above the water surface [N/m].
    depth : float
        Water depth [m].
    x_top : float
        Height of the upper end [m].
    tan0 : float
        Slope of the pipe at touchdown, the seabed's [-]; default 0 (flat).
    """

    h: float
    w1: float
    w2: float
    depth: float
    x_top: float
    tan0: float = 0.0

    @property
    def _sec0(self) -> float:
        """sqrt(1 + tan0^2): Te / h at touchdown [-] (1.0 flat)."""
        return float(np.sqrt(1.0 + self.tan0 * self.tan0))

    @property
    def _s_surface(self) -> float:
        """Arc length from touchdown to the water surface [m] (inf if never reached)."""
        if self.x_top <= self.depth:
            return np.inf
        c = self._sec0 + self.w1 * self.depth / self.h
        return self.h / self.w1 * (np.sqrt(c * c - 1.0) - self.tan0)

    @property
    def top_tension(self) -> float:
        """Effective tension at the top [N]."""
        below = min(self.x_top, self.depth)
        return self.h * self._sec0 + self.w1 * below + self.w2 * max(self.x_top - self.depth, 0.0)

    @property
    def length(self) -> float:
        """Suspended arc length from touchdown to the top [m]."""
        sec = self.top_tension / self.h
        tan_top = np.sqrt(sec * sec - 1.0)
        sd = self._s_surface
        if not np.isfinite(sd):
            return self.h * (tan_top - self.tan0) / self.w1
        return sd + (self.h * (tan_top - self.tan0) - self.w1 * sd) / self.w2

    def at(self, s):
        """Shape at arc lengths ``s`` [m] from touchdown: x, z [m], theta [rad], Te [N]."""
        s = np.asarray(s, dtype=np.float64)
        sd = self._s_surface
        below = s <= sd
        above = self.w1 * sd + self.w2 * (s - sd) if np.isfinite(sd) else 0.0
        v = np.where(below, self.w1 * s, above)
        tan = self.tan0 + v / self.h
        sec = np.sqrt(1.0 + tan * tan)
        sec0, asinh0 = self._sec0, np.arcsinh(self.tan0)
        x1 = self.h / self.w1 * (sec - sec0)
        z1 = self.h / self.w1 * (np.arcsinh(tan) - asinh0)
        if np.isfinite(sd):
            tan_d = self.tan0 + self.w1 * sd / self.h
            sec_d = np.sqrt(1.0 + tan_d * tan_d)
            x2 = self.depth + self.h / self.w2 * (sec - sec_d)
            z2 = (self.h / self.w1 * (np.arcsinh(tan_d) - asinh0)
                  + self.h / self.w2 * (np.arcsinh(tan) - np.arcsinh(tan_d)))
            x = np.where(below, x1, x2)
            z = np.where(below, z1, z2)
        else:
            x, z = x1, z1
        return x, z, np.arctan(tan), self.h * sec

    @property
    def span(self) -> float:
        """Horizontal distance from touchdown to the top [m]."""
        return float(self.at(self.length)[1])

    @property
    def top_angle(self) -> float:
        """Angle of the top tangent above horizontal [rad]."""
        return float(np.arccos(self.h / self.top_tension))


def from_top_tension(t_top, w1, w2, depth, x_top, tan0: float = 0.0) -> Catenary:
    """The catenary whose top effective tension is ``t_top`` [N], of weights
    ``w1``, ``w2`` [N/m] below and above the surface at height ``depth`` [m],
    its top at height ``x_top`` [m], touching down at the slope ``tan0``.
    ValueError when ``t_top`` is not above the weight of a vertical hang to
    ``x_top``."""
    h = t_top - w1 * min(x_top, depth) - w2 * max(x_top - depth, 0.0)
    if h <= 0.0:
        raise ValueError(
            f"lay.top_tension = {t_top:g} N is too low to hold the pipe: the weight of a "
            f"vertical hang to x = {x_top:g} m alone needs {t_top - h:g} N"
        )
    if tan0 != 0.0:
        h /= float(np.sqrt(1.0 + tan0 * tan0))
    return Catenary(h, w1, w2, depth, x_top, tan0)

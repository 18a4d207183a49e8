"""The current's drag on a solved pipe, integrated from its profile
independently of the engine's element loads: Morison's normal part under
the power-law current, by the trapezoidal rule over the nodes."""

from __future__ import annotations

import math

import numpy as np


def drag_vector(case, prof) -> np.ndarray:
    """Drag (x, y, z) [N] on the deformed pipe (Morison, normal part, the
    power-law current along its heading in the y-z plane), integrated by
    the trapezoidal rule over the nodes."""
    pipe, env = case.pipe, case.environment
    q0 = 0.5 * env.water_density * pipe.drag_coefficient * pipe.hydrodynamic_diameter
    r = prof[["x", "y", "z"]].to_numpy()
    heading = math.radians(env.current.heading)
    e = np.array([0.0, math.sin(heading), math.cos(heading)])
    height = np.clip(r[:, 0] / env.water_depth, 0.0, None)
    v = (env.current.speed * height**env.current.exponent)[:, None] * e
    s = prof["s"].to_numpy()
    t = np.gradient(r, s, axis=0)
    t /= np.linalg.norm(t, axis=1)[:, None]
    vn = v - np.sum(v * t, axis=1)[:, None] * t
    f = q0 * np.linalg.norm(vn, axis=1)[:, None] * vn * (r[:, :1] <= env.water_depth)
    return np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(s)[:, None], axis=0)

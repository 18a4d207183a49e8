"""From a validated :class:`~pipelay_fast.case.Case` to the flat arrays of the kernels."""

from __future__ import annotations

import math

import numpy as np

from .case import Case
from .kernels import layout as L

_PROFILES = {
    "uniform": L.PROFILE_UNIFORM,
    "linear": L.PROFILE_LINEAR,
    "power": L.PROFILE_POWER,
    "table": L.PROFILE_TABLE,
}


def dimension_of(case: Case) -> int:
    """Space dimension the case is solved in: 2 when every load is planar ("auto")."""
    if case.solver.dimension == "2d":
        if not case.is_planar:
            raise ValueError(
                "solver.dimension = '2d' but the loads are not planar "
                "(lateral current, torque or an out-of-plane distributed moment): "
                "use '3d' or 'auto'"
            )
        return 2
    if case.solver.dimension == "3d":
        return 3
    return 2 if case.is_planar else 3


def build_props(case: Case, gravity_factor: float = 1.0, current_factor: float = 1.0):
    """The ``props`` vector and the current table ``[[x, speed], ...]`` of a case."""
    pipe = case.pipe
    env = case.environment
    cur = env.current
    p = np.zeros(L.N_PROPS)
    p[L.EI] = pipe.bending_stiffness
    p[L.EA] = pipe.axial_stiffness
    p[L.W_DRY] = case.weight_dry
    p[L.W_CONT] = case.weight_contents
    p[L.H_CONT] = pipe.contents_level
    p[L.W_BUOY] = case.buoyancy
    p[L.DEPTH] = env.water_depth
    p[L.RHOW_G] = env.water_density * env.gravity
    p[L.RHOI_G] = pipe.contents_density * env.gravity
    p[L.AREA_I] = pipe.inner_area
    p[L.AREA_E] = pipe.outer_area
    p[L.DRAG] = 0.5 * env.water_density * pipe.drag_coefficient * pipe.hydrodynamic_diameter
    p[L.CUR_SPEED] = cur.speed
    heading = math.radians(cur.heading)
    p[L.CUR_EY] = math.sin(heading)
    p[L.CUR_EZ] = math.cos(heading)
    p[L.CUR_PROFILE] = _PROFILES[cur.profile]
    p[L.CUR_EXP] = cur.exponent
    p[L.SEABED_K] = 0.0 if case.seabed.stiffness is None else float(case.seabed.stiffness)
    p[L.EXTENSIBLE] = 1.0 if pipe.extensible else 0.0
    p[L.TORQUE] = case.lay.torque
    p[L.MOM_X], p[L.MOM_Y], p[L.MOM_Z] = case.lay.distributed_moment
    p[L.GRAVITY_FACTOR] = gravity_factor
    p[L.CURRENT_FACTOR] = current_factor
    p[L.MU_Y] = case.seabed.lateral_friction
    p[L.MU_Z] = case.seabed.axial_friction
    p[L.FRICTION_SLIP] = case.seabed.friction_slip
    p[L.FRICTION_ON] = 0.0  # switched on for the current's load path (solver)
    if cur.profile == "table" and cur.table:
        table = np.ascontiguousarray(np.array(cur.table, dtype=np.float64).reshape(-1, 2))
    else:
        table = np.zeros((1, 2))
    return p, table

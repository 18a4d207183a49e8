"""From a validated :class:`~pipelay_fast.input.case.Case` to the flat arrays of
the kernels (engine layer): the dimension solved in, the ``props`` vector and the
current table, the per-element ``section`` array, and the tension jump at a
pinned S-lay top."""

from __future__ import annotations

import contextlib
import math
import threading

import numpy as np

from ..input.case import Case
from ..kernels import layout as L
from ..kernels.scene import Scene, union

_PROFILES = {
    "uniform": L.PROFILE_UNIFORM,
    "linear": L.PROFILE_LINEAR,
    "power": L.PROFILE_POWER,
    "table": L.PROFILE_TABLE,
}


# per thread (a sweep's tasks may run in threads of one process: dask's
# threaded workers): .scenes, dimension -> the scene its cases are compiled
# with at least
_SHARED = threading.local()


@contextlib.contextmanager
def shared_scenes(scenes: dict):
    """Within the block, in this thread, a case of dimension nd is compiled
    with at least the features of ``scenes[nd]`` (:func:`scene_of`): a
    sweep's cases then share one Newton kernel per dimension
    (:func:`pipelay_fast.study.runner.sweep_scenes`)."""
    saved = getattr(_SHARED, "scenes", {})
    _SHARED.scenes = dict(scenes)
    try:
        yield
    finally:
        _SHARED.scenes = saved


def scene_of(case: Case) -> Scene:
    """The features ``case``'s Newton kernel is compiled with
    (:mod:`..kernels.scene`): seabed friction when a coefficient that acts
    in its dimension is above 0 (the axial one; the lateral one in 3D), the
    stinger when it has one (a curve or rollers: S-lay); and those of
    :func:`shared_scenes`."""
    nd = dimension_of(case)
    friction = case.seabed.axial_friction > 0.0 or (nd == 3 and case.seabed.lateral_friction > 0.0)
    own = Scene(friction=bool(friction), stinger=case.lay.curve is not None or case.lay.has_rollers)
    return union(own, getattr(_SHARED, "scenes", {}).get(nd, own))


def dimension_of(case: Case) -> int:
    """Space dimension the case is solved in, 2 or 3: 2 when every load is
    planar ("auto"). ValueError for "2d" with loads out of the plane."""
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


def build_props(case: Case):
    """The ``props`` vector of the scene (``layout.N_PROPS`` floats, SI, one per
    slot of :mod:`pipelay_fast.kernels.layout`) and the current table ``[[x,
    speed], ...]`` ([m], [m/s]; one zero row without a table profile) of a
    case (its data only: the load path's factors are the solver's, layout
    ``F_*``; the pipe's section is :func:`sections_of`'s)."""
    pipe = case.pipe
    env = case.environment
    cur = env.current
    p = np.zeros(L.N_PROPS)
    p[L.EI_REF] = pipe.bending_stiffness
    p[L.H_CONT] = pipe.contents_level
    p[L.DEPTH] = env.water_depth
    p[L.RHOW_G] = env.water_density * env.gravity
    p[L.RHOI_G] = pipe.contents_density * env.gravity
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
    p[L.MU_Y] = case.seabed.lateral_friction
    p[L.MU_Z] = case.seabed.axial_friction
    p[L.FRICTION_SLIP] = case.seabed.friction_slip
    p[L.SEABED_TAN] = math.tan(case.seabed.slope)
    p[L.SEABED_Z0] = case.seabed.slope_origin
    if cur.profile == "table" and cur.table:
        table = np.ascontiguousarray(np.array(cur.table, dtype=np.float64).reshape(-1, 2))
    else:
        table = np.zeros((1, 2))
    return p, table


def section_row(case: Case) -> np.ndarray:
    """The case's pipe as a ``section`` row (``layout.N_SECTION`` floats, SI,
    the ``S_*`` slots: EI [N m2], EA [N], the dry, contents and buoyancy
    weights [N/m], the steel's inner and outer areas [m2], the drag's 1/2
    rho_w C_D D_h [kg/m2])."""
    pipe = case.pipe
    env = case.environment
    row = np.zeros(L.N_SECTION)
    row[L.S_EI] = pipe.bending_stiffness
    row[L.S_EA] = pipe.axial_stiffness
    row[L.S_W_DRY] = case.weight_dry
    row[L.S_W_CONT] = case.weight_contents
    row[L.S_W_BUOY] = case.buoyancy
    row[L.S_AREA_I] = pipe.inner_area
    row[L.S_AREA_E] = pipe.outer_area
    row[L.S_DRAG] = 0.5 * env.water_density * pipe.drag_coefficient * pipe.hydrodynamic_diameter
    return row


def sections_of(case: Case) -> list[tuple[float, np.ndarray]]:
    """The sections along the line, from the top down: ``(start, row)`` pairs,
    ``start`` [m] the unstretched arc length from the top (the vessel's end, a
    material point that stays where it is when laid pipe is added or cut at
    the lower end) at which the section begins, the first 0, increasing;
    ``row`` its :func:`section_row`. A case has one section, its pipe."""
    return [(0.0, section_row(case))]


def section_array(s: np.ndarray, sections) -> np.ndarray:
    """The kernels' ``section`` array ((n_elements, N_SECTION), C-contiguous)
    of the mesh with nodes ``s`` [m] (increasing from the lower end to the
    top): element e gets the row of the section its midpoint lies in, its
    distance from the top s[-1] - (s[e] + s[e+1]) / 2 measured against the
    ``sections``' starts (:func:`sections_of`). A section joint that is to
    fall on an element boundary has to be a node of the mesh: an element
    across it takes the section of its midpoint."""
    s = np.asarray(s, dtype=np.float64)
    rows = np.array([row for _start, row in sections], dtype=np.float64).reshape(-1, L.N_SECTION)
    starts = np.array([start for start, _row in sections], dtype=np.float64)
    depth = s[-1] - 0.5 * (s[:-1] + s[1:])  # each element's midpoint, from the top
    which = np.clip(np.searchsorted(starts, depth, side="right") - 1, 0, len(starts) - 1)
    return np.ascontiguousarray(rows[which])


def pin_jump(case: Case) -> float:
    """Jump of the effective tension across a pinned S-lay top [N], else 0.

    On a curved stinger the pipe conforms up to a pinned top, so its moment
    falls from M_U = EI kappa_U (the stinger's curvature at its upper end) to
    zero at the pin. Along the pipe Te + M^2/(2 EI) - W(x) is constant (the
    rod's first integral: Te' = w x' - (M^2/2EI)', normal reactions doing no
    tangential work), so across the pin Te jumps by M_U^2/(2 EI): the pipe
    below the pin is the firing line's with the top tension that much lower.
    It is the limit of any model of the pin zone in which the support's
    reaction is normal (a stiff elastic stinger: the reaction's tangential
    share integrates to k gap^2/2, zero at both ends of the zone); a clamp to
    the curve one element below the pin instead puts 1.5 M_U there and
    returns only part of the difference (the tests' reference,
    tests/test_slay.py).
    """
    lay = case.lay
    if lay.curve is None or lay.top_angle != "pinned":
        return 0.0
    moment = case.pipe.bending_stiffness * float(lay.curve.curvature(lay.curve.upper[1]))
    return moment * moment / (2.0 * case.pipe.bending_stiffness)

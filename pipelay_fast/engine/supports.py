"""The supports of a problem as one table, built here only: one row per
support, in the order of the contact boundaries (:mod:`pipelay_fast.kernels.layout`
``ROW_*``: row b is boundary b's support), each a kind (``SUP_*``), its
parameters (a row of N_GEOM floats) and the nodes it holds (int8 per node).

* row ``ROW_BED``: the seabed, the plane x = tan(angle) (z - z0) through
  the reference level x = 0 (``SUP_SEABED``, ``SB_*``, :func:`seabed_row`;
  its elastic stiffness is ``props[SEABED_K]``), touchdown's support;
* row ``ROW_CURVE``: the quadratic stinger (``SUP_CURVE``, ``ST_*``; a
  trimmed vessel's turned, :class:`pipelay_fast.input.trim.TrimmedStinger`),
  lift-off's; an empty row (``SUP_NONE``) in J-lay and on a roller stinger;
* rows ``ROW_PT + j``: the rigid points (``SUP_POINT``, ``PT_*``: the quadratic
  stinger's tip, or a roller stinger's rollers), point j's boundary B_PT + j.

The kernels read a support's geometry through :mod:`pipelay_fast.kernels.supports`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..input.parabola import turned
from ..input.profile import bed_heights
from ..kernels import layout as L


def support_table(nn: int, curve=None, points=None, seabed=(0.0, 0.0, 0.0)):
    """(kind (n_sup,) int64, geom (n_sup, N_GEOM), active (n_sup, nn) int8)
    for ``nn`` nodes: the seabed ``seabed`` (level [m], angle [rad], z0 [m]:
    x = level + tan(angle) (z - z0), :func:`seabed_row`), the stinger's curve
    ``curve`` (a, b, c, zL, zU, turn: layout ``ST_*``; None: none) and the
    rigid points ``points`` (n_points, N_PT; None: none), no node held yet."""
    n_pt = 0 if points is None else len(points)
    n_sup = L.ROW_PT + n_pt
    kind = np.full(n_sup, L.SUP_NONE, dtype=np.int64)
    geom = np.zeros((n_sup, L.N_GEOM))
    kind[L.ROW_BED] = L.SUP_SEABED
    geom[L.ROW_BED, [L.SB_LEVEL, L.SB_ANGLE, L.SB_Z0]] = seabed
    if curve is not None:
        kind[L.ROW_CURVE] = L.SUP_CURVE
        geom[L.ROW_CURVE, :L.N_STINGER] = curve
    if n_pt:
        kind[L.ROW_PT:] = L.SUP_POINT
        geom[L.ROW_PT:, :L.N_PT] = points
    return kind, geom, np.zeros((n_sup, nn), dtype=np.int8)



def line_height(kind: int, g, z):
    """(x, dx/dz) of line support ``kind`` with parameters ``g`` at z [m]
    (NumPy: an array or a scalar), for the Python layer: the arithmetic of
    :func:`pipelay_fast.kernels.supports.support_height`, to the bit."""
    if kind == L.SUP_CURVE:
        if g[L.ST_TURN] != 0.0:  # a trimmed vessel's
            return turned(g[L.ST_A], g[L.ST_B], g[L.ST_C], g[L.ST_TURN], z)[:2]
        return (g[L.ST_A] * z + g[L.ST_B]) * z + g[L.ST_C], 2.0 * g[L.ST_A] * z + g[L.ST_B]
    if kind == L.SUP_SEABED:
        slope = np.tan(g[L.SB_ANGLE])
        return g[L.SB_LEVEL] + slope * (z - g[L.SB_Z0]), slope + 0.0 * z
    raise ValueError(f"line_height: support kind {kind} is not a line")


def seabed_row(seabed) -> tuple[float, float, float]:
    """The seabed's parameters (level [m], angle [rad], z0 [m]) of the
    input's ``seabed`` table: the plane through the reference level x = 0 at
    z = ``slope_origin``."""
    return 0.0, seabed.slope, seabed.slope_origin


def surface_heights(props, bed, z):
    """(x [m], dx/dz [-]) at ``z`` [m] (an array) of the elastic seabed's
    surface: the arithmetic of :func:`pipelay_fast.kernels.loads.seabed_surface`
    (the sloped plane of ``props``, else the profile's knots ``bed``)."""
    z = np.asarray(z, dtype=float)
    m = props[L.SEABED_TAN]
    if m != 0.0:
        return m * (z - props[L.SEABED_Z0]), np.full(z.shape, m)
    return bed_heights(bed, z)


def seabed_height(case, z):
    """The seabed's height x [m] at z [m] (an array or a scalar) of ``case``."""
    return line_height(L.SUP_SEABED, np.array(seabed_row(case.seabed)), z)[0]


def line_span(kind: int, g) -> tuple[float, float]:
    """(z_low, z_high) [m] the line support holds, as
    :func:`pipelay_fast.kernels.supports.support_span` (a curve's lower end is
    the stinger's tip)."""
    if kind == L.SUP_CURVE:
        return float(g[L.ST_ZL]), float(g[L.ST_ZU])
    return -np.inf, np.inf

@dataclass
class Contacts:
    """The contact sets and the states of the contacts, which the Newton
    kernel updates (and :mod:`.boundaries` at a switch of regime at the
    stinger's tip).

    ``kind``, ``geom``, ``active``: the supports' table
    (:func:`support_table`: the seabed, the stinger's curve, the rigid
    points), and views of it: ``bed_active``, ``st_active`` (nn,) int8
    the seabed and stinger contact sets; ``points`` (n_points, N_PT) the
    rigid points (the tip, rollers; layout ``PT_*``: position [m], bearing,
    reaction [N], lateral hold); ``fric`` (nn, N_FRIC): the friction springs
    (layout ``FR_*``);
    ``phi_r``, ``phi_rp`` (nn,) [rad]: the nodal frames' rotations of r and
    r' (a node on the stinger: its tangent); ``y_held`` (nn,) bool: the
    nodes the stinger held laterally in the last Newton call.
    """

    kind: np.ndarray
    geom: np.ndarray
    active: np.ndarray
    fric: np.ndarray
    phi_r: np.ndarray
    phi_rp: np.ndarray
    y_held: np.ndarray

    @property
    def bed_active(self) -> np.ndarray:
        return self.active[L.ROW_BED]

    @property
    def st_active(self) -> np.ndarray:
        return self.active[L.ROW_CURVE]

    @property
    def points(self) -> np.ndarray:
        return self.geom[L.ROW_PT:]

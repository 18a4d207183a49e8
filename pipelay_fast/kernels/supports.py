"""The supports' geometry as kernels: each support a kind (:mod:`.layout`
``SUP_*``) and its row of parameters ``g`` (a row of ``Supports.geom``,
columns named per kind: ``SB_*``, ``ST_*``, ``PT_*``).

The Newton kernel reaches a support's geometry only through these
functions, each a branch per kind, so a new kind is a new branch here (and
its row in :func:`pipelay_fast.engine.supports.support_table`), not a new
path in the iteration:

* :func:`support_height`: a line support's height x = f(z) [m] and its
  derivatives (a point's: its own height);
* :func:`support_angle`: its tangent's angle above horizontal [rad], the
  frame its reactions are reported in;
* :func:`support_span`: the z range it holds [m] (a curve's lower end is the
  stinger's tip);
* :func:`support_gap`: a position's clearance above it [m] (a point's along
  the normal of a frame turned by ``phi``);
* :func:`in_curve_coords`, :func:`holds_laterally`: whether its contact
  nodes are held in curve coordinates x = f(z) + c (:mod:`.system`), and
  on the stinger's plane (3D);
* :func:`frame_angle`, :func:`normal_offset`: the nodal frame a support
  holds its contacts in (the seabed's: turned by its angle, so that slot x
  is its normal and slot z its tangent) and the normal coordinate of its
  line in that frame;
* :func:`tangency`: the pipe tangent to it at a boundary node whose slope is
  otherwise free (lift-off's equation).

The seabed is a plane x = level + tan(angle) (z - z0) (layout ``SB_*``); at
angle 0 its arithmetic reduces to the flat seabed's to the bit (tan 0 = sin
0 = 0, cos 0 = 1 exactly), and :func:`tangency` keeps the flat seabed's own
branch where the general form would round differently (x' against x' - 0
z'). The small ones are phases (:func:`._jit.phase`, inlined into their
callers), so that they add no kernel of their own to compile.
"""

from __future__ import annotations

import math

from ._jit import jit, phase
from .layout import (
    PT_X,
    PT_Z,
    SB_ANGLE,
    SB_LEVEL,
    SB_Z0,
    ST_A,
    ST_B,
    ST_C,
    ST_ZL,
    ST_ZU,
    SUP_CURVE,
    SUP_POINT,
    SUP_SEABED,
)


@phase
def support_height(kind, g, z):
    """(f, f', f'') of support ``kind`` with parameters ``g`` at z [m]: its
    height x [m], dx/dz [-], d2x/dz2 [1/m]; a point's: its height, 0, 0."""
    if kind == SUP_CURVE:
        fpp = 2.0 * g[ST_A]
        return (g[ST_A] * z + g[ST_B]) * z + g[ST_C], fpp * z + g[ST_B], fpp
    if kind == SUP_POINT:
        return g[PT_X], 0.0, 0.0
    slope = math.tan(g[SB_ANGLE])
    return g[SB_LEVEL] + slope * (z - g[SB_Z0]), slope, 0.0


@phase
def support_angle(kind, g, z):
    """Angle [rad] of the support's tangent above horizontal at z [m]."""
    if kind == SUP_CURVE:
        return math.atan(2.0 * g[ST_A] * z + g[ST_B])
    if kind == SUP_SEABED:
        return g[SB_ANGLE]
    return 0.0


@phase
def support_span(kind, g):
    """(z_low, z_high) [m]: the z range the support holds (a curve's lower
    end is the stinger's tip; the seabed's is unbounded)."""
    if kind == SUP_CURVE:
        return g[ST_ZL], g[ST_ZU]
    if kind == SUP_POINT:
        return g[PT_Z], g[PT_Z]
    return -math.inf, math.inf


@phase
def support_gap(kind, g, x, z, phi):
    """Clearance [m] of the position (x, z) above the support: x - f(z) for
    a line support; for a point, along the normal of a frame turned by
    ``phi`` [rad] (the pipe's, :func:`.constraints._over_point`); the
    seabed's is vertical, x - f(z)."""
    if kind == SUP_POINT:
        return math.cos(phi) * (x - g[PT_X]) - math.sin(phi) * (z - g[PT_Z])
    if kind == SUP_CURVE:
        return x - ((g[ST_A] * z + g[ST_B]) * z + g[ST_C])
    return x - (g[SB_LEVEL] + math.tan(g[SB_ANGLE]) * (z - g[SB_Z0]))


@phase
def frame_angle(kind, g):
    """The angle [rad] of the nodal frames support ``kind`` holds its
    contacts in (:func:`.assembly.rotate_node`: slot x its normal, slot z its
    tangent): the seabed's angle (0 when flat: the global frame); 0 for the
    others (a curve's contacts are in curve coordinates, a point's node in
    the pipe's frame, :func:`.constraints._nodal_frames`)."""
    if kind == SUP_SEABED:
        return g[SB_ANGLE]
    return 0.0


@phase
def normal_offset(kind, g):
    """The seabed's normal coordinate [m] in its frame (:func:`frame_angle`):
    x cos(angle) - z sin(angle) on its plane, level cos(angle) - z0
    sin(angle) (the level when flat)."""
    a = g[SB_ANGLE]
    return g[SB_LEVEL] * math.cos(a) - g[SB_Z0] * math.sin(a)


@phase
def in_curve_coords(kind):
    """Whether the support's contact nodes are held in its curve
    coordinates x = f(z) + c, x' = f'(z) z' + c' (c = c' = 0 held)."""
    return kind == SUP_CURVE


@phase
def holds_laterally(kind):
    """Whether the support holds the pipe on its plane (y = 0, y' = 0, 3D)
    over its z range (:func:`.contact.lateral_hold`)."""
    return kind == SUP_CURVE


@jit(_nrt=False)
def tangency(nd, u, kind, g, node, row):
    """The pipe tangent to its support at node ``node``: x' - f'(z) z' = 0
    (x' = 0 on the flat seabed); lift-off's equation. ``row`` gets its
    derivative d/du (global frame); an empty ``row``: the value alone."""
    ndn = 2 * nd + 1
    base = node * ndn
    want = row.shape[0] > 0
    if want:
        for i in range(row.shape[0]):
            row[i] = 0.0
        row[base + nd] = 1.0
    if kind == SUP_SEABED and g[SB_ANGLE] == 0.0:
        return u[base + nd]
    _f, fp, fpp = support_height(kind, g, u[base + nd - 1])
    zp = u[base + 2 * nd - 1]
    if want:
        row[base + nd - 1] = -fpp * zp
        row[base + 2 * nd - 1] = -fp
    return u[base + nd] - fp * zp

"""Seabed friction along the current's load path: whether a case takes that
path, the laid length it needs, and the springs' anchors."""

from __future__ import annotations

import math

import numpy as np

from ..input.case import Case
from ..kernels import layout as L
from . import tuning as T
from .model import dimension_of


def slipping_length_bound(case: Case, cat) -> float:
    """Laid length [m] over which friction takes up the lateral drag's share at
    touchdown, so that the held lower end carries none (0 off the friction
    path or without a lateral current).

    The suspended span, the natural catenary ``cat`` (:mod:`.catenary`), as a
    taut string from touchdown to its top, straight in height: the lateral
    drag q(t) on it puts a share int q (1 - t) ds on touchdown, which friction
    mu w carries over its slipping length. The string ignores the pipe's
    lateral bending and the drag's fall as the pipe swings, so this bounds the
    slipping length found (about twice it in J125, 1 and 2 m/s).
    """
    ey = case.current_direction[0]
    if not (friction_path(case) and dimension_of(case) == 3 and ey != 0.0):
        return 0.0
    pipe = case.pipe
    drag = 0.5 * case.environment.water_density * pipe.drag_coefficient * pipe.hydrodynamic_diameter
    share = cat.length * drag * ey * ey * drag_share(case, cat.x_top)
    return share / _sliding_force(case)


def drag_share(case: Case, x_top: float) -> float:
    """int_0^1 V(t x_top)^2 (1 - t) dt [m2/s2]: the squared current speed V
    [m/s] on a straight string from the seabed (t = 0) to the height
    ``x_top`` [m] (t = 1), weighted by its share on the lower end; V = 0 above
    the surface. In closed form for the uniform, linear and power profiles;
    for a table (V piecewise linear, the integrand a cubic between its
    heights) by Simpson's rule on each piece, which is exact there."""
    cur, depth = case.environment.current, case.environment.water_depth
    t_d = depth / x_top  # the surface's t
    t_s = min(1.0, t_d)
    if cur.profile == "uniform":
        return cur.speed**2 * (t_s - t_s**2 / 2.0)
    if cur.profile == "linear":
        return (cur.speed / t_d) ** 2 * (t_s**3 / 3.0 - t_s**4 / 4.0)
    if cur.profile == "power":
        e = 2.0 * cur.exponent
        return cur.speed**2 / t_d**e * (t_s ** (e + 1.0) / (e + 1.0) - t_s ** (e + 2.0) / (e + 2.0))
    heights = np.array(cur.table, dtype=float)[:, 0] / x_top
    knots = np.unique(np.concatenate(([0.0, t_s], heights[(heights > 0.0) & (heights < t_s)])))
    a, b = knots[:-1], knots[1:]

    def integrand(t):
        return np.asarray(case.current_speed_at(t * x_top)) ** 2 * (1.0 - t)

    return float(np.sum((b - a) / 6.0 * (integrand(a) + 4.0 * integrand((a + b) / 2.0)
                                          + integrand(b))))


def _sliding_force(case: Case) -> float:
    """Lateral friction of the laid pipe when sliding, mu w cos(slope) [N/m]
    (the normal force from the seabed's plane)."""
    return (case.seabed.lateral_friction * float(case.effective_weight(0.0))
            * math.cos(case.seabed.slope))


def friction_laid_length(case: Case, cat) -> float:
    """Laid length [m] the friction path needs behind touchdown: the slipping
    length (:func:`slipping_length_bound`) and tuning.DECAY_LENGTHS decay
    lengths of the sticking zone behind it, where the sticking springs (mu w
    / friction_slip per m) hold the pipe as an elastic foundation and the
    force left decays over (4 EI friction_slip / mu w)^(1/4) (0 where the
    slipping length is)."""
    slip = slipping_length_bound(case, cat)
    if slip <= 0.0:
        return 0.0
    decay = (4.0 * case.pipe.bending_stiffness * case.seabed.friction_slip
             / _sliding_force(case)) ** 0.25
    return slip + T.DECAY_LENGTHS * decay


def friction_path(case: Case) -> bool:
    """True when seabed friction meets the current: its load path is followed.
    Lateral friction needs a lateral load: under planar loads (an in-plane
    current) the 3D pipe stays in its plane, the lateral springs carry
    nothing, and the solve is the 2D one's."""
    lateral = (dimension_of(case) == 3 and case.seabed.lateral_friction > 0.0
               and not case.is_planar)
    return (lateral or case.seabed.axial_friction > 0.0) and case.environment.current.speed > 0.0


def anchor_friction(fric, u, nd, s, props):
    """Friction springs unstretched: anchors at the nodes' present positions
    and material points (arc lengths ``s`` [m]); the axial one's along the
    seabed plane's tangent (:func:`..kernels.contact.slip_coordinate`, z on
    the flat seabed, ``props`` the model's properties)."""
    fric[:, L.FR_S] = s
    lateral, along = slip_positions(u, nd, props)
    fric[:, L.FR_Z] = along
    if lateral is not None:
        fric[:, L.FR_Y] = lateral
    fric[:, L.FR_DIR] = 0.0
    fric[:, L.FR_DIRZ] = 0.0


def slip_positions(u, nd, props):
    """The nodes' coordinates [m] the friction springs measure in the state
    ``u``: (y, lateral; None in 2D) and along the seabed plane's tangent
    (:func:`..kernels.contact.slip_coordinate`, z on the flat seabed)."""
    ndn = 2 * nd + 1
    m = props[L.SEABED_TAN]  # the plane's tangent (m c, c), as the kernels' plane_tangent
    c = 1.0 / math.sqrt(1.0 + m * m)
    along = u[nd - 1::ndn] if m == 0.0 else m * c * u[0::ndn] + c * u[nd - 1::ndn]
    return (u[1::ndn] if nd == 3 else None), along

"""Seabed friction along the current's load path: whether a case takes that
path, the laid length it needs, and the springs' anchors."""

from __future__ import annotations

import numpy as np

from ..input.case import Case
from ..kernels import layout as L
from .model import dimension_of

# Decay lengths of the sticking zone behind the slipping one the laid pipe
# modelled holds: e^-3, the held lower end's share of the lateral force 5 %
# of what it was at the slipping zone's end. Without them S67 3D at 2 m left
# the held lower end 0.4 to 1 % of the laid pipe's lateral force (a = -0.0022
# to -0.0009; the laid pipe doubled above 1 %, from a = -0.0008), and a warm
# start from a neighbour whose laid pipe had been doubled solved another
# domain: 4.7e-6 from the cold peak stress (S67 3D 2 m, a = -0.0009 from
# -0.00088), 8.6e-8 with them; 0.02 to 0.05 % left at the lower end, 17
# elements more of 235 (4 m: 0.2 % -> 0.015 %, 8 more of 150).
STICK_DECAY_LENGTHS = 3.0


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
    t = np.linspace(0.0, 1.0, 65)
    pipe = case.pipe
    speed = np.asarray(case.current_speed_at(t * cat.x_top)) * ey
    q = (0.5 * case.environment.water_density * pipe.drag_coefficient
         * pipe.hydrodynamic_diameter * speed**2) * (1.0 - t)
    share = cat.length * float(np.sum(0.5 * (q[1:] + q[:-1]) * np.diff(t)))
    return share / _sliding_force(case)


def _sliding_force(case: Case) -> float:
    """Lateral friction of the laid pipe when sliding, mu w [N/m]."""
    return case.seabed.lateral_friction * float(case.effective_weight(0.0))


def friction_laid_length(case: Case, cat) -> float:
    """Laid length [m] the friction path needs behind touchdown: the slipping
    length (:func:`slipping_length_bound`) and STICK_DECAY_LENGTHS decay
    lengths of the sticking zone behind it, where the sticking springs (mu w
    / friction_slip per m) hold the pipe as an elastic foundation and the
    force left decays over (4 EI friction_slip / mu w)^(1/4) (0 where the
    slipping length is)."""
    slip = slipping_length_bound(case, cat)
    if slip <= 0.0:
        return 0.0
    decay = (4.0 * case.pipe.bending_stiffness * case.seabed.friction_slip
             / _sliding_force(case)) ** 0.25
    return slip + STICK_DECAY_LENGTHS * decay


def friction_path(case: Case) -> bool:
    """True when seabed friction meets the current: its load path is followed.
    Lateral friction needs a lateral load: under planar loads (an in-plane
    current) the 3D pipe stays in its plane, the lateral springs carry
    nothing, and the solve is the 2D one's."""
    lateral = (dimension_of(case) == 3 and case.seabed.lateral_friction > 0.0
               and not case.is_planar)
    return (lateral or case.seabed.axial_friction > 0.0) and case.environment.current.speed > 0.0


def anchor_friction(fric, u, nd, s):
    """Friction springs unstretched: anchors at the nodes' present positions
    and material points (arc lengths ``s`` [m])."""
    ndn = 2 * nd + 1
    fric[:, L.FR_S] = s
    fric[:, L.FR_Z] = u[nd - 1::ndn]
    if nd == 3:
        fric[:, L.FR_Y] = u[1::ndn]
    fric[:, L.FR_DIR] = 0.0
    fric[:, L.FR_DIRZ] = 0.0

"""Seabed friction along the current's load path: whether a case takes that
path, the laid length it needs, and the springs' anchors."""

from __future__ import annotations

from scipy.integrate import quad

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

    def on_touchdown(t):  # [N/m] the lateral drag at height t x_top, its share on touchdown
        return drag * (float(case.current_speed_at(t * cat.x_top)) * ey) ** 2 * (1.0 - t)

    share = cat.length * quad(on_touchdown, 0.0, 1.0)[0]  # adaptive, to scipy's tolerance
    return share / _sliding_force(case)


def _sliding_force(case: Case) -> float:
    """Lateral friction of the laid pipe when sliding, mu w [N/m]."""
    return case.seabed.lateral_friction * float(case.effective_weight(0.0))


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

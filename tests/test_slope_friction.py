"""Seabed friction on a sloped seabed with a current (3D): lateral friction
in the seabed's plane, mu_y times the normal force from the plane. The
answer's admissibility, checked here on J125 (150 m of water, the plane
through x = 0 at z = 134 m) at -5 and +5 deg under the paper's power-law
current across the lay (heading 90 deg, and -90 deg for its mirror image):
the seabed contacts push, the reactions, the drag, the weight and the
bottom tension along the plane balance, friction stays in its cone
|f_y| <= mu_y N with N the reaction normal to the plane (and reaches it
where the pipe slides), and the mirrored current gives the mirrored answer."""

from __future__ import annotations

import math

import numpy as np
import pytest

import pipelay_fast as pf
from tests.test_hard_cases import weight_of

SLOPES = (-5.0, 5.0)


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


def _solved(slope: float, heading: float, **more):
    """(case, profile) of J125 3D on the slope under the current."""
    case = pf.load_case("j125_3d").with_changes({
        "checks": None, "environment.water_depth": 150.0, "seabed.slope_deg": slope,
        "seabed.slope_origin": 134.0, "environment.current.speed": 1.0,
        "environment.current.heading": heading, **more})
    res = pf.solve(case)
    assert res.summary["status"] == "ok" and res.summary["dimension"] == "3d"
    return case, res.profile


@pytest.fixture(scope="module")
def answers():
    """(case, profile) per (slope, heading), on the rigid seabed."""
    return {(slope, heading): _solved(slope, heading)
            for slope in SLOPES for heading in (90.0, -90.0)}


def _cone(case, prof, bed, n):
    """|f_y| / (mu_y N) at the seabed nodes ``bed`` with normal forces ``n``."""
    return np.abs(prof["reaction_y"].to_numpy()[bed]) / (case.seabed.lateral_friction * n)


@pytest.mark.parametrize("slope", SLOPES)
def test_friction_on_a_slope_is_admissible(answers, slope):
    case, prof = answers[slope, 90.0]
    assert case.environment.current.profile == "power"
    a = math.radians(slope)
    bed = (prof["contact"] == "seabed").to_numpy() & (prof["s"] > 0.0).to_numpy()
    n = prof["seabed_reaction"].to_numpy()[bed]
    # the contacts push (the normal reaction), and carry the weight where the
    # pipe rests: w cos(a) per metre normal to the plane
    assert n.min() >= 0.0 and bed.sum() > 20
    # the cone in the plane, with the normal force from the plane; the
    # sliding pipe at its edge (the vertical part of N, N cos(a), would
    # leave it at cos(5 deg) = 0.9962 of the edge)
    ratio = _cone(case, prof, bed, n)
    assert ratio.max() <= 1.0 + 1e-6
    assert (np.abs(ratio - 1.0) < 1e-6).sum() > 10
    # the balance: the constraints' forces (the seabed's normal and
    # friction, the vessel's), the drag, the weight and the bottom tension
    # pulling the lower end down the plane's line, -Tb (sin a, 0, cos a)
    w = weight_of(case, prof)
    drag = drag_vector(case, prof)
    tb = prof["effective_tension"].iloc[0]
    total = prof[["reaction_x", "reaction_y", "reaction_z"]].sum().to_numpy() + drag
    total -= np.array([w + tb * math.sin(a), 0.0, tb * math.cos(a)])
    assert abs(total[0]) < 1e-4 * w and abs(total[2]) < 1e-4 * w, total / w
    assert abs(total[1]) < 2e-3 * abs(drag[1]), total[1] / drag[1]


@pytest.mark.parametrize("slope", SLOPES)
def test_the_mirrored_current_gives_the_mirrored_answer(answers, slope):
    """Heading -90 deg is heading 90 deg mirrored in the plane y = 0: y and
    the lateral reactions change sign, the rest is the same (to 1e-9)."""
    _case, a = answers[slope, 90.0]
    _case, b = answers[slope, -90.0]
    scale = a["seabed_reaction"].abs().max()
    for key, sign in (("y", -1.0), ("reaction_y", -1.0), ("x", 1.0), ("z", 1.0),
                      ("seabed_reaction", 1.0), ("effective_tension", 1.0)):
        ref = a[key].to_numpy()
        tol = 1e-9 * (scale if "reaction" in key else max(np.abs(ref).max(), 1.0))
        np.testing.assert_allclose(b[key].to_numpy(), sign * ref, rtol=0, atol=tol, err_msg=key)


@pytest.mark.parametrize("slope", SLOPES)
def test_friction_on_an_elastic_slope_is_admissible(slope):
    """The elastic seabed (1e6 N/m per m) on the slope: its nodal normal
    forces N (the ``seabed_reaction`` column: k times the normal
    penetration over the node's share) push along the plane's normal (cos a,
    0, -sin a); friction stays in the cone mu_y N and reaches it where the
    pipe slides; the forces balance to 5e-4 of the weight (the nodal
    lumping of the foundation, against the elements' Gauss points)."""
    case, prof = _solved(slope, 90.0, **{"seabed.stiffness": 1e6})
    a = math.radians(slope)
    n_all = prof["seabed_reaction"].to_numpy()
    bed = (prof["contact"] == "seabed").to_numpy() & (prof["s"] > 0.0).to_numpy()
    assert n_all.min() >= 0.0 and bed.sum() > 20
    ratio = _cone(case, prof, bed, n_all[bed])
    assert ratio.max() <= 1.0 + 1e-6 and (np.abs(ratio - 1.0) < 1e-6).sum() > 10
    w = weight_of(case, prof)
    drag = drag_vector(case, prof)
    tb = prof["effective_tension"].iloc[0]
    total = prof[["reaction_x", "reaction_y", "reaction_z"]].sum().to_numpy() + drag
    total += n_all.sum() * np.array([math.cos(a), 0.0, -math.sin(a)])
    total -= np.array([w + tb * math.sin(a), 0.0, tb * math.cos(a)])
    assert abs(total[0]) < 5e-4 * w and abs(total[2]) < 5e-4 * w, total / w
    assert abs(total[1]) < 2e-3 * abs(drag[1]), total[1] / drag[1]

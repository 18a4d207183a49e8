"""Touchdown on an elastic seabed is where the pipe's cubic Hermite
clearance crosses the seabed (against scipy's CubicHermiteSpline and PCHIP
with brentq), which moves with the mesh's grading only by the
discretisation's error: on the graded meshes it is the independent
elastica's (scipy's solve_bvp) to 1 mm."""

import copy

import numpy as np
import pytest
from scipy.integrate import solve_bvp
from scipy.interpolate import CubicHermiteSpline
from scipy.optimize import brentq

import pipelay_fast as pf
from pipelay_fast.engine.boundaries import stinger_foci, touchdown_position
from pipelay_fast.engine.problem import remesh
from pipelay_fast.engine.solver import _solve_gravity
from pipelay_fast.input.limits import IterationBudget
from tests.reference.profile import profile_depth
from tests.test_profile_solve import DEPTH, PROFILE, _j125


@pytest.fixture(scope="module")
def on_profile():
    """J125 on the trench and hump, inextensible and its top under water (the
    reference elastica's: one weight, no stretch)."""
    case = _j125(**{"seabed.profile": PROFILE, "pipe.extensible": False,
                    "lay.top": [120.0, 440.0]})
    res = pf.solve(case)
    assert res.summary["status"] == "ok"
    return case, res


def test_touchdown_is_where_the_hermite_clearance_crosses_the_profile(on_profile):
    """The last crossing of the pipe's clearance above the profile, from
    scipy's CubicHermiteSpline of the nodal x(s), z(s) (slopes x', z') and
    the PCHIP of the table: touchdown_position's, to 1e-9 m."""
    _case, res = on_profile
    pb = res.state
    nd, ndn, u, s = pb.nd, pb.ndn, pb.u, pb.s
    x = CubicHermiteSpline(s, u[0::ndn], u[nd::ndn])
    z = CubicHermiteSpline(s, u[nd - 1::ndn], u[2 * nd - 1::ndn])

    def gap(si):
        return x(si) - (DEPTH - profile_depth(PROFILE, z(si)))

    k = int(np.flatnonzero(gap(s) < 0.0)[-1])
    ref = brentq(gap, s[k], s[k + 1], xtol=1e-13)
    assert touchdown_position(pb) == pytest.approx(ref, abs=1e-9)
    assert res.summary["tdp_z"] == pytest.approx(float(z(ref)), abs=1e-6)


def elastica_touchdown(case, res, z_a: float) -> float:
    """z [m] of touchdown of the J-lay ``case`` (inextensible, one weight w,
    current-free, a pinned top under water) on the elastic seabed of its
    profile, independent of the engine: the planar elastica (Z, X, theta,
    kappa, n_X) over arc length from z_a, where it rests on the flat
    profile (X = x_b - w/k, theta = 0), to the top (its position, no
    moment, Te = h cos(theta) + n_X sin(theta) the top tension), its length
    and horizontal force h unknown, the load -w + k max(x_b - X, 0)
    (tests/test_profile_solve.py's foundation), by scipy's solve_bvp from
    the answer ``res``; touchdown where X last crosses x_b."""
    ei, k, w = case.pipe.bending_stiffness, case.seabed.stiffness, float(case.effective_weight(0.0))
    x_top, z_top = case.lay.top
    t_top = case.lay.top_tension

    def xb(z):
        return DEPTH - profile_depth(PROFILE, z)

    def f(t, y, p):
        length, h = p
        z, x, th, kap, nx = y
        return length * np.vstack([np.cos(th), np.sin(th), kap,
                                   (np.sin(th) * h - np.cos(th) * nx) / ei,
                                   w - k * np.maximum(xb(z) - x, 0.0)])

    def bc(ya, yb, p):
        return np.array([ya[0] - z_a, ya[1] - (xb(z_a) - w / k), ya[2], yb[0] - z_top,
                         yb[1] - x_top, yb[3],
                         p[1] * np.cos(yb[2]) + yb[4] * np.sin(yb[2]) - t_top])

    prof = res.profile
    s, z, x, th = (prof[c].to_numpy() for c in ("s", "z", "x", "angle_deg"))
    s0 = np.interp(z_a, z, s)
    length = s[-1] - s0
    t = np.linspace(0.0, 1.0, 4001)
    y = np.zeros((5, t.size))
    y[0], y[1] = np.interp(s0 + length * t, s, z), np.interp(s0 + length * t, s, x)
    y[2] = np.radians(np.interp(s0 + length * t, s, th))
    y[3] = np.gradient(y[2], length * t)
    h = float(prof["effective_tension"].iloc[0])
    y[4] = h * np.tan(y[2])
    sol = solve_bvp(f, bc, t, y, p=[length, h], tol=1e-6, max_nodes=100000)
    assert sol.success, sol.message
    dense = np.linspace(0.0, 1.0, 400001)
    zd, xd = sol.sol(dense)[:2]
    gap = xd - xb(zd)
    i = int(np.flatnonzero(gap < 0.0)[-1])
    return float(zd[i] - (zd[i + 1] - zd[i]) * gap[i] / (gap[i + 1] - gap[i]))


def test_touchdown_moves_with_the_grading_only_by_the_discretisation(on_profile):
    """The mesh graded 0.1 m either side of the touchdown found and solved
    again: touchdown moves by less than 1 mm (the chord between nodes moved
    it by ~8 mm, a tenth of the focus's move), and on each mesh its z is
    the independent elastica's (:func:`elastica_touchdown`, from z = 80 m,
    past the hump) to 1 mm (0.2 mm on the solve's own mesh)."""
    case, res = on_profile
    pb0 = res.state
    s_t = touchdown_position(pb0)
    z_ref = elastica_touchdown(case, res, 80.0)
    assert res.summary["tdp_z"] == pytest.approx(z_ref, abs=1e-3)
    for d in (-0.1, 0.1):
        pb = remesh(case, copy.deepcopy(pb0), s_t + d, stinger_foci(case, pb0), grading=True,
                    total=pb0.stats.get("cold_total"))
        pb.settings.tolerance = None
        pb.settings.in_balance = True
        pb, _react, _stats = _solve_gravity(case, pb, IterationBudget(100))
        assert abs(touchdown_position(pb) - s_t) < 1e-3
        z = CubicHermiteSpline(pb.s, pb.u[pb.nd - 1::pb.ndn], pb.u[2 * pb.nd - 1::pb.ndn])
        assert float(z(touchdown_position(pb))) == pytest.approx(z_ref, abs=1e-3)

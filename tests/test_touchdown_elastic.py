"""Touchdown on an elastic seabed is where the pipe's cubic Hermite
clearance crosses the seabed (against scipy's CubicHermiteSpline and PCHIP
with brentq), which moves with the mesh's grading only by the
discretisation's error."""

import copy

import numpy as np
import pytest
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
    case = _j125(**{"seabed.profile": PROFILE})
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


def test_touchdown_moves_with_the_grading_only_by_the_discretisation(on_profile):
    """The mesh graded 0.1 m either side of the touchdown found and solved
    again: touchdown moves by less than 1 mm (the chord between nodes moved
    it by ~8 mm, a tenth of the focus's move)."""
    case, res = on_profile
    pb0 = res.state
    s_t = touchdown_position(pb0)
    for d in (-0.1, 0.1):
        pb = remesh(case, copy.deepcopy(pb0), s_t + d, stinger_foci(case, pb0), grading=True,
                    total=pb0.stats.get("cold_total"))
        pb.settings.tolerance = None
        pb.settings.in_balance = True
        pb, _react, _stats = _solve_gravity(case, pb, IterationBudget(100))
        assert abs(touchdown_position(pb) - s_t) < 1e-3

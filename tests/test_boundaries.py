"""Touchdown as an unknown of Newton (``solver.contact = "boundaries"``, J-lay).

The mesh follows touchdown: its arc length s_T is a bordered unknown, closed
by the continuum's condition there (the pipe on the seabed, tangent to it,
with no moment on the free side). Checked against the independent planar
elastica (``tests/reference/elastica.py``, scipy's BVP solver) for the same
four J125 lays as ``test_jlay`` (one bending dominated, one with a clamped
90 deg top), and against the 2D answer in 3D.
"""

from __future__ import annotations

import pytest

import pipelay_fast as pf
from tests.helpers import elastica_for
from tests.test_jlay import TENSIONS


@pytest.mark.parametrize("name", list(TENSIONS))
def test_touchdown_unknown_matches_elastica(j125, name):
    case = j125.with_changes({**TENSIONS[name], "pipe.extensible": False,
                              "solver.contact": "boundaries"})
    kw = ({"T_top": case.lay.top_tension} if case.lay.top_tension
          else {"T_bottom": case.lay.bottom_tension})
    ref = elastica_for(case, **kw)
    sm = pf.solve(case).summary
    # the active set, at the same 4 m mesh, misses touchdown by 2 to 7 mm
    assert abs(sm["tdp_z"] - ref["tdp_z"]) < 1e-3
    assert sm["sagbend_max_moment"] == pytest.approx(ref["sagbend_moment"], rel=1e-3)
    assert sm["top_tension"] == pytest.approx(ref["top_tension"], rel=1e-6)
    assert sm["bottom_tension"] == pytest.approx(ref["bottom_tension"], rel=1e-6)
    assert sm["n_iterations"] <= 12  # cold, from the catenary guess


@pytest.mark.parametrize("h", [8.0, 2.0])
def test_touchdown_unknown_3d_equals_2d(j125, h):
    case = j125.with_changes({"solver.contact": "boundaries", "solver.element_length": h})
    a = pf.solve(case).summary
    b = pf.solve(case.with_changes({"solver.dimension": "3d"})).summary
    for key in ("max_von_mises", "sagbend_max_moment", "tdp_z", "top_angle_deg",
                "bottom_tension"):
        assert b[key] == pytest.approx(a[key], rel=1e-9, abs=1e-9), key


def test_touchdown_unknown_refuses_slay(j125):
    s67 = pf.load_case(pf.__path__[0] + "/examples/s67.toml")
    with pytest.raises(ValueError, match="solver.contact"):
        s67.with_changes({"solver.contact": "boundaries"})

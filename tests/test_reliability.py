"""Classes of refusal of issue 42, each a case of its class solved and checked
against the planar elastica of ``tests/reference`` (2D). The straight stinger
(class 4, a = 0) is a case of tests/test_boundaries.py's tip regime test."""

from __future__ import annotations

import pytest

import pipelay_fast as pf
from tests.helpers import EXAMPLES, weights
from tests.reference.slay import slay_elastica

# Class 1, S-lay that failed at the homotopy's first load step: a switch to
# bearing on the tip from a state lifting off that passes below the tip (the
# cases 1:2d-85 and 1:2d-395 of benchmarks/bench_random.py --seed 1, rounded).
SLAY_FIRST_STEP = {
    "shallow, steep stinger": {
        "pipe.outer_diameter": 0.5867, "pipe.inner_diameter": 0.5386,
        "pipe.coating_outer_diameter": 0.6228, "pipe.hydrodynamic_diameter": 0.6228,
        "pipe.coating_density": 2553.4, "environment.water_depth": 44.61,
        "lay.stinger.a": -0.0051048, "lay.stinger.lower": [40.155, 343.973],
        "lay.stinger.upper": [56.794, 400.0], "lay.bottom_tension": 111556.0},
    "heavy pipe, 49 deg tip": {
        "pipe.outer_diameter": 1.1674, "pipe.inner_diameter": 1.0791,
        "pipe.coating_outer_diameter": 1.1674, "pipe.hydrodynamic_diameter": 1.1674,
        "pipe.coating_density": 0.0, "environment.water_depth": 183.41,
        "lay.stinger.a": -0.0034820, "lay.stinger.lower": [97.949, 242.142],
        "lay.stinger.upper": [189.947, 400.0], "lay.bottom_tension": 210336.0},
}
AGREE = 5e-3  # issue 42's target: tensions and peak moments against the reference


@pytest.mark.parametrize("name", SLAY_FIRST_STEP)
def test_slay_first_load_step_matches_elastica(name):
    """S-lay (class 1) with its bottom tension given and the top pinned: the
    engine solves it, and its top tension and peak moments agree with the
    independent planar elastica within 0.5 %, the regime (lifting off, no
    reaction at the tip) the same. The engine's pin (a hinge at the top, the
    stinger's curvature k_U released there) raises the top's effective
    tension by EI k_U^2 / 2 over the elastica's, clamped along the stinger."""
    changes = {**SLAY_FIRST_STEP[name], "lay.top_tension": None, "lay.top_angle": "pinned",
               "environment.current.speed": 0.0, "solver.dimension": "2d"}
    case = pf.load_case(EXAMPLES / "s67.toml").with_changes(changes)
    st = case.lay.stinger
    d = case.environment.water_depth
    w_sub, w_dry = weights(case)
    ref = slay_elastica(case.pipe.bending_stiffness, w_sub, w_dry, d, st.a, st.lower, st.upper,
                        T_bottom=case.lay.bottom_tension)
    assert ref["regime"] == "liftoff"
    (x_l, z_l), (x_u, z_u) = st.lower, st.upper
    slope = 2.0 * st.a * z_u + (x_u - x_l) / (z_u - z_l) - st.a * (z_u + z_l)
    k_u = 2.0 * st.a / (1.0 + slope * slope) ** 1.5
    top = ref["top_tension"] + 0.5 * case.pipe.bending_stiffness * k_u * k_u
    sm = pf.solve(case).summary
    assert sm["tip_reaction"] == 0.0
    assert sm["top_tension"] == pytest.approx(top, rel=AGREE)
    for key in ("sagbend_max_moment", "overbend_max_moment"):
        assert sm[key] == pytest.approx(ref[key], rel=AGREE)


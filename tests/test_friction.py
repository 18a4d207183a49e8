"""Seabed friction on the current's load path: J125 in 3D under a lateral current.

Friction is mobilised by the current from the pipe as laid under gravity; each
seabed contact carries an elastic-perfectly-plastic spring (full friction mu W
after ``seabed.friction_slip`` of motion). Checked here: the friction cone at
every contact, one friction direction (against the drag), lateral balance of
drag and reactions, and a slipping length that grows with the current.
"""

from __future__ import annotations

import numpy as np
import pytest

import pipelay_fast as pf
from pipelay_fast.engine.friction import slipping_length_bound
from pipelay_fast.engine.guess import free_span
from tests.helpers import EXAMPLES
from tests.reference.drag import drag_vector


def lateral_drag(case, prof):
    """Lateral drag [N] on the deformed pipe under the power-law current along
    +y (:func:`tests.reference.drag.drag_vector`'s y part)."""
    return float(drag_vector(case, prof)[1])


@pytest.fixture(scope="module")
def lateral():
    """The paper's 1/7 power-law current (zero at the seabed) along +y."""
    # 1 m elements: the drag is integrated independently at the nodes below
    base = pf.load_case(EXAMPLES / "j125_3d.toml").with_changes({"solver.element_length": 1.0})
    assert base.environment.current.profile == "power"
    assert base.environment.current.heading == 90.0
    return {v: (base.with_changes({"environment.current.speed": v}),
                pf.solve(base.with_changes({"environment.current.speed": v})))
            for v in (1.0, 2.0)}


@pytest.mark.parametrize("speed", [1.0, 2.0])
def test_friction_cone_direction_and_lateral_balance(lateral, speed):
    case, res = lateral[speed]
    prof = res.profile
    mu = case.seabed.lateral_friction
    # seabed contacts but the lower end, which is held laterally
    bed = (prof["contact"] == "seabed").to_numpy() & (prof["s"] > 0.0).to_numpy()
    w = prof["seabed_reaction"].to_numpy()[bed]
    fy = prof["reaction_y"].to_numpy()[bed]
    # inside the cone everywhere, on it and against the drag (+y) where slipping;
    # friction uses W of the last-but-one iteration: a 1e-6 tolerance
    assert np.all(np.abs(fy) <= mu * w * (1 + 1e-6))
    slip = prof["slipping"].to_numpy()[bed]
    assert slip.sum() > 10
    np.testing.assert_allclose(np.abs(fy[slip]), mu * w[slip], rtol=1e-6)
    assert np.all(fy[slip] < 0.0)
    # (beyond the slipping zone the springs hold the laid pipe as an elastic
    # bed holds a beam loaded at its end: part of it pushes back, along +y)
    # drag, friction, the held lower end and the vessel balance laterally; the
    # drag is integrated here independently, at the nodes (a 1e-3 quadrature)
    held = prof["reaction_y"].sum()
    drag = lateral_drag(case, prof)
    assert held + drag == pytest.approx(0.0, abs=2e-3 * drag)


def test_slipping_length_grows_with_the_current(lateral, j125):
    mu, w = 0.5, float(j125.effective_weight(0.0))
    lengths, bounds = [], []
    for speed in (1.0, 2.0):
        prof = lateral[speed][1].profile
        slip = prof[prof["slipping"]]
        bed = prof[prof["contact"] == "seabed"]
        lengths.append(slip["s"].max() - slip["s"].min())
        # slipping nodes carry mu W, the others less: the slipping length is at
        # most the seabed's lateral force over mu w
        bounds.append(-bed["reaction_y"].sum() / (mu * w))
    assert lengths[1] > 2.0 * lengths[0]
    for length, bound in zip(lengths, bounds, strict=True):
        assert 0.5 * bound < length <= bound * (1 + 1e-6)


def test_laid_length_bound_holds_the_slipping_zone(lateral):
    """The laid length is sized before the solve by a taut-string bound on the
    slipping length: it bounds the length found, without overshooting it by
    more than 3 times, so the held lower end carries under 1 % of the laid
    pipe's lateral force and no second, longer mesh is needed."""
    for case, res in lateral.values():
        prof = res.profile
        slip = prof[prof["slipping"]]
        found = slip["s"].max() - slip["s"].min()
        # the slipping part of the laid length the solver sizes (friction_laid_length)
        bound = slipping_length_bound(case, free_span(case))
        assert found < bound < 3.0 * found
        bed = (prof["contact"] == "seabed").to_numpy()
        lower = abs(prof["reaction_y"].iloc[0])
        assert lower < 0.01 * np.abs(prof["reaction_y"].to_numpy()[bed]).sum()


def test_stiffer_friction_spring_approaches_rigid_coulomb(lateral):
    """The slip displacement is a regularisation: dividing it by 10 changes the
    span's peak stress and deflection by well under 1 %."""
    case, res = lateral[1.0]
    stiff = pf.solve(case.with_changes({"seabed.friction_slip": 1e-3}))
    for key in ("max_von_mises", "max_lateral_deflection", "tdp_z"):
        assert stiff.summary[key] == pytest.approx(res.summary[key], rel=1e-2)


def test_current_steps_are_counted_as_newton_ran_them(monkeypatch):
    """``n_current_steps`` and ``max_current_step_iterations`` are the
    current's load steps and the most Newton iterations one took: here
    counted independently, call by call of the Newton kernel while the
    current's factor rises (a step is one call, or several when the regime
    at the stinger's tip switches or a predicted start is dropped for the
    last converged state: neither happens in this J-lay)."""
    from pipelay_fast.engine import continuation
    from pipelay_fast.kernels import layout as L
    from pipelay_fast.kernels.layout import I_ITER

    calls = []
    run = continuation.run_newton

    def counted(pb, *args):
        status, react, info = run(pb, *args)
        if pb.settings.factors[L.F_CURRENT] > 0.0:
            calls.append(int(info[I_ITER]))
        return status, react, info

    monkeypatch.setattr(continuation, "run_newton", counted)
    case = pf.load_case(EXAMPLES / "j125_3d.toml")
    sm = pf.solve(case).summary
    # the current rises in steps of at most a quarter (apply_current)
    assert len(calls) >= 4
    assert sm["n_current_steps"] == len(calls)
    assert sm["max_current_step_iterations"] == max(calls)
    assert sm["n_iterations"] >= sum(calls)
    # without a lateral current there is no friction path, and no steps
    planar = pf.solve(pf.load_case(EXAMPLES / "j125_2d.toml")).summary
    assert planar["n_current_steps"] == 0 and planar["max_current_step_iterations"] == 0


@pytest.mark.parametrize("profile", ["uniform", "linear", "power", "table"])
@pytest.mark.parametrize("x_top", [80.0, 125.0, 160.0])
def test_drag_share_is_the_integral_of_the_squared_speed(profile, x_top):
    """drag_share (closed forms; Simpson on a table's pieces) against scipy's
    adaptive quadrature of V(t x_top)^2 (1 - t), told the kinks (the surface,
    the table's heights), for a string below, at and above the surface."""
    from scipy.integrate import quad

    from pipelay_fast.engine.friction import drag_share

    changes = {"environment.current.profile": profile}
    if profile == "table":
        changes.update({"environment.current.speed": 1.3, "environment.current.table":
                        [[0.0, 0.2], [30.0, 0.8], [90.0, 1.1], [125.0, 1.3]]})
    case = pf.load_case(EXAMPLES / "j125_3d.toml").with_changes(changes)
    depth = case.environment.water_depth
    kinks = [h / x_top for h in (30.0, 90.0, depth) if h < x_top]
    exact = quad(lambda t: float(case.current_speed_at(t * x_top)) ** 2 * (1.0 - t), 0.0, 1.0,
                 points=kinks or None, limit=500, epsabs=1e-13, epsrel=1e-11)[0]
    assert drag_share(case, x_top) == pytest.approx(exact, rel=1e-9)

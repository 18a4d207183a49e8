"""S-lay over a stinger: frictionless contact, conforming curvature, 2D vs 3D."""

from __future__ import annotations

import numpy as np
import pytest

import pipelay_fast as pf
from tests.helpers import EXAMPLES, slay_elastica_for, weights


@pytest.fixture(scope="module")
def s67():
    return pf.load_case(EXAMPLES / "s67.toml")


def solve(case):
    return pf.solve(case)


@pytest.fixture(scope="module")
def still(s67):
    """S67 without current, the paper's a = -0.0012."""
    return solve(s67.with_changes({"environment.current.speed": 0.0}))


def test_stinger_reactions_are_frictionless_and_push(s67, still):
    prof = still.profile
    st = s67.lay.stinger
    on = (prof["contact"] == "stinger").to_numpy()
    assert on.sum() > 20  # the stinger arc of about 135 m, in 4 m elements or finer
    slope = np.asarray(st.slope(prof["z"].to_numpy()[on]))
    tangent = np.stack([slope, np.ones_like(slope)], axis=1) / np.hypot(slope, 1.0)[:, None]
    force = prof[["reaction_x", "reaction_z"]].to_numpy()[on]
    along = np.abs((force * tangent).sum(axis=1))
    assert (along <= 1e-8 * np.linalg.norm(force, axis=1) + 1e-6).all()
    assert (prof["stinger_reaction"].to_numpy()[on] >= 0.0).all()


def test_weight_is_carried_by_seabed_stinger_and_top(s67, still):
    """Vertical balance to 1e-8: reactions (seabed, stinger, tip, top) = weight."""
    prof = still.profile
    d = s67.environment.water_depth
    s, x = prof["s"].to_numpy(), prof["x"].to_numpy()
    w_sub, w_dry = (float(s67.effective_weight(0.0)), float(s67.effective_weight(d + 1)))
    # weight of the modelled pipe, with the water-surface crossing located on the
    # element's Hermite shape by bisection
    k = np.flatnonzero((x[:-1] < d) & (x[1:] >= d))[0]
    lo, hi = s[k], s[k + 1]
    pb = still.state
    ndn = pb.ndn
    le = hi - lo
    xa, pa = pb.u[k * ndn], pb.u[k * ndn + 2]
    xb, pbb = pb.u[(k + 1) * ndn], pb.u[(k + 1) * ndn + 2]

    def height(t):
        return ((1 - 3 * t**2 + 2 * t**3) * xa + le * (t - 2 * t**2 + t**3) * pa
                + (3 * t**2 - 2 * t**3) * xb + le * (-t**2 + t**3) * pbb)

    a, b = 0.0, 1.0
    for _ in range(60):
        m = 0.5 * (a + b)
        a, b = (m, b) if height(m) < d else (a, m)
    s_surface = lo + a * le
    weight = w_sub * s_surface + w_dry * (s[-1] - s_surface)
    assert prof["reaction_x"].sum() == pytest.approx(weight, rel=1e-8)


def test_conforming_pipe_follows_stinger_curvature(s67, still):
    prof = still.profile
    st = s67.lay.stinger
    on = np.flatnonzero((prof["contact"] == "stinger").to_numpy())
    inner = on[3:-3]  # away from lift-off and the held top
    slope = np.asarray(st.slope(prof["z"].to_numpy()[inner]))
    kappa = 2.0 * abs(st.a) / (1.0 + slope**2) ** 1.5
    np.testing.assert_allclose(prof["curvature"].to_numpy()[inner], kappa, rtol=1e-2)


def test_2d_and_3d_agree_on_the_stinger(s67):
    """The paper's first conclusion: current along z (2D) or along y (3D) gives
    the same stresses on the stinger, within 2 %."""
    r2 = solve(s67.with_changes({"environment.current.heading": 0.0}))
    r3 = solve(s67.with_changes({"environment.current.heading": 90.0}))
    assert (r2.summary["dimension"], r3.summary["dimension"]) == ("2d", "3d")
    assert r3.summary["max_lateral_deflection"] > 0.5
    assert r3.summary["overbend_max_von_mises"] == pytest.approx(
        r2.summary["overbend_max_von_mises"], rel=2e-2)
    p2, p3 = r2.profile, r3.profile
    z = np.linspace(300.0, 395.0, 40)
    vm2 = np.interp(z, p2["z"], p2["von_mises"])
    vm3 = np.interp(z, p3["z"], p3["von_mises"])
    np.testing.assert_allclose(vm3, vm2, rtol=2e-2)
    assert np.abs(p3.loc[p3["contact"] == "stinger", "y"]).max() < 1e-9


S67_A = {
    "lift-off on the stinger (a = -0.0012)": -0.0012,
    "lift-off on the stinger (a = -0.0019)": -0.0019,
    "bearing on the tip (a = -0.0009)": -0.0009,
}


@pytest.mark.parametrize("name", list(S67_A))
def test_s67_matches_planar_elastica(s67, name):
    """FE against the independent elastica of tests/reference/slay.py (S67 2D,
    no current): peaks within 1 %, touchdown and lift-off within 0.5 m."""
    from tests.reference.slay import slay_elastica

    a = S67_A[name]
    case = s67.with_changes({"environment.current.speed": 0.0, "lay.stinger.a": a,
                             "pipe.extensible": False})
    d = case.environment.water_depth
    ref = slay_elastica(case.pipe.bending_stiffness, float(case.effective_weight(0.0)),
                        float(case.effective_weight(d + 1.0)), d, a, case.lay.stinger.lower,
                        case.lay.stinger.upper, T_top=case.lay.top_tension)
    sm = solve(case).summary
    assert sm["overbend_max_moment"] == pytest.approx(ref["overbend_max_moment"], rel=1e-2)
    assert sm["sagbend_max_moment"] == pytest.approx(ref["sagbend_max_moment"], rel=1e-2)
    assert abs(sm["tdp_z"] - ref["tdp_z"]) < 0.5
    assert abs(sm["liftoff_z"] - ref["liftoff_z"]) < 0.5
    assert sm["bottom_tension"] == pytest.approx(ref["bottom_tension"], rel=1e-3)
    if ref["regime"] == "tip":
        assert sm["tip_reaction"] == pytest.approx(ref["tip_reaction"], rel=2e-2)
    else:
        assert sm["tip_reaction"] == 0.0


def test_a_warm_start_out_of_the_tip_regime_gives_the_cold_answer(s67):
    """From a solution bearing on the tip (a = -0.00105) to one lifting off
    above it (-0.0012, 2 m elements): the warm solve's tip contact lets go on
    the way, so it must end lifting off with no node over the tip and the
    mesh graded only at the boundaries found, as the cold solve does (ending
    with an unloaded node over the tip, lift-off came out 0.28 m up the
    stinger and the peak stress 4.6e-6 off the cold one's)."""
    case = s67.with_changes({"solver.element_length": 2.0})
    bearing = pf.solve(case.with_changes({"lay.stinger.a": -0.00105}))
    assert bearing.summary["tip_reaction"] > 0.0
    cold = pf.solve(case).summary
    warm = pf.solve(case, warm=bearing)
    assert warm.state.tip_node < 0 and warm.summary["tip_reaction"] == 0.0
    for key in ("max_von_mises", "overbend_max_moment", "sagbend_max_moment", "tdp_z",
                "bottom_tension"):
        assert warm.summary[key] == pytest.approx(cold[key], rel=1e-7), key
    assert warm.summary["liftoff_z"] == pytest.approx(cold["liftoff_z"], abs=1e-3)


@pytest.mark.parametrize("a", [-0.00125, -0.0015, -0.0009])
def test_warm_start_gives_the_cold_answer(s67, still, a):
    """Started from the solution at a = -0.0012 (lift-off regime), including a
    jump into the tip regime (-0.0009): the answer of a solve from the catenary
    (measured: 5.5e-11 in peak stress, 1.5e-11 in touchdown, 1.7e-11 in lift-off)."""
    case = s67.with_changes({"environment.current.speed": 0.0, "lay.stinger.a": a})
    cold = solve(case).summary
    warm = pf.solve(case, warm=still).summary
    for key in ("max_von_mises", "overbend_max_moment", "tdp_z", "liftoff_z", "tip_reaction",
                "bottom_tension"):
        assert warm[key] == pytest.approx(cold[key], rel=1e-7, abs=1e-6), key


def test_a_warm_start_with_friction_follows_the_cold_slip_path():
    """S67 3D (1 m/s lateral current, friction 0.5) at a = -0.0015 from its
    neighbour at -0.00152: each step of the current starts from the
    neighbour's increment over it, but the friction springs' anchors are
    the warm solve's own path, so its answer is the cold solve's: the same
    nodes slipping, the peak stress to 1e-6 and the lateral deflection to
    1e-4 (measured 4.7e-8 and 3.3e-6; the tolerance 1e-8 on each step's
    residual leaves the springs' anchors a little apart)."""
    base = pf.load_case(EXAMPLES / "s67_3d.toml").with_changes({"solver.element_length": 4.0})
    case = base.with_changes({"lay.stinger.a": -0.0015})
    neighbour = pf.solve(base.with_changes({"lay.stinger.a": -0.00152}))
    cold = pf.solve(case)
    warm = pf.solve(case, warm=neighbour)
    assert warm.state.path.warm_path is neighbour.state.path.current_path
    assert cold.profile["slipping"].sum() > 5
    np.testing.assert_array_equal(warm.profile["slipping"], cold.profile["slipping"])
    assert warm.summary["max_von_mises"] == pytest.approx(cold.summary["max_von_mises"],
                                                          rel=1e-6)
    assert warm.summary["max_lateral_deflection"] == pytest.approx(
        cold.summary["max_lateral_deflection"], rel=1e-4)


def test_a_warm_start_from_a_sweep_step_away_follows_the_cold_slip_path():
    """S125 3D at 4 m, a = -0.0015 from -0.00135 (a step of a nine-value
    sweep): the neighbour models another length of laid pipe (its own cold
    start's), so the warm solve is graded anew to this case's, and each
    step of the current starts from the neighbour's increment matched from
    the top: the same nodes slip, and the peak stress is the cold one to
    1e-8 (measured 1.5e-9; 2.0e-6, one node of the slip set apart, while the
    warm solve kept the neighbour's laid length)."""
    base = pf.load_case(EXAMPLES / "s125_3d.toml").with_changes({"solver.element_length": 4.0})
    case = base.with_changes({"lay.stinger.a": -0.0015})
    neighbour = pf.solve(base.with_changes({"lay.stinger.a": -0.00135}))
    cold = pf.solve(case)
    warm = pf.solve(case, warm=neighbour)
    assert neighbour.state.s[-1] != pytest.approx(cold.state.s[-1], abs=1e-3)
    assert warm.state.s[-1] == pytest.approx(cold.state.s[-1], rel=1e-12)
    assert warm.summary["n_current_steps"] == cold.summary["n_current_steps"]
    assert warm.summary["n_iterations"] < cold.summary["n_iterations"]  # the increments served
    np.testing.assert_array_equal(warm.profile["slipping"], cold.profile["slipping"])
    assert warm.summary["max_von_mises"] == pytest.approx(cold.summary["max_von_mises"],
                                                          rel=1e-8)


def test_a_warm_start_solves_the_laid_length_the_cold_solve_does():
    """S67 3D at 2 m, a = -0.0009 from its neighbour at -0.00088: the laid
    pipe modelled holds the slipping zone and the sticking zone's decay
    behind it, so neither solve doubles it and both solve the same domain:
    the warm peak stress is the cold one to 1e-6 (measured 8.6e-8; 4.7e-6
    when the neighbour's laid pipe had been doubled and the cold one's not),
    and the held lower end carries under 0.1 % of the laid pipe's lateral
    force (the reactions on the seabed and the lower end, friction included)."""
    base = pf.load_case(EXAMPLES / "s67_3d.toml").with_changes({"solver.element_length": 2.0})
    case = base.with_changes({"lay.stinger.a": -0.0009})
    neighbour = pf.solve(base.with_changes({"lay.stinger.a": -0.00088}))
    cold = pf.solve(case)
    warm = pf.solve(case, warm=neighbour)
    assert warm.summary["n_elements"] == cold.summary["n_elements"]
    assert warm.summary["max_von_mises"] == pytest.approx(cold.summary["max_von_mises"],
                                                          rel=1e-6)
    prof = cold.profile
    ry = prof["reaction_y"].to_numpy()
    on_bed = (prof["contact"] == "seabed").to_numpy()
    assert abs(ry[0]) < 1e-3 * (np.abs(ry[on_bed]).sum() + abs(ry[0]))


def test_a_warm_step_starts_from_the_neighbours_increment():
    """Problem.start_step: the neighbour's answers at both ends of the step,
    on a mesh of its own, are interpolated at this mesh's material points
    and their difference added (with the bottom tension's). With the
    neighbour's shapes cubic in arc length and its tension linear (which
    the cubic Hermite and linear interpolations reproduce), the increment is
    the closed-form difference; a step the neighbour did not take, or one
    with other boundaries, starts from the state as it is."""
    from pipelay_fast.engine.problem import build_problem

    pb = build_problem(pf.load_case(EXAMPLES / "s67_3d.toml"))
    nd, ndn = pb.nd, pb.ndn
    s_nb = np.linspace(0.0, pb.s[-1], 37)  # the neighbour's mesh

    def state(s, c):
        u = np.zeros(s.size * ndn)
        for i in range(nd):
            u[i::ndn] = c * (1.0 + i) * (0.2 * s - 3e-4 * s**2 + 4e-7 * s**3)
            u[nd + i::ndn] = c * (1.0 + i) * (0.2 - 6e-4 * s + 1.2e-6 * s**2)
        u[2 * nd::ndn] = c * (3e5 + 40.0 * s)
        return u

    on = pb.bnodes >= 0
    pb.path.warm_path = [{"level": lev, "s": s_nb, "u": state(s_nb, c), "on": on,
                     "tb": np.array([1e5 * c]), "s_bd": pb.mesh.s_bd.copy()}
                    for lev, c in ((0.0, 1.0), (0.25, 1.5))]
    pb.path.current_path = [pb.path_state(0.0)]
    u0, tb0, s0, bd0 = pb.u.copy(), pb.tb.copy(), pb.s.copy(), pb.mesh.s_bd.copy()
    assert not pb.start_step(0.5)  # the neighbour has no step ending there
    np.testing.assert_array_equal(pb.u, u0)
    assert pb.start_step(0.25)
    np.testing.assert_allclose(pb.u - u0, state(pb.s, 0.5), rtol=1e-9, atol=1e-9)
    assert pb.tb[0] - tb0[0] == pytest.approx(0.5e5)
    # the neighbour's touchdown moved 0.3 m over the step: this one's moves
    # as much, and the state is carried to the nodes it moves (a cubic
    # state: its interpolation is exact), the increment added there
    pb.u[:], pb.tb[:] = state(s0, 1.0), tb0
    pb.path.warm_path[1]["s_bd"] = bd0 + np.where(np.arange(bd0.size) == 0, 0.3, 0.0)
    assert on[0] and pb.start_step(0.25)
    assert pb.mesh.s_bd[0] == pytest.approx(bd0[0] + 0.3)
    assert np.abs(pb.s - s0).max() == pytest.approx(0.3)
    np.testing.assert_allclose(pb.u, state(pb.s, 1.5), rtol=1e-9, atol=1e-9)
    pb.mesh.s_bd[:] = bd0
    pb.mesh.update_nodes()
    pb.u[:] = u0
    pb.path.warm_path[1]["on"] = ~on
    assert not pb.start_step(0.25)
    np.testing.assert_array_equal(pb.u, u0)


def test_warm_start_refuses_another_dimension(s67, still):
    with pytest.raises(ValueError, match="warm"):
        pf.solve(s67.with_changes({"solver.dimension": "3d"}), warm=still)


@pytest.mark.parametrize("name,h", [("s67.toml", 2.0), ("s67_3d.toml", 4.0), ("s67.toml", 4.0)])
def test_a_sweep_across_the_tip_regime_has_no_jumps(name, h):
    """From bearing on the tip (a = -0.0009) to lifting off the stinger
    (-0.0015): every solve converges, the tip reaction falls to zero once and
    stays there, and the overbend peak has a single minimum (no chattering).
    With the boundaries unknowns the tip regime is a complementarity; 8 to 150
    iterations (the most at -0.00115, next to the change of regime)."""
    base = pf.load_case(EXAMPLES / name).with_changes({"solver.element_length": h})
    grid = np.linspace(-0.0009, -0.0015, 13)
    rows = [pf.solve(base.with_changes({"lay.stinger.a": float(a)})).summary for a in grid]
    tip = np.array([r["tip_reaction"] for r in rows])
    over = np.array([r["overbend_max_von_mises"] for r in rows])
    bearing = tip > 0.0
    assert bearing[0] and not bearing[-1]
    assert np.all(np.diff(bearing.astype(int)) <= 0)  # switches once
    assert np.all(np.diff(tip[bearing]) < 0.0)
    steps = np.sign(np.diff(over))
    assert np.count_nonzero(np.diff(steps) != 0) == 1  # down, then up


def _stinger_top_moment(case):
    """EI kappa_U [N m], the stinger's curvature at its upper end from its two
    points and a (x = a z^2 + b z + c), and the jump M_U^2 / (2 EI) [N]."""
    st = case.lay.stinger
    (x_l, z_l), (x_u, z_u) = st.lower, st.upper
    slope = 2.0 * st.a * z_u + (x_u - x_l) / (z_u - z_l) - st.a * (z_u + z_l)
    ei = case.pipe.bending_stiffness
    moment = ei * 2.0 * abs(st.a) / (1.0 + slope**2) ** 1.5
    return moment, moment**2 / (2.0 * ei)


def _rise(case, x):
    """W(x) = int_0^x w dx [N], from the weights recomputed from the pipe data."""
    w_sub, w_dry = weights(case)
    d = case.environment.water_depth
    return w_sub * min(x, d) + w_dry * max(x - d, 0.0)


def test_pinned_top_conforms_up_to_the_pin(s67, still):
    """A pinned top on the curved stinger: the pipe conforms up to the pin (a
    moment-free end cannot lift off a convex support), so the moment is the
    stinger's EI kappa_U next to the top and zero at the pin, with no spike
    beside it (a clamp one element below the pin put 1.5 EI kappa_U there),
    and the top angle is the stinger's. The overbend is the firing line's."""
    pinned = pf.solve(s67.with_changes({"environment.current.speed": 0.0,
                                        "lay.top_angle": "pinned"}))
    prof = pinned.profile
    moment_u, _ = _stinger_top_moment(s67)
    assert prof["moment"].iloc[-1] == 0.0  # the pin's own value
    assert prof["moment"].iloc[-2] == pytest.approx(moment_u, rel=1e-3)
    assert pinned.summary["top_angle_deg"] == pytest.approx(
        float(s67.lay.stinger.angle(s67.lay.stinger.upper[1])), abs=1e-9)
    assert pinned.summary["top_tension"] == pytest.approx(s67.lay.top_tension, rel=1e-12)
    # the firing line's peak is at its top node, the pinned one's a node below
    # (kappa_s grows towards the top; 2.7e-4 of it over the last element here)
    assert pinned.summary["overbend_max_moment"] == pytest.approx(
        still.summary["overbend_max_moment"], rel=1e-3)


# A steep stinger: tip 40.2 deg, upper end 11.6 deg, kappa_U = -7.5e-3 1/m, so
# M_U^2/(2 EI) = 7.27 kN against a bottom tension of 191 kN (sqrt(EI/T) = 29 m).
STEEP_PINNED = {"lay.top_angle": "pinned", "environment.current.speed": 0.0,
                "pipe.extensible": False, "lay.top_tension": 300e3,
                "lay.stinger.a": -0.004, "lay.stinger.lower": [30.0, 320.0]}


def _pin_jump_measured(case, res):
    """Te(top) less the conforming pipe's Te carried up to the top along the first
    integral Te + M^2/(2 EI) - W(x) = const, from the node below the top [N]."""
    prof = res.profile
    te, m, x = (prof[k].to_numpy() for k in ("effective_tension", "moment", "x"))
    moment_u, _ = _stinger_top_moment(case)
    ei = case.pipe.bending_stiffness
    below = (te[-2] + (m[-2] ** 2 - moment_u**2) / (2.0 * ei)
             + _rise(case, x[-1]) - _rise(case, x[-2]))
    return te[-1] - below


def test_pinned_top_on_a_steep_stinger(s67):
    """Across a moment-free pin on a curved stinger the effective tension jumps
    by M_U^2/(2 EI) (the rod's first integral), so the bottom tension is
    T_top - W(x_U) exactly and the span is the clamped-top elastica's with
    T_top - M_U^2/(2 EI) (tests/reference/slay.py, independent).

    Tolerances from the convergence study below: at the default mesh (4 m,
    graded) the bottom tension is within 3e-5 of T_top - W(x_U) for element
    lengths of 8 to 0.5 m (the graded elements at lift-off and touchdown set
    it), touchdown and lift-off within 4 mm of the elastica, the jump within
    0.4 %. The discrete pin that freed the top's slope one element above a
    clamp to the curve gave 1.25 times the jump whatever the mesh: the bottom
    tension 0.95 % low and touchdown 0.36 m off here (2.8 % and 1.3 m with a
    tip at 53 deg)."""
    case = s67.with_changes(STEEP_PINNED)
    res = pf.solve(case)
    sm = res.summary
    _, jump = _stinger_top_moment(case)
    t_top = case.lay.top_tension
    assert sm["top_tension"] == pytest.approx(t_top, rel=1e-12)
    assert sm["bottom_tension"] == pytest.approx(t_top - _rise(case, case.lay.top[0]), rel=1e-4)
    assert _pin_jump_measured(case, res) == pytest.approx(jump, rel=1e-2)
    ref = slay_elastica_for(case.with_changes({"lay.top_tension": t_top - jump}))
    assert ref["regime"] == "liftoff"
    for key in ("tdp_z", "liftoff_z"):
        assert sm[key] == pytest.approx(ref[key], abs=1e-2), key


def test_pinned_top_converges_with_the_mesh(s67):
    """The bottom tension's error against T_top - W(x_U) falls as h_min^2 with
    the finest graded element (2.7e-5, 7.6e-6, 1.9e-6, 5.8e-7 at 1, 0.5, 0.25,
    0.125 m) and the jump at the pin tends to M_U^2/(2 EI) (0.9966 to 0.9999
    of it); before, both stayed put (0.25 M_U^2/(2 EI) too low, 1.25 times)."""
    h_min = np.array([1.0, 0.5, 0.25, 0.125])
    base = s67.with_changes(STEEP_PINNED)
    _, jump = _stinger_top_moment(base)
    target = base.lay.top_tension - _rise(base, base.lay.top[0])
    errors, jumps = [], []
    for h in h_min:
        case = base.with_changes({"solver.min_element_length": float(h)})
        res = pf.solve(case)
        errors.append(abs(res.summary["bottom_tension"] / target - 1.0))
        jumps.append(abs(_pin_jump_measured(case, res) / jump - 1.0))
    slope = np.polyfit(np.log(h_min), np.log(errors), 1)[0]
    assert slope > 1.5
    assert errors[-1] < 2e-6
    assert jumps[-1] < 1e-3 and jumps[-1] < jumps[0]


def test_top_angle_rejects_other_words(s67):
    with pytest.raises(ValueError, match="lay.top_angle"):
        s67.with_changes({"lay.top_angle": "free"})


@pytest.fixture(scope="module")
def fixed_length(s67):
    """S67 inextensible, no current, at the paper's a, and the same pipe given
    by its length with the lower end held at z = 0 (the paper's assumption v)."""
    base = s67.with_changes({"environment.current.speed": 0.0, "pipe.extensible": False})
    top = pf.solve(base)
    z_lower = top.state.u[top.state.nd - 1]  # the laid pipe extends straight back to z = 0
    length = float(top.state.s[-1] + z_lower)
    return top, base.with_changes({"lay.top_tension": None, "lay.pipe_length": length})


def test_pipe_length_reproduces_the_top_tension_case(fixed_length):
    top, case = fixed_length
    given = pf.solve(case).summary
    assert given["top_tension"] == pytest.approx(top.summary["top_tension"], rel=1e-6)
    for key in ("max_von_mises", "overbend_max_moment", "sagbend_max_moment"):
        assert given[key] == pytest.approx(top.summary[key], rel=1e-5), key
    for key in ("tdp_z", "liftoff_z"):
        assert given[key] == pytest.approx(top.summary[key], abs=1e-3), key


def test_fixed_length_sagbend_falls_and_overbend_grows_with_a(fixed_length):
    """With the lower end held (length fixed) a more curved stinger pulls the
    span tighter: in the lift-off regime the overbend peak grows with |a| and
    the sagbend peak falls, as the paper finds; the top tension grows."""
    _, case = fixed_length
    rows = [pf.solve(case.with_changes({"lay.stinger.a": a})).summary
            for a in (-0.0012, -0.0015, -0.0018, -0.0021)]
    over = [r["overbend_max_von_mises"] for r in rows]
    sag = [r["sagbend_max_von_mises"] for r in rows]
    top = [r["top_tension"] for r in rows]
    assert np.all(np.diff(over) > 0) and np.all(np.diff(sag) < 0) and np.all(np.diff(top) > 0)


def test_lateral_hold_clamps_the_free_span_at_the_tip():
    """The stinger holds the pipe on its plane along a line, so the free span
    below the tip is clamped laterally: y = y' = 0 at the held nodes, and the
    lateral moment at the tip is the free side's (the held side carries the
    clamp's couple). With the clamp exact, the peak at the tip of S125 3D
    converges with the mesh: 8 m elements agree with 1 m to 1e-3 (the old hold,
    y = 0 at nodes only, approached the clamp as O(h): 3.7e-3 at 8 m)."""
    base = pf.load_case(EXAMPLES / "s125_3d.toml")
    coarse, fine = (pf.solve(base.with_changes({"solver.element_length": h})) for h in (8.0, 1.0))
    for res in (coarse, fine):
        p = res.profile
        held = (p["z"] >= base.lay.stinger.lower[1] - 1e-3).to_numpy().copy()
        held[-1] = False  # the top is held by its own condition
        assert np.abs(p["y"].to_numpy()[held]).max() < 1e-9
        tip = int(np.flatnonzero(held)[0])
        mz = p["moment_z"].to_numpy()
        # the moment at the tip continues the free span's, and the held side
        # beyond it carries almost none
        assert abs(mz[tip]) > 100e3
        assert abs(mz[tip + 2]) < 0.1 * abs(mz[tip])
        assert abs(mz[tip] - mz[tip - 1]) < 0.1 * abs(mz[tip])
    vm_c, vm_f = coarse.summary["max_von_mises"], fine.summary["max_von_mises"]
    assert abs(vm_c - vm_f) / vm_f < 1e-3


@pytest.mark.parametrize("h", [4.0, 8.0])
def test_an_ungraded_mesh_puts_a_node_where_the_lateral_hold_begins(h):
    """Ungraded (uniform elements), the mesh follows touchdown and lift-off,
    but no unknown follows the tip's material point, where the stinger's
    lateral hold ends: with it up to half an element off a node, S67 3D's peak
    stress (the lateral moment at the tip) was 6.5 % high at 4 and 8 m. The
    mesh is remeshed with a node there: the first held node lies at the tip's
    height, and the peak agrees with the graded 1 m mesh to 1e-3."""
    base = pf.load_case(EXAMPLES / "s67_3d.toml")
    ungraded = pf.solve(base.with_changes({"solver.element_length": h,
                                           "solver.grading": False}))
    fine = pf.solve(base.with_changes({"solver.element_length": 1.0}))
    p = ungraded.profile
    z_tip = base.lay.stinger.lower[1]
    # the hold begins at the node nearest the tip's height (within the share
    # of an element the regrading allows), and it holds y = 0 from there up
    z = p["z"].to_numpy()
    first = int(np.argmin(np.abs(z - z_tip)))
    assert abs(z[first] - z_tip) < 0.02 * h
    assert abs(p["y"].to_numpy()[first:]).max() < 1e-9
    assert abs(p["y"].to_numpy()[first - 1]) > 1e-3  # the free span below it moves
    vm, vm_fine = ungraded.summary["max_von_mises"], fine.summary["max_von_mises"]
    assert abs(vm - vm_fine) / vm_fine < 1e-3


@pytest.mark.parametrize("scene", ["s125", "s125_3d"])
def test_the_fine_mesh_reference_converges_to_the_1_m_answer(scene):
    """speed_vs_error's reference of S125 (0.25 m graded to 0.05 m, some 1900
    elements in 2D and 2300 in 3D): bearing on the tip, its tip's contact
    releases and bears again on the way from the guess, and it must still
    converge there (a regime rule tried once stopped it at the second release,
    and it failed). Its peak stress and touchdown agree with the 1 m mesh's to
    2e-4 and 1 mm (measured 8.4e-5 and 0.08 mm)."""
    base = pf.load_case(EXAMPLES / f"{scene}.toml")
    fine = pf.solve(base.with_changes({"solver.element_length": 0.25,
                                       "solver.min_element_length": 0.05})).summary
    metre = pf.solve(base.with_changes({"solver.element_length": 1.0})).summary
    assert fine["tip_reaction"] > 0.0  # bearing on the tip
    assert abs(metre["max_von_mises"] / fine["max_von_mises"] - 1.0) < 2e-4
    assert abs(metre["tdp_z"] - fine["tdp_z"]) < 1e-3


def test_a_node_sliding_off_the_tip_does_not_cycle():
    """S125 3D on 2 m elements near a = -0.00168: a node at the stinger's tip
    slid off it and back on at every iteration (the boundary it slid off was
    not in the contact history, so the cycle was never frozen) and the solve
    failed. Every a converges now; the peak stress (at the tip) rises
    linearly with |a| there (slopes within 10 %), and agrees with 4 m
    elements to 1e-3."""
    base = pf.load_case(EXAMPLES / "s125_3d.toml")
    grid = [-0.001675, -0.001679, -0.00168, -0.001681, -0.001685]

    def peaks(h):
        return np.array([pf.solve(base.with_changes({"solver.element_length": h,
                                                      "lay.stinger.a": a})).summary[
            "max_von_mises"] for a in grid])

    vm = peaks(2.0)
    slope = np.diff(vm) / np.diff(grid)
    assert np.all(slope < 0.0)  # more negative a: more stress at the tip
    assert np.ptp(slope) < 0.1 * np.abs(slope).mean()
    np.testing.assert_allclose(vm, peaks(4.0), rtol=1e-3)


def test_a_warm_state_slides_to_keep_its_element_lengths(s67):
    """problem._slide_to_length on a solved (smooth) S67 state: after a
    shift in x (as a changed stinger's curve gives), each node slides along
    the pipe by the lengthening of the elements above it; the chords come
    back to their lengths to second order in the shift (here under 1 % of
    the change the shift made), the top stays and the lower end slides
    along the seabed (x held)."""
    from pipelay_fast.engine.warm import _slide_to_length

    pb = pf.solve(s67.with_changes({"environment.current.speed": 0.0})).state
    pos = (np.arange(pb.nn) * pb.ndn)[:, None] + np.arange(pb.nd)
    r_old = pb.u[pos].copy()

    def chords():
        return np.linalg.norm(np.diff(pb.u[pos], axis=0), axis=1)

    before = chords()
    pb.u[0::pb.ndn] += 0.05 * np.sin(np.pi * pb.s / pb.s[-1])
    stretched = np.abs(chords() - before).max()
    assert stretched > 1e-4
    _slide_to_length(pb, r_old)
    assert np.abs(chords() - before).max() < 1e-2 * stretched
    np.testing.assert_array_equal(pb.u[pos[-1]], r_old[-1])
    assert pb.u[0] == pytest.approx(r_old[0, 0], abs=1e-12)


def test_a_warm_start_from_another_pipe_length_gives_the_cold_answer():
    """S67 2D with the pipe length given (its lower end held at z = 0), warm
    from the answer for a pipe 2 m longer: the warm solve cuts its mesh to
    this length and holds the lower end where the case holds it, so it gives
    the cold answer (measured 7e-13 in peak stress; before, held where the
    neighbour's laid pipe put the material point now at the lower end, 2 m
    along the seabed, the top tension was 59 % off)."""
    base = pf.load_case(EXAMPLES / "s67.toml").with_changes(
        {"lay.top_tension": None, "lay.pipe_length": 409.87, "solver.element_length": 2.0})
    neighbour = pf.solve(base.with_changes({"lay.pipe_length": 411.87}))
    cold, warm = pf.solve(base), pf.solve(base, warm=neighbour)
    assert warm.state.s[-1] == pytest.approx(409.87, rel=1e-12)
    assert abs(warm.state.u[warm.state.nd - 1]) < 1e-9  # the lower end at z = 0
    for key in ("top_tension", "max_von_mises", "tdp_z", "liftoff_z"):
        assert warm.summary[key] == pytest.approx(cold.summary[key], rel=1e-8, abs=1e-6), key

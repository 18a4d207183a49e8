"""Target 3 and 6 of the seabed profile (``seabed.profile`` on the elastic
seabed): the stiff limit, the spans over a trench and a hump against an
independent beam on an elastic foundation (scipy's solve_bvp), 3D
admissibility with a current, and the refusals."""

import numpy as np
import pytest
from scipy.integrate import solve_bvp

import pipelay_fast as pf
from pipelay_fast.input.case import load_case
from tests.reference.profile import profile_depth
from tests.test_friction import lateral_drag
from tests.test_hard_cases import weight_of

DEPTH = 125.0
# behind J125's touchdown (z ~ 140 m): a 1 m trench, then a 0.8 m hump
PROFILE = [[-150.0, 125.0], [-70.0, 125.0], [-60.0, 126.0], [-45.0, 126.0], [-35.0, 125.0],
           [15.0, 125.0], [22.0, 124.2], [26.0, 124.2], [33.0, 125.0], [500.0, 125.0]]


def _j125(**changes):
    base = {"environment.current.speed": 0.0, "checks": None, "seabed.stiffness": 1e6}
    return load_case("j125_2d").with_changes({**base, **changes})


def foundation_reference(profile, ei, ws, k, h, z_a, length):
    """The laid pipe as a planar inextensible elastica, independent of the
    engine: unknowns (Z, X, theta, kappa, n_X) along arc length s from z_a,
    where it rests on the flat seabed (X = x_b - w/k, theta = 0), over
    ``length`` [m] to a point resting again; the horizontal force n_Z = h
    [N] (the laid pipe carries no horizontal load), the load q_X = -w + k
    (x_b(Z) - X) where X <= x_b(Z) (the vertical foundation), x_b the PCHIP
    of the table held at its ends. Returns (s, Z, gap = X - x_b(Z)) dense."""
    def xb(z):
        return DEPTH - profile_depth(profile, z)

    def f(s, y):
        z, x, th, kap, nx = y
        qx = -ws + k * np.maximum(xb(z) - x, 0.0)
        # EI theta'' = sin(theta) n_Z - cos(theta) n_X, n_X' = -q_X
        return np.vstack([np.cos(th), np.sin(th), kap, (np.sin(th) * h - np.cos(th) * nx) / ei,
                          -qx])

    def bc(ya, yb):
        return np.array([ya[0] - z_a, ya[1] - (xb(z_a) - ws / k), ya[2],
                         yb[1] - (xb(yb[0]) - ws / k), yb[2]])

    s = np.linspace(0.0, length, 4001)
    y = np.zeros((5, s.size))
    y[0] = z_a + s
    y[1] = xb(y[0]) - ws / k
    sol = solve_bvp(f, bc, s, y, tol=1e-6, max_nodes=1000000)
    assert sol.success, sol.message
    sd = np.linspace(0.0, length, 200001)
    z, x = sol.sol(sd)[0], sol.sol(sd)[1]
    return sd, z, x - xb(z)


def reference_spans(sd, z, gap):
    """(start z, length, largest gap) of each free stretch of a dense solution."""
    free = gap > 0.0
    edges = np.flatnonzero(np.diff(free.astype(int)))
    return [(z[a], sd[b] - sd[a], gap[a:b + 1].max()) for a, b in zip(edges[0::2], edges[1::2],
                                                                       strict=True)]


def test_spans_over_a_trench_and_a_hump_match_an_independent_foundation():
    case = _j125(**{"seabed.profile": PROFILE})
    r = pf.solve(case)
    assert r.summary["status"] == "ok"
    prof = r.profile
    # the horizontal force in the laid pipe: the engine's tension at its lower end
    h = float(prof["effective_tension"].iloc[0])
    sd, z, gap = foundation_reference(PROFILE, case.pipe.bending_stiffness,
                                      float(case.effective_weight(0.0)), 1e6, h, -120.0, 232.0)
    ref = [sp for sp in reference_spans(sd, z, gap) if sp[2] > 0.01]
    spans = r.spans[r.spans["max_gap"] > 0.01]
    assert len(ref) == len(spans) == 3  # over the trench, before and after the hump
    for (z0, length, top), (_, row) in zip(ref, spans.iterrows(), strict=True):
        assert row["start_z"] == pytest.approx(z0, abs=0.5)
        assert row["length"] == pytest.approx(length, rel=0.01)
        assert row["max_gap"] == pytest.approx(top, rel=0.01)
    sm = r.summary
    assert sm["n_spans"] == len(r.spans)
    assert sm["max_span_length"] == pytest.approx(r.spans["length"].max())
    assert sm["max_span_gap"] == pytest.approx(max(sp[2] for sp in ref), rel=0.01)
    assert sm["seabed_depth_at_tdp"] == pytest.approx(DEPTH)  # touchdown on the flat part
    # the foundation's force is k times the sinking under the profile
    assert (prof["seabed_reaction"] >= 0.0).all()


def test_stiff_foundation_on_a_flat_profile_gives_the_rigid_answer():
    case = _j125(**{"seabed.stiffness": 1e9, "seabed.profile": [[-100.0, DEPTH], [600.0, DEPTH]]})
    rigid = pf.solve(_j125(**{"seabed.stiffness": "rigid"})).summary
    stiff = pf.solve(case).summary
    for key in ("bottom_tension", "top_angle_deg", "sagbend_max_moment", "max_von_mises"):
        assert stiff[key] == pytest.approx(rigid[key], rel=1e-3), key
    # the foundation's touchdown (where the axis rises out of it) lies about a
    # foundation length (4 EI/k)^(1/4) beyond the rigid one (tests/test_boundaries.py)
    beta = (4.0 * case.pipe.bending_stiffness / 1e9) ** 0.25
    assert 0.0 < stiff["tdp_z"] - rigid["tdp_z"] < 1.5 * beta
    assert stiff["n_spans"] == 0


def test_touchdown_on_a_profiles_flank_gives_its_height_and_depth():
    """J125 touching down where the profile rises 4 m over 160 m (z = 60 to
    220 m): ``seabed_depth_at_tdp`` is the table's depth at ``tdp_z``
    (scipy's PCHIP), and ``tdp_x``, the axis where it leaves the foundation,
    is the seabed's height there, to a micrometre (the pipe rests w/k =
    3.3 mm below the surface behind touchdown)."""
    rows = [[-200.0, DEPTH], [60.0, DEPTH], [220.0, DEPTH - 4.0], [600.0, DEPTH - 4.0]]
    r = pf.solve(_j125(**{"seabed.profile": rows}))
    sm = r.summary
    assert sm["status"] == "ok" and 80.0 < sm["tdp_z"] < 200.0
    depth = float(profile_depth(rows, sm["tdp_z"]))
    assert DEPTH - 3.9 < depth < DEPTH - 0.1  # on the flank
    assert sm["seabed_depth_at_tdp"] == pytest.approx(depth, abs=1e-9)
    assert sm["tdp_x"] == pytest.approx(DEPTH - depth, abs=1e-6)


def test_3d_with_a_current_on_a_profile_is_admissible():
    """J125 3D (1 m/s along +y) on the trench and hump: the foundation
    pushes, it and the vessel carry the weight, friction stays in its cone
    (mu times the foundation's force) and balances the drag with the vessel
    and the held lower end (tests/test_friction.py's checks, its drag)."""
    case = load_case("j125_3d").with_changes(
        {"checks": None, "seabed.stiffness": 1e6, "seabed.profile": PROFILE,
         "solver.element_length": 1.0})
    r = pf.solve(case)
    assert r.summary["status"] == "ok" and r.summary["dimension"] == "3d"
    prof = r.profile
    w = prof["seabed_reaction"].to_numpy()
    assert (w >= 0.0).all() and r.summary["n_spans"] >= 3
    # the drag has no vertical part here (current along y, normal to x)
    carried = prof["reaction_x"].sum() + w.sum()
    assert carried == pytest.approx(weight_of(case, prof), rel=1e-3)
    bed = (prof["contact"] == "seabed").to_numpy() & (prof["s"] > 0.0).to_numpy()
    fy = prof["reaction_y"].to_numpy()[bed]
    assert np.all(np.abs(fy) <= case.seabed.lateral_friction * w[bed] * (1 + 1e-6))
    drag = lateral_drag(case, prof)
    assert prof["reaction_y"].sum() + drag == pytest.approx(0.0, abs=2e-3 * drag)


@pytest.mark.parametrize("changes, words", [
    ({"seabed.profile": [[0.0, 120.0], [-10.0, 125.0]]}, "seabed.profile[1]"),
    ({"seabed.profile": [[0.0, 120.0], [10.0, 0.0]]}, "not positive"),
    ({"seabed.profile": [[0.0, 120.0], [10.0, -3.0]]}, "seabed.profile[1]"),
    ({"seabed.profile": [[0.0, 120.0]]}, "two rows"),
    ({"seabed.stiffness": "rigid", "seabed.profile": [[0.0, 125.0], [10.0, 126.0]]},
     "needs the elastic seabed"),
    ({"seabed.slope_deg": 2.0, "seabed.profile": [[0.0, 125.0], [10.0, 126.0]]},
     "seabed.slope_deg"),
])
def test_bad_profiles_are_refused_naming_the_key(changes, words):
    with pytest.raises(ValueError) as err:
        _j125(**changes)
    assert "seabed.profile" in str(err.value) and words in str(err.value)

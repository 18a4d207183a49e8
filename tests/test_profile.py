"""The seabed profile's input and interpolant (input/profile.py, kernels/bed.py)
against scipy's Hermite and PCHIP interpolants."""

import numpy as np
import pytest
from scipy.integrate import solve_bvp
from scipy.interpolate import CubicHermiteSpline, PchipInterpolator

from pipelay_fast.input.profile import bed_knots, check_profile, pchip_slopes
from pipelay_fast.kernels.bed import bed_height
from tests.reference.profile import profile_depth

# a trench then a hump along the route [m]
PROFILE = [[-400.0, 60.0], [-250.0, 61.0], [-200.0, 64.5], [-170.0, 64.0],
           [-120.0, 59.0], [-90.0, 58.0], [0.0, 60.0]]
DEPTH = 60.0


def _knots():
    return bed_knots(check_profile(PROFILE), DEPTH)


def test_interior_slopes_are_scipys_pchip():
    z, x = _knots()[:, 0], _knots()[:, 1]
    m = pchip_slopes(z, x)
    ref = PchipInterpolator(z, x).derivative()(z)
    np.testing.assert_allclose(m[1:-1], ref[1:-1], rtol=1e-13, atol=1e-15)
    assert m[0] == 0.0 and m[-1] == 0.0


def test_kernel_is_the_hermite_interpolant():
    knots = _knots()
    ref = CubicHermiteSpline(knots[:, 0], knots[:, 1], knots[:, 2])
    dref = ref.derivative()
    for z in np.linspace(-399.0, -1.0, 777):
        x, dx = bed_height(knots, z)
        assert x == pytest.approx(float(ref(z)), abs=1e-11)
        assert dx == pytest.approx(float(dref(z)), abs=1e-11)


def test_c1_at_knots_and_held_beyond():
    knots = _knots()
    eps = 1e-7
    for zk, xk, mk in knots:
        for side in (-eps, eps):
            x, dx = bed_height(knots, zk + side)
            assert x == pytest.approx(xk, abs=1e-5)
            assert dx == pytest.approx(mk, abs=1e-5)
    assert bed_height(knots, -1e4) == (knots[0, 1], 0.0)
    assert bed_height(knots, 1e4) == (knots[-1, 1], 0.0)
    assert bed_height(np.zeros((0, 3)), 12.0) == (0.0, 0.0)


def test_no_overshoot():
    knots = _knots()
    zs = np.linspace(knots[0, 0], knots[-1, 0], 4001)
    xs = np.array([bed_height(knots, z)[0] for z in zs])
    for k in range(knots.shape[0] - 1):
        inside = (zs >= knots[k, 0]) & (zs <= knots[k + 1, 0])
        lo, hi = sorted(knots[k:k + 2, 1])
        assert xs[inside].min() >= lo - 1e-12 and xs[inside].max() <= hi + 1e-12


@pytest.mark.parametrize("bad, words", [
    ([[0.0, 10.0]], "two rows"),
    ([[0.0, 10.0], [0.0, 12.0]], r"seabed.profile\[1\].*ascend"),
    ([[0.0, 10.0], [5.0, -1.0]], r"seabed.profile\[1\].*not positive"),
    ([[0.0, 10.0], [5.0, 0.0]], r"seabed.profile\[1\].*not positive"),
    ([[0.0, 10.0], [5.0]], r"seabed.profile\[1\].*pair"),
    ([[0.0, 10.0], [float("nan"), 3.0]], r"seabed.profile\[1\].*finite"),
    ([[0.0, 10.0], ["a", 3.0]], r"seabed.profile\[1\].*numbers"),
    ("deep", "table"),
])
def test_bad_profiles_are_refused(bad, words):
    with pytest.raises(ValueError, match=words):
        check_profile(bad)


def test_array_form_is_the_kernels():
    from pipelay_fast.input.profile import bed_heights

    knots = _knots()
    z = np.linspace(-450.0, 50.0, 1001)
    x, dx = bed_heights(knots, z)
    for zi, xi, dxi in zip(z, x, dx, strict=True):
        xk, dxk = bed_height(knots, zi)
        assert xi == pytest.approx(xk, abs=1e-12)
        assert dxi == pytest.approx(dxk, abs=1e-12)
    x0, dx0 = bed_heights(np.zeros((0, 3)), z)
    assert not x0.any() and not dx0.any()


def _beam_on_foundation(rows, depth, ei, h, ws, k, z0, z1, x1):
    """Heights [m] (a callable of z) of the tensioned beam on the unilateral
    foundation under the profile ``rows`` in ``depth`` [m] of water, by
    scipy's solve_bvp, independent of the engine: EI w^(4) - H w^(2) - k
    max(x_b - w, 0) + w_s = 0 on [z0, z1], free at z0 (EI w^(2) = 0,
    EI w^(3) - H w^(1) = 0: no moment, no shear), w = x1, w^(1) = 0 at z1."""
    def xb(z):
        return depth - profile_depth(rows, z)

    def f(z, y):
        return np.vstack([y[1], y[2], y[3],
                          (h * y[2] + k * np.maximum(xb(z) - y[0], 0.0) - ws) / ei])

    def bc(ya, yb):
        return np.array([ya[2], ei * ya[3] - h * ya[1], yb[0] - x1, yb[1]])

    z = np.linspace(z0, z1, 2001)
    y = np.zeros((4, z.size))
    y[0] = np.minimum(xb(z), 0.0) - ws / k
    sol = solve_bvp(f, bc, z, y, tol=1e-8, max_nodes=1000000)
    assert sol.success, sol.message
    return lambda zz: sol.sol(zz)[0]


def test_guess_beam_rests_at_w_over_k_and_bridges_a_narrow_trench():
    """The first guess's laid pipe (engine/bed_guess.py): on a flat profile at
    rest, w_s/k below it (its upper end held there, level); over a trench
    shorter than the beam, sagging into it clear of the trench's bottom (a
    span), the tensioned beam on the foundation solved by scipy's solve_bvp
    (:func:`_beam_on_foundation`; the guess's finite differences on their
    grid of a quarter foundation length, 1.4 m here, are within 3 mm of it
    along the trench's 3.6 cm sag)."""
    from pipelay_fast.engine.bed_guess import laid_on_foundation

    flat = bed_knots(check_profile([[0.0, 100.0], [10.0, 100.0]]), 100.0)
    z = np.linspace(-50.0, 50.0, 41)
    x, th = laid_on_foundation(flat, -50.0, 50.0, -3600.0 / 1e6, 0.0, 2.7e8, 4e5, 3600.0, 1e6,
                               z)
    np.testing.assert_allclose(x, -3600.0 / 1e6, rtol=1e-6)
    np.testing.assert_allclose(th, 0.0, atol=1e-9)
    # (level end rows: scipy's PCHIP then has the engine's zero end slopes)
    rows = [[-20.0, 100.0], [-10.0, 100.0], [-5.0, 101.0], [5.0, 101.0], [10.0, 100.0],
            [20.0, 100.0]]
    z = np.linspace(-60.0, 60.0, 25)
    x, _ = laid_on_foundation(bed_knots(check_profile(rows), 100.0), -80.0, 80.0,
                              -3600.0 / 1e6, 0.0, 2.7e8, 4e5, 3600.0, 1e6, z)
    ref = _beam_on_foundation(rows, 100.0, 2.7e8, 4e5, 3600.0, 1e6, -80.0, 80.0, -3600.0 / 1e6)
    assert -1.0 < x[12] < -0.01
    np.testing.assert_allclose(x, ref(z), rtol=0.0, atol=4e-3)


def test_laid_pipe_prepended_on_a_profile_lies_on_it():
    """Laid pipe prepended at the lower end (engine/problem.py remesh: the
    laid length doubled) is put on the profile's height at its z, scipy's
    PCHIP of the table (a 1 m deeper stretch there), not on the reference
    level."""
    from pipelay_fast.engine.problem import build_problem, remesh
    from pipelay_fast.input.case import load_case

    table = [[-600.0, 126.0], [-300.0, 126.0], [-200.0, 125.0], [600.0, 125.0]]
    case = load_case("j125_2d").with_changes(
        {"environment.current.speed": 0.0, "checks": None, "seabed.stiffness": 1e6,
         "seabed.profile": table, "solver.laid_length": 60.0})
    pb = build_problem(case)
    ndn = pb.ndn
    z_old = float(pb.u[pb.nd - 1])
    new = remesh(case, pb, 60.0, laid=600.0)
    z = new.u[new.nd - 1::ndn]
    first = z < z_old - 1e-9
    assert first.sum() > 10 and z.min() < -300.0
    depth = profile_depth(table, z[first])
    np.testing.assert_allclose(new.u[0::ndn][first], 125.0 - depth, rtol=0.0, atol=1e-9)

"""The elastic seabed on a profile in the element kernels: the tangent's new
x-z coupling (dq_x/dz = k x_b'(z)) and dG/dle against central differences,
and the load against the foundation's closed form k (x_b(z) - x)."""

import numpy as np
import pytest

from pipelay_fast.kernels import layout as L
from pipelay_fast.kernels.assembly import element_force
from pipelay_fast.kernels.bed import bed_height
from tests.test_element import make_props, random_state

# a seabed rising 0.4 m per m around z = 0 and dipping again: slopes of both signs
KNOTS = np.array([[-30.0, -3.0, 0.0], [-2.0, -0.5, 0.35], [2.5, 0.8, -0.2], [30.0, 0.0, 0.0]])


def _state(nd, seed, le=1.7):
    """A random element state with both nodes below the profile (x_b - 0.3 m)."""
    rng = np.random.default_rng(seed)
    ue = random_state(nd, rng, x0=0.0, chord=le)
    ndn = 2 * nd + 1
    for node in (0, ndn):
        ue[node] = bed_height(KNOTS, ue[node + nd - 1])[0] - 0.3
    return ue


@pytest.mark.parametrize("nd", [2, 3])
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_tangent_on_a_profile_matches_central_difference(nd, seed):
    props, sec = make_props(bed_k=1e5)
    ue = _state(nd, seed)
    table = np.zeros((0, 2))
    ne = ue.size
    fe, ke, kfd = np.zeros(ne), np.zeros((ne, ne)), np.zeros((ne, ne))
    for j in range(ne):
        h = 1e-6 * max(1.0, abs(ue[j])) if j % (2 * nd + 1) != 2 * nd else 1e-2
        up = ue.copy()
        up[j] += h
        element_force(nd, 1.7, up, props, sec, table, 0.0, fe, ke, False, bed=KNOTS)
        fp = fe.copy()
        up[j] -= 2 * h
        element_force(nd, 1.7, up, props, sec, table, 0.0, fe, ke, False, bed=KNOTS)
        kfd[:, j] = (fp - fe) / (2 * h)
    element_force(nd, 1.7, ue, props, sec, table, 0.0, fe, ke, True, bed=KNOTS)
    scale = np.abs(kfd).max(axis=1, keepdims=True) + 1e-30
    assert np.max(np.abs(ke - kfd) / scale) < 2e-6
    # the x-z block by itself (small beside the bending's): the positions'
    # x rows on their z columns, which the flat seabed leaves at 0
    ndn = 2 * nd + 1
    xs, zs = np.array([0, ndn]), np.array([nd - 1, ndn + nd - 1])
    block, block_fd = ke[np.ix_(xs, zs)], kfd[np.ix_(xs, zs)]
    ke_flat = np.zeros((ne, ne))
    element_force(nd, 1.7, ue, props, sec, table, 0.0, fe, ke_flat, True)
    assert np.all(ke_flat[np.ix_(xs, zs)] == 0.0)
    np.testing.assert_allclose(block, block_fd, rtol=1e-5)


@pytest.mark.parametrize("nd", [2, 3])
@pytest.mark.parametrize("le", [0.5, 4.0])
def test_length_derivative_on_a_profile_matches_central_difference(nd, le):
    props, sec = make_props(bed_k=1e5)
    table = np.zeros((0, 2))
    ue = _state(nd, 11, le)
    ne = ue.size
    fe, fp, ke = np.zeros(ne), np.zeros(ne), np.zeros((ne, ne))
    dfe = np.full(ne, np.nan)
    element_force(nd, le, ue, props, sec, table, 0.0, fe, ke, False, dfe, bed=KNOTS)
    h = 1e-5 * le
    element_force(nd, le + h, ue, props, sec, table, 0.0, fp, ke, False, bed=KNOTS)
    element_force(nd, le - h, ue, props, sec, table, 0.0, fe, ke, False, bed=KNOTS)
    dfd = (fp - fe) / (2 * h)
    ndn = 2 * nd + 1
    for rows in (np.r_[0:nd, ndn:ndn + nd], np.r_[nd:2 * nd, ndn + nd:ndn + 2 * nd],
                 np.array([2 * nd, ndn + 2 * nd])):
        scale = np.abs(dfd[rows]).max()
        assert np.max(np.abs(dfe[rows] - dfd[rows])) < 1e-8 * scale


@pytest.mark.parametrize("nd", [2, 3])
def test_a_straight_element_sunk_under_the_profile_carries_k_times_the_depth(nd):
    """A straight horizontal element (lam = 0, no bending) at height x0
    below a profile: the x rows of G sum to -(integral of q_x), with q_x =
    k (x_b(z) - x0) - w, integrated here by scipy's quad."""
    from scipy.integrate import quad

    props, sec = make_props(bed_k=2e5, extensible=False)
    props[L.H_CONT] = -100.0  # contents flooded: the weight a constant, whatever x
    ndn = 2 * nd + 1
    le, z0, x0 = 3.0, -1.2, -1.5
    ue = np.zeros(2 * ndn)
    ue[0], ue[nd - 1], ue[2 * nd - 1] = x0, z0, 1.0
    ue[ndn], ue[ndn + nd - 1], ue[ndn + 2 * nd - 1] = x0, z0 + le, 1.0
    fe, ke = np.zeros(2 * ndn), np.zeros((2 * ndn, 2 * ndn))
    element_force(nd, le, ue, props, sec, np.zeros((0, 2)), 0.0, fe, ke, False, bed=KNOTS)
    w = -fe[0] - fe[ndn]  # at zero load the sum is the integral of q_x
    element_force(nd, le, ue, props, sec, np.zeros((0, 2)), 0.0, fe, ke, False)
    w_flat = -fe[0] - fe[ndn]
    ref = quad(lambda z: 2e5 * (max(bed_height(KNOTS, z)[0] - x0, 0.0) - max(-x0, 0.0)),
               z0, z0 + le, points=[-2.0])[0]
    assert w - w_flat == pytest.approx(ref, rel=1e-10)

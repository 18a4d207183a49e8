"""Helpers shared by test modules: the bundled examples, weights, the J-lay elastica."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

import pipelay_fast as pf
from tests.reference.elastica import jlay_elastica

EXAMPLES = Path(pf.__file__).resolve().parent / "examples"
# set by .ci/run: a peer engine that cannot load fails its tests instead of skipping them
REQUIRE_PEERS = "PIPELAY_FAST_REQUIRE_PEERS"


def load(name: str, **changes) -> pf.Case:
    """The bundled example ``name``, with ``changes`` (dotted keys) if any."""
    case = pf.load_case(EXAMPLES / f"{name}.toml")
    return case.with_changes(changes) if changes else case


def refused(base, changes) -> str:
    """The ValueError message of ``base.with_changes(changes)``."""
    with pytest.raises(ValueError) as info:
        base.with_changes(changes)
    return str(info.value)


def require_peer(load):
    """What ``load()`` returns (a peer engine's module); when it raises ImportError
    (the engine is not installed or cannot load), skip the test, or the test
    module when called at import, with the error's message as the reason, or
    fail when the environment sets PIPELAY_FAST_REQUIRE_PEERS=1."""
    try:
        return load()
    except ImportError as err:
        reason = str(err)
    if os.environ.get(REQUIRE_PEERS) == "1":
        pytest.fail(f"{reason} ({REQUIRE_PEERS}=1)", pytrace=False)
    pytest.skip(reason, allow_module_level=True)


def weights(case):
    """Submerged and dry effective weight [N/m], recomputed here from the pipe data."""
    p, env = case.pipe, case.environment
    g = env.gravity
    steel = p.steel_density * np.pi * (p.outer_diameter**2 - p.inner_diameter**2) / 4
    coat = p.coating_density * np.pi * (p.coating_outer_diameter**2 - p.outer_diameter**2) / 4
    w_dry = g * (steel + coat)
    return w_dry - env.water_density * g * np.pi * p.coating_outer_diameter**2 / 4, w_dry


def friction_system(pb):
    """Closures over a solved problem's state ``pb`` (its load factors set by
    the caller), for the seabed friction springs' tests: the node arc lengths
    s (nn,) [m]; ``residual(u, tangent, friction=True)`` -> (g, ab), the
    elements' residual and band tangent (rows 2 kl + i - j) with the springs
    (:func:`pipelay_fast.kernels.contact.friction_forces`) or without;
    ``dense(ab)`` -> the band as a dense matrix; ``friction_only(u)`` -> the
    springs' share of the residual."""
    from pipelay_fast.kernels import layout as L
    from pipelay_fast.kernels.assembly import element_work
    from pipelay_fast.kernels.contact import friction_forces, node_arcs
    from pipelay_fast.kernels.system import _system

    nd, ndn, n = pb.nd, pb.ndn, pb.u.size
    kl = 2 * ndn - 1
    torques = np.full(pb.nn - 1, pb.props[L.TORQUE])
    s = np.zeros(pb.nn)
    node_arcs(pb.s_el, s)
    nb = pb.bnodes.size

    def residual(u, tangent, friction=True):
        g = np.zeros(n)
        ab = np.zeros((3 * kl + 1, n)) if tangent else np.zeros((1, 1))
        _system(nd, pb.s_el, u, pb.model(), torques, ab, kl, kl, g,
                pb.kernel_ends(np.zeros(n)), tangent, np.zeros((nb, pb.nn)),
                np.full(nb, -1, dtype=np.int64), np.zeros((nb, n)), element_work(nd),
                np.zeros(0), np.zeros(0), 0.0)
        if friction:
            friction_forces(nd, u, g, ab, 2 * kl if tangent else 0, pb.model(),
                            pb.contacts.bed_active, pb.contacts.fric, np.zeros(n), s, False)
        return g, ab

    def dense(ab):
        k = np.zeros((n, n))
        for j in range(n):
            for r in range(max(0, j - kl), min(n, j + kl + 1)):
                k[r, j] = ab[2 * kl + r - j, j]
        return k

    def friction_only(u):
        return residual(u, False)[0] - residual(u, False, False)[0]

    return s, residual, dense, friction_only


def elastica_for(case, **tension):
    """The planar J-lay elastica (:func:`jlay_elastica`) of ``case`` with ``tension`` given."""
    w_sub, w_dry = weights(case)
    x_top, z_top = case.lay.top
    ei = case.pipe.youngs_modulus * np.pi * (
        case.pipe.outer_diameter**4 - case.pipe.inner_diameter**4) / 64
    return jlay_elastica(ei, w_sub, w_dry, case.environment.water_depth, x_top, z_top,
                         top_angle_deg=case.lay.top_angle, **tension)


def slay_elastica_for(case):
    """The planar S-lay elastica (:func:`tests.reference.slay.slay_elastica`) of
    ``case``, its top tension given."""
    from tests.reference.slay import slay_elastica

    d = case.environment.water_depth
    return slay_elastica(case.pipe.bending_stiffness, float(case.effective_weight(0.0)),
                         float(case.effective_weight(d + 1.0)), d, case.lay.stinger.a,
                         case.lay.stinger.lower, case.lay.stinger.upper,
                         T_top=case.lay.top_tension)

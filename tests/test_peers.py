"""Peers: the same scenes solved by other engines.

MoorPy's catenary (a mooring-line solver): J125 with EI a million times
smaller (the cable limit), inextensible, the hang-off at the water surface
(all of the pipe submerged, so one weight), and the pipe length given with its
lower end on the seabed at z = 0: MoorPy's ``catenary`` (line from an anchor at
(0, 0) to a fairlead at (z_top, x_top), seabed contact without friction) gives
the horizontal and vertical fairlead forces and the length on the seabed.

OpenSees (``tests/reference/opensees_peer.py``): J125 and S67 in 2D with the
current off (OpenSees has no deformation-dependent drag), corotational elastic
beams from a straight line, compression-only seabed and stinger springs; peaks,
tensions, touchdown and lift-off compared at 1 m elements (observed: stresses
and sagbend moments within 6e-5, overbend moment 2e-4, tensions 2e-5,
touchdown 0.12 m, lift-off 3 cm).

Skipped, with the reason, when MoorPy or openseespy is not installed (extras
``test`` and ``peers``) or cannot load (openseespy needs the system BLAS and
LAPACK); .ci/run sets PIPELAY_FAST_REQUIRE_PEERS=1, which fails them instead."""

from __future__ import annotations

import importlib

import numpy as np
import pytest

import pipelay_fast as pf
from tests.helpers import EXAMPLES, require_peer, weights
from tests.reference import opensees_peer


def _moorpy():
    try:
        return importlib.import_module("moorpy.Catenary")
    except ImportError as err:
        raise ImportError(f"MoorPy cannot import ({err}): pip install '.[test]'") from err


catenary = require_peer(_moorpy).catenary


@pytest.mark.parametrize("length", [480.0, 520.0])
def test_cable_limit_matches_moorpy(j125, length):
    depth = j125.environment.water_depth
    top = (depth, 440.0)  # hang-off at the surface [m]
    case = j125.with_changes({
        "pipe.youngs_modulus": 207e3, "pipe.extensible": False,
        "solver.min_element_length": 0.005, "lay.top": list(top),
        "lay.top_tension": None, "lay.pipe_length": length})
    w_sub, _ = weights(case)
    f_ah, f_av, f_bh, f_bv, info = catenary(top[1], top[0], length, 1e15, w_sub, CB=0.0)
    assert not info["error"]
    ours = pf.solve(case).summary
    horizontal, vertical = -f_bh, -f_bv
    assert ours["bottom_tension"] == pytest.approx(horizontal, rel=1e-4)
    assert ours["top_tension"] == pytest.approx(np.hypot(horizontal, vertical), rel=1e-4)
    # the lower end is at z = 0: touchdown lies at the length on the seabed,
    # up to the rod's boundary layer there, sqrt(EI / H) (5 cm here), by
    # which a rod touches down before the cable
    layer = np.sqrt(case.pipe.bending_stiffness / horizontal)
    assert ours["tdp_z"] == pytest.approx(info["LBot"], abs=2.0 * layer)
    assert ours["suspended_length"] == pytest.approx(length - info["LBot"], abs=2.0 * layer)


# --------------------------------------------------------------------------- OpenSees

PEER_ELEMENT = 1.0  # m, both tools' element length (pipelay_fast grades its mesh)
PEER_RTOL = 0.01  # -, stresses, moments and tensions
PEER_TDP_TOL = 0.25  # m, touchdown (observed: under 0.12 m at 1 m elements)


def _peer_pair(name):
    """(pipelay_fast summary, OpenSees result) for a bundled scene, current off."""
    require_peer(opensees_peer.opensees)
    case = pf.load_case(EXAMPLES / f"{name}.toml").with_changes(
        {"environment.current.speed": 0.0, "solver.element_length": PEER_ELEMENT})
    return pf.solve(case).summary, opensees_peer.solve(case, PEER_ELEMENT)


@pytest.mark.parametrize("name", ["j125", "s67"])
def test_opensees_peer_agrees(name):
    """An OpenSees corotational-beam model of the scene, solved from a straight
    line with compression-only seabed (and stinger) springs, gives the same
    peaks, tensions and touchdown (tests/reference/opensees_peer.py)."""
    ours, peer = _peer_pair(name)
    theirs = peer.summary
    keys = ["max_von_mises", "sagbend_max_von_mises", "sagbend_max_moment", "top_tension",
            "bottom_tension"]
    if name == "s67":
        keys += ["overbend_max_von_mises", "overbend_max_moment"]
    for key in keys:
        assert theirs[key] == pytest.approx(ours[key], rel=PEER_RTOL), key
    assert theirs["tdp_z"] == pytest.approx(ours["tdp_z"], abs=PEER_TDP_TOL)
    if name == "s67":
        assert theirs["liftoff_z"] == pytest.approx(ours["liftoff_z"], abs=2.0 * PEER_ELEMENT)
    # the peer's own checks: contacts barely penetrate, the stinger springs'
    # tangent lines stay on the curve, the lower end lies on the seabed
    checks = peer.stats
    assert checks["bed_penetration_max"] < 1e-5
    assert abs(checks["lower_end_height"]) < 1e-5
    if name == "s67":
        assert checks["stinger_slide_max"] < 0.05
        assert checks["stinger_curve_gap_min"] > -1e-5
        assert checks["stinger_free_clearance_min"] > -1e-5


ROLLERS_PER_SPAN = 24  # the peer's elements between rollers (6.04 m apart: 0.25 m elements)


@pytest.fixture(scope="module")
def roller_pair():
    """S67 on its 23 rollers (``s67_rollers``, on the paper's curve), current
    off, the top held along the curve's tangent: pipelay_fast and the
    OpenSees peer with compression-only supports at the rollers, its nodes
    a 24th of the rollers' spacing apart (at 12, the contacts at the tip
    differ: there the pipe clears roller 20 by 0.19 mm)."""
    require_peer(opensees_peer.opensees)
    curve = pf.load_case(EXAMPLES / "s67.toml").lay.stinger
    case = pf.load_case(EXAMPLES / "s67_rollers.toml").with_changes(
        {"environment.current.speed": 0.0, "solver.element_length": PEER_ELEMENT,
         "lay.top_angle": float(curve.angle(curve.upper[1]))})
    n_rollers = len(case.lay.stinger.rollers)
    h = opensees_peer._Stinger(curve).length / n_rollers / ROLLERS_PER_SPAN
    return pf.solve(case), opensees_peer.solve(case, h, curve=curve)


def test_opensees_peer_agrees_on_rollers(roller_pair):
    """Each roller's reaction within 1 % of the largest, the same rollers in
    contact, and the peaks and tensions within 1 %."""
    ours, peer = roller_pair
    mine = ours.rollers["reaction"].to_numpy()
    theirs = peer.stats["roller_reactions"]
    assert np.abs(theirs - mine).max() < PEER_RTOL * mine.max()
    assert ((theirs > 0.0) == ours.rollers["in_contact"].to_numpy()).all()
    for key in ["max_von_mises", "sagbend_max_von_mises", "sagbend_max_moment",
                "overbend_max_von_mises", "overbend_max_moment", "top_tension",
                "bottom_tension"]:
        assert peer.summary[key] == pytest.approx(ours.summary[key], rel=PEER_RTOL), key
    assert peer.summary["tdp_z"] == pytest.approx(ours.summary["tdp_z"], abs=PEER_TDP_TOL)
    assert peer.stats["stinger_slide_max"] < 0.05
    assert peer.stats["bed_penetration_max"] < 1e-5

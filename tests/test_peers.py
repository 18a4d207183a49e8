"""Peers: the same cable solved by MoorPy's catenary (a mooring-line solver).

J125 with EI a million times smaller (the cable limit), inextensible, the
hang-off at the water surface (all of the pipe submerged, so one weight), and
the pipe length given with its lower end on the seabed at z = 0: MoorPy's
``catenary`` (line from an anchor at (0, 0) to a fairlead at (z_top, x_top),
seabed contact without friction) gives the horizontal and vertical fairlead
forces and the length on the seabed. Skipped when MoorPy is not installed
(extras ``test`` and ``peers``).
"""

from __future__ import annotations

import numpy as np
import pytest
from test_jlay import weights

import pipelay_fast as pf

catenary = pytest.importorskip("moorpy.Catenary", reason="MoorPy not installed").catenary


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

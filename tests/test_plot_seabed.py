"""The case figure's elevation in the frame the case uses (issue 45, part
5): the seabed (a profile, a slope's plane) at the pipe's z, the water line
and one shaded, labelled artist per free span, read back from the figure's
artists and checked against the inputs (the profile's own PCHIP by scipy,
the plane's equation), not against the plotting code."""

from __future__ import annotations

import math

import numpy as np
import pytest

import pipelay_fast as pf
from tests.reference.profile import profile_depth
from tests.test_frame import S67_WATERLINE, waterline
from tests.test_profile_solve import DEPTH, PROFILE

pytest.importorskip("matplotlib")


def _line(ax, label):
    """The panel's one line labelled ``label``."""
    (line,) = [ln for ln in ax.lines if ln.get_label() == label]
    return np.asarray(line.get_xdata(), dtype=float), np.asarray(line.get_ydata(), dtype=float)


def _spans_drawn(ax, result):
    """The span artists (gid "span") and length labels (gid "span length"),
    each checked against its row of ``result.spans``."""
    fills = [c for c in ax.collections if c.get_gid() == "span"]
    texts = [t for t in ax.texts if t.get_gid() == "span length"]
    spans = result.spans
    assert len(fills) == len(texts) == len(spans)
    for fill, text, (_, row) in zip(fills, texts, spans.iterrows(), strict=True):
        s_drawn = np.concatenate([p.vertices[:, 0] for p in fill.get_paths()])
        assert row["start_s"] <= s_drawn.min() and s_drawn.max() <= row["end_s"]
        assert text.get_text() == f"{row['length']:.1f} m"
        assert row["start_s"] < text.xy[0] < row["end_s"]
    return len(fills)


def test_waterline_frame_draws_the_profile_spans_and_water_line_about_still_water():
    """S67 in the waterline frame on a profile with a trench and a hump behind
    touchdown: elevations are x - water_depth, the seabed is -depth(z) at the
    pipe's z, the water line is at 0, one span artist per span."""
    flat = waterline("s67", S67_WATERLINE).with_changes(
        {"seabed.stiffness": 1e6, "checks": None, "environment.current.speed": 0.0})
    depth = flat.environment.water_depth
    z_td = float(pf.solve(flat).summary["tdp_z"])
    rows = [[z_td + dz, depth + d] for dz, d in
            [(-290.0, 0.0), (-210.0, 0.0), (-200.0, 1.0), (-185.0, 1.0), (-175.0, 0.0),
             (-125.0, 0.0), (-118.0, -0.8), (-114.0, -0.8), (-107.0, 0.0), (360.0, 0.0)]]
    result = pf.solve(flat.with_changes({"seabed.profile": rows}))
    assert len(result.spans) >= 2
    ax = result.plot().axes[0]
    cols = result.columns
    assert "still water" in ax.get_ylabel() and "[m]" in ax.get_ylabel()
    s, pipe = _line(ax, "pipe")
    np.testing.assert_array_equal(s, cols["s"])
    np.testing.assert_allclose(pipe, cols["x"] - depth, rtol=0.0, atol=1e-9)
    s_bed, bed = _line(ax, "seabed")
    np.testing.assert_array_equal(s_bed, cols["s"])
    np.testing.assert_allclose(bed, -profile_depth(rows, cols["z"]), rtol=0.0, atol=1e-9)
    _, water = _line(ax, "water line")
    assert (water == 0.0).all()
    _spans_drawn(ax, result)


def test_seabed_frame_draws_the_profile_and_water_line_above_the_reference_seabed():
    """J125 in the seabed frame on tests/test_profile_solve.py's profile:
    elevations are x, the seabed is water_depth - depth(z), the water line is
    at water_depth, one span artist per span."""
    case = pf.load_case("j125_2d").with_changes(
        {"environment.current.speed": 0.0, "checks": None, "seabed.stiffness": 1e6,
         "seabed.profile": PROFILE})
    result = pf.solve(case)
    assert case.environment.water_depth == DEPTH and len(result.spans) >= 2
    ax = result.plot().axes[0]
    cols = result.columns
    assert "reference seabed" in ax.get_ylabel() and "[m]" in ax.get_ylabel()
    _, pipe = _line(ax, "pipe")
    np.testing.assert_array_equal(pipe, cols["x"])
    _, bed = _line(ax, "seabed")
    np.testing.assert_allclose(bed, DEPTH - profile_depth(PROFILE, cols["z"]), rtol=0.0, atol=1e-9)
    _, water = _line(ax, "water line")
    assert (water == DEPTH).all()
    assert _spans_drawn(ax, result) == len(result.spans)


def test_a_sloped_seabed_is_drawn_as_its_plane_and_has_no_spans():
    """S67 on a 2 deg slope (rigid): the seabed line is the plane
    x = (z - slope_origin) tan(slope) at the pipe's z; no span artists."""
    case = pf.load_case("s67").with_changes(
        {"checks": None, "environment.current.speed": 0.0, "seabed.slope_deg": 2.0,
         "seabed.slope_origin": 100.0})
    result = pf.solve(case)
    ax = result.plot().axes[0]
    _, bed = _line(ax, "seabed")
    z = result.columns["z"]
    np.testing.assert_allclose(bed, (z - 100.0) * math.tan(math.radians(2.0)), rtol=0.0,
                               atol=1e-9)
    assert len(result.spans) == 0 and _spans_drawn(ax, result) == 0

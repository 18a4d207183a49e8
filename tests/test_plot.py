"""Figures: Result.plot / pipelay-fast plot CASE.toml, and a sweep's figure.

Each test renders into a temporary folder and checks the file (written, its
format, its pixel size), and that the curves are drawn from the data: line
counts, the plotted values, axis limits that hold the data."""

from __future__ import annotations

import struct

import numpy as np
import pytest

import pipelay_fast as pf
from pipelay_fast.cli import main
from pipelay_fast.output.design import interior_peak, lcc_sections, utilisation_along
from pipelay_fast.output.io import read_result, write_result
from pipelay_fast.output.plot import DPI, PANEL_SIZE, marks
from pipelay_fast.study.dataset import read_summary
from pipelay_fast.study.plot import plot_sweep
from pipelay_fast.study.runner import run_sweep
from pipelay_fast.study.select import select
from pipelay_fast.study.sweep_file import load_sweep
from tests.helpers import EXAMPLES

pytest.importorskip("matplotlib")


def png_size(path) -> tuple[int, int]:
    """(width, height) in pixels from the PNG's IHDR chunk."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", data[16:24])


def _holds(limits, values):
    lo, hi = sorted(limits)
    return lo <= np.nanmin(values) and np.nanmax(values) <= hi


@pytest.fixture(scope="module")
def s67():
    return pf.solve(pf.load_case(EXAMPLES / "s67.toml"))


MARKS = ("touchdown", "lift-off", "tip")


def _marks(ax, count) -> list[float]:
    """The x of a panel's last ``count`` lines (its vertical marks), each
    checked to be vertical."""
    xs = []
    for line in ax.lines[-count:]:
        x = np.asarray(line.get_xdata(), dtype=float)
        assert x[0] == x[-1]
        xs.append(float(x[0]))
    return xs


def test_result_plot_draws_the_lay(s67, tmp_path):
    path = tmp_path / "lay.png"
    fig = s67.plot(path)
    assert png_size(path) == (round(PANEL_SIZE[0] * DPI), round(4 * PANEL_SIZE[1] * DPI))
    assert path.stat().st_size > 20_000
    elevation, moment, vm, util = fig.axes  # 2D: no plan
    cols, case, sm = s67.columns, s67.case, s67.summary
    s = cols["s"]
    for ax in fig.axes:  # every panel against s, its x axis the elevation's
        np.testing.assert_array_equal(ax.lines[0].get_xdata(), s)
        assert ax.get_shared_x_axes().joined(ax, elevation)
    # touchdown, lift-off and the tip on every panel, where the summary has them
    tdp, lift, tip = _marks(elevation, 3)
    assert [line.get_label() for line in elevation.lines[-3:]] == list(MARKS)
    assert np.interp(tdp, s, cols["z"]) == pytest.approx(sm["tdp_z"], abs=1e-9)
    assert np.interp(lift, s, cols["z"]) == pytest.approx(sm["liftoff_z"], abs=1e-9)
    assert np.interp(tip, s, cols["z"]) == pytest.approx(case.lay.stinger.lower[1], abs=1e-9)
    for ax in fig.axes[1:]:
        assert _marks(ax, 3) == [tdp, lift, tip]
    # pipe, seabed, water line, stinger, then the marks
    assert len(elevation.lines) == 4 + 3
    np.testing.assert_array_equal(elevation.lines[0].get_ydata(), cols["x"])
    assert _holds(elevation.get_ylim(), [0.0, case.environment.water_depth, cols["x"].max()])
    # the signed in-plane moment: sagging (> 0) between touchdown and the
    # inflection, hogging (< 0) on the stinger above lift-off
    m = moment.lines[0].get_ydata()
    np.testing.assert_allclose(m, cols["moment_y"] / 1e3)
    assert "hogging" in moment.get_ylabel() and "sagging" in moment.get_ylabel()
    assert (m[s > lift] < 0.0).all() and m.max() > 0.0
    assert tdp < s[np.argmax(m)] < lift
    assert _holds(moment.get_ylim(), m)
    # von Mises and the SMYS line at pipe.smys, labelled with its value
    smys = vm.lines[1]
    assert smys.get_ydata()[0] == case.pipe.smys / 1e6
    assert smys.get_label() == f"SMYS {case.pipe.smys / 1e6:.0f} MPa"
    assert _holds(vm.get_ylim(), cols["von_mises"] / 1e6)
    # sagbend load-controlled, overbend strain / limit, the line at 1, the marks
    assert len(util.lines) == 3 + 3
    sag, over, one = (line.get_ydata() for line in util.lines[:3])
    assert one[0] == 1.0
    assert max(np.nanmax(sag), np.nanmax(over)) == pytest.approx(sm["max_utilisation"],
                                                                   abs=1e-9)
    # each check only where the code applies it: the strain limit on the
    # hogging pipe above touchdown, the load-controlled one from touchdown
    # to lift-off on the rest
    hogging = (s >= tdp) & (cols["moment_y"] < 0.0)
    assert np.array_equal(np.isfinite(over), hogging)
    assert np.array_equal(np.isfinite(sag), (s >= tdp) & (s <= lift) & ~hogging)
    assert np.nanmax(over) == pytest.approx(sm["overbend_max_strain"]
                                            / case.checks.overbend_strain_limit, rel=1e-12)
    assert _holds(util.get_ylim(), np.concatenate([sag[np.isfinite(sag)],
                                                   over[np.isfinite(over)]]))


def test_bearing_on_the_tip_is_marked(tmp_path):
    """The roller stinger of s125_rollers bears on its last roller (its tip)."""
    result = pf.solve(pf.load_case(EXAMPLES / "s125_rollers.toml"))
    assert result.summary["bears_on_tip"]
    fig = result.plot()
    elevation = fig.axes[0]
    tip_s = float(result.rollers["s"].iloc[-1])
    star = next(line for line in elevation.lines if line.get_label().startswith("bears on tip"))
    assert star.get_xdata()[0] == tip_s
    tip = next(line for line in elevation.lines if line.get_label().startswith("tip"))
    assert tip.get_xdata()[0] == tip_s and tip.get_linestyle() == "-"
    util = fig.axes[-1]
    top = max(np.nanmax(line.get_ydata()) for line in util.lines[:2])
    assert top == pytest.approx(result.summary["max_utilisation"], abs=1e-9)


def test_jlay_utilisation_is_the_sagbend_peak():
    """J-lay: no overbend, no lift-off or tip; the load-controlled curve above
    touchdown peaks at the summary's max_utilisation (a clamped top's rise
    above the sagbend's peak is not drawn)."""
    result = pf.solve(pf.load_case(EXAMPLES / "j125.toml"))
    fig = result.plot()
    sm, cols = result.summary, result.columns
    (tdp,) = _marks(fig.axes[0], 1)
    assert np.interp(tdp, cols["s"], cols["z"]) == pytest.approx(sm["tdp_z"], abs=1e-9)
    sag, over = (line.get_ydata() for line in fig.axes[-1].lines[:2])
    assert np.isnan(over).all()
    assert np.nanmax(sag) == pytest.approx(sm["max_utilisation"], abs=1e-9)


def test_jlay_clamped_top_rise_is_left_out():
    """J-lay's sagbend utilisation is the interior peak above touchdown
    (a clamped top's rise is not in it): a profile whose top three nodes
    carry 1.5, 2 and 3 times the sagbend peak's moment, so that the
    load-controlled utilisation rises to the top above the peak, has that
    rise left out and the peak kept."""
    result = pf.solve(pf.load_case(EXAMPLES / "j125.toml"))
    cols = {k: np.array(v, copy=True) for k, v in result.columns.items()}
    lcc = lcc_sections(result.case, cols, result.functional)[0]
    behind = cols["s"] >= marks(result)["touchdown"]
    peak = interior_peak(lcc[behind])
    at_peak = np.flatnonzero(lcc == peak)[0]
    for name in ("moment_x", "moment_y", "moment_z"):  # (the section peak's moment, raised)
        cols[name][-3:] = cols[name][at_peak] * np.array([1.5, 2.0, 3.0])
    raised = lcc_sections(result.case, cols, result.functional)[0]
    assert raised[-1] > raised[-2] > raised[-3] > peak  # the rise to the top
    over, sag = utilisation_along(result.case, cols, marks(result)["touchdown"], None, None,
                                  result.functional)
    assert np.isnan(over).all() and np.isnan(sag[-3:]).all()
    assert np.nanmax(sag) == interior_peak(raised[behind]) == pytest.approx(peak, rel=1e-12)


def test_a_written_result_plots_the_same_marks(s67, tmp_path):
    """A solve written to disk and read back (no solver state) marks
    touchdown, lift-off and the tip where the solved result does."""
    write_result(s67, tmp_path / "out")
    again = read_result(tmp_path / "out")
    assert marks(again) == marks(s67)
    util = again.plot().axes[-1]
    top = max(np.nanmax(line.get_ydata()) for line in util.lines[:2])
    assert top == pytest.approx(s67.summary["max_utilisation"], abs=1e-9)


def test_3d_lay_has_a_plan_and_no_checks_shows_strain(tmp_path):
    case = pf.load_case(EXAMPLES / "s67_3d.toml").with_changes({"checks": None})
    result = pf.solve(case)
    path = tmp_path / "lay3d.png"
    fig = result.plot(path)
    assert png_size(path) == (round(PANEL_SIZE[0] * DPI), round(5 * PANEL_SIZE[1] * DPI))
    plan, util = fig.axes[1], fig.axes[4]
    np.testing.assert_array_equal(plan.lines[0].get_xdata(), result.columns["s"])
    np.testing.assert_array_equal(plan.lines[0].get_ydata(), result.columns["y"])
    assert _holds(plan.get_ylim(), result.columns["y"])
    assert util.get_ylabel() == "strain [%]" and len(util.lines) == 1 + 3


@pytest.mark.parametrize(("suffix", "magic"), [(".svg", b"<?xml"), (".pdf", b"%PDF")])
def test_cli_plot_case_format_by_suffix(tmp_path, capsys, suffix, magic):
    out = tmp_path / f"j125{suffix}"
    assert main(["plot", str(EXAMPLES / "j125.toml"), "--out", str(out)]) == 0
    assert out.read_bytes()[:len(magic)] == magic
    assert f"wrote {out}" in capsys.readouterr().out


A_SWEEP = {"name": "a_sweep", "set": {"solver.element_length": 8.0},
           "scenes": [{"name": "S67", "case": "s67", "reference_a": -0.0012,
                       "vary": {"a": [-0.0010, -0.0012, -0.0014]}}]}


def _labelled(ax, start: str):
    """The lines of ``ax`` whose label starts with ``start``."""
    return [line for line in ax.lines if line.get_label().startswith(start)]


def test_sweep_plot_marks_the_chosen_a(tmp_path):
    root = tmp_path / "a"
    run_sweep(load_sweep(A_SWEEP), root, workers=1, progress=False)
    table = select(root)
    chosen, least = table["a_equal_peaks"].iloc[0], table["a_min_stress"].iloc[0]
    path = tmp_path / "a.png"
    fig = plot_sweep(root, path)
    assert png_size(path) == (round(PANEL_SIZE[0] * DPI), round(PANEL_SIZE[1] * DPI))
    (ax,) = fig.axes
    summary = read_summary(root).sort_values("a")
    over, sag, smys = ax.lines[:3]
    np.testing.assert_array_equal(over.get_xdata(), summary["a"])
    np.testing.assert_allclose(over.get_ydata(), summary["overbend_max_von_mises"] / 1e6)
    np.testing.assert_allclose(sag.get_ydata(), summary["sagbend_max_von_mises"] / 1e6)
    # the SMYS line at the pipe's SMYS
    pipe = pf.load_case(EXAMPLES / "s67.toml").pipe
    assert smys.get_ydata()[0] == pytest.approx(pipe.smys / 1e6, rel=1e-12)
    assert smys.get_label() == f"SMYS {pipe.smys / 1e6:.0f} MPa"
    # the chosen a, printed as select's table prints it (six decimals)
    (mark,) = _labelled(ax, "equal peaks a")
    (least_mark,) = _labelled(ax, "min stress a")
    assert np.isfinite(chosen) and mark.get_xdata()[0] == chosen
    assert np.isfinite(least) and least_mark.get_xdata()[0] == least
    assert mark.get_label() == f"equal peaks a = {chosen:.6f}"
    # the scene's published a (A_SWEEP's reference_a), marked where it is
    (reference,) = _labelled(ax, "reference a")
    assert reference.get_xdata()[0] == A_SWEEP["scenes"][0]["reference_a"]
    assert _holds(ax.get_xlim(), summary["a"])
    assert _holds(ax.get_ylim(), summary[["overbend_max_von_mises",
                                          "sagbend_max_von_mises"]].to_numpy() / 1e6)
    assert ax.get_title().endswith("top tension 580 kN")  # the case's given tension, in kN
    # a minimum tip clearance half-way between two grid points' binds inside
    # the grid: the range is shaded, and its binding end is a line where the
    # clearance interpolated along the grid equals the limit
    clearance = summary["tip_clearance"].to_numpy()
    limit = 0.5 * (clearance[0] + clearance[1])
    table = select(root, refine=False, limits={"min_tip_clearance": limit})
    low, high = table["a_feasible_min"].iloc[0], table["a_feasible_max"].iloc[0]
    (ax,) = plot_sweep(root).axes
    (span,) = ax.patches
    assert span.get_x() == low
    assert span.get_x() + span.get_width() == pytest.approx(high, rel=1e-12)
    (bound,) = _labelled(ax, "tip_clearance >=")
    end = bound.get_xdata()[0]
    assert end in (low, high)
    assert np.interp(end, summary["a"], clearance) == pytest.approx(limit, abs=1e-12)


def test_sweep_plot_draws_no_lay_table_for_several_cases_per_depth(tmp_path):
    """Two depths with three values of a each: a sweep over a, not a lay
    table (one case per depth); its panels are the two against a, the
    shallower scene's first."""
    sweep = {"name": "two", "set": {"solver.element_length": 8.0}, "scenes": [
        {"name": name, "case": "s67", "water_depth": float(d),
         "stinger_lower": [d - 25.5, 265.0], "stinger_upper": [d + 5.0, 400.0],
         "vary": {"a": [-0.0010, -0.0012, -0.0014]}} for name, d in (("deep", 80),
                                                                     ("shallow", 67))]}
    root = tmp_path / "two"
    run_sweep(load_sweep(sweep), root, workers=1, progress=False)
    fig = plot_sweep(root)
    visible = [ax for ax in fig.axes if ax.get_visible()]
    assert len(visible) == 2
    assert all(ax.get_xlabel() == "a [1/m]" for ax in visible)
    # shallowest first, whatever the scenes' names
    assert [ax.get_title().split()[0] for ax in visible] == ["shallow", "deep"]


DEPTH_SWEEP = {"name": "depths", "set": {"solver.element_length": 8.0},
               "select": {"top_tension": [400e3, 900e3], "max_utilisation": 0.9}, "scenes": [
    {"name": f"S{d}", "case": "s67", "water_depth": float(d),
     "stinger_lower": [d - 25.5, 265.0], "stinger_upper": [d + 5.0, 400.0]}
    for d in (67, 80, 95)]}


def test_sweep_plot_draws_the_lay_table_against_depth(tmp_path, capsys):
    root = tmp_path / "d"
    run_sweep(load_sweep(DEPTH_SWEEP), root, workers=1, progress=False)
    assert main(["plot", str(root)]) == 0
    path = root / "sweep.png"
    assert png_size(path) == (round(2 * PANEL_SIZE[0] * DPI), round(PANEL_SIZE[1] * DPI))
    fig = plot_sweep(root)
    tension, util = fig.axes
    summary = read_summary(root).sort_values("water_depth")
    np.testing.assert_array_equal(tension.lines[0].get_xdata(), [67.0, 80.0, 95.0])
    np.testing.assert_allclose(tension.lines[0].get_ydata(), summary["top_tension"] / 1e3)
    np.testing.assert_allclose(util.lines[0].get_ydata(), summary["max_utilisation"])
    # the limits of [select] as lines: the tension window, the utilisation's
    assert len(util.lines) == 2 and util.lines[1].get_ydata()[0] == 0.9
    assert [line.get_ydata()[0] for line in tension.lines[1:]] == [400.0, 900.0]
    assert _holds(util.get_ylim(), summary["max_utilisation"])


def test_sweep_plot_of_nothing_is_refused(tmp_path):
    with pytest.raises(ValueError, match="no solved case to plot"):
        plot_sweep(tmp_path)
    assert main(["plot", str(tmp_path)]) == 2

"""The figure of a sweep's results directory (matplotlib, the ``plot`` extra).

:func:`plot_sweep`: the overbend and sagbend peaks of von Mises stress
against ``a`` for each S-lay scene and current, shallowest scene first, with
the SMYS line and ``select``'s answers (``selection.parquet``): the feasible
range shaded, the limits binding at its ends and the chosen ``a`` as
vertical lines, as the paper's Figures 3, 5, 7 and 9; and, when a method
was solved at several depths, the lay table against depth (top tension with
the ``[select]`` tension window, max utilisation with its limit).

Figures are built without pyplot (no display needed, nothing global changed);
``path`` writes them, the format from its suffix (PNG by default, SVG, PDF).
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np
import pandas as pd

from ..output.plot import figure, save
from .dataset import read_summary
from .limits import DEFAULT_MAX_UTILISATION, check_limits
from .select import design_variable
from .select_format import design_value
from .sweep import AXES

__all__ = ["plot_sweep"]

# the columns that make one curve over a (as select's groups)
GROUP_KEYS = ("scene", "dimension", "water_depth", "current_speed", "current_heading_deg",
              "given_top_tension", "given_bottom_tension", "given_pipe_length")
GIVEN_KEYS = GROUP_KEYS[5:]  # the given tension or pipe length, in a panel's title


def plot_sweep(root: str | os.PathLike, path: str | os.PathLike | None = None):
    """The figure of a sweep's results directory ``root``; written to ``path``
    when given. Returns the matplotlib Figure.

    One panel per S-lay scene, dimension, water depth, current and given
    tension whose cases span several values of a stinger design axis (``a``, or a roller
    stinger's ``stinger_radius`` or ``roller_shift``), ordered by water
    depth: :func:`_design_panel`'s. Then, for each method solved at several
    water depths with one case per depth (a lay table), top tension (with
    the ``[select]`` table's ``top_tension`` window of ``root/sweep.json``
    as lines) and max utilisation (with its ``max_utilisation`` limit, by
    default DEFAULT_MAX_UTILISATION) against depth.

    Raises
    ------
    ValueError
        When the directory has no solved case to draw.
    """
    root = Path(root)
    summary = read_summary(root)
    if summary.empty or not (summary["status"] == "ok").any():
        raise ValueError(f"{root}: no solved case to plot (run a sweep into it first)")
    ok = summary[summary["status"] == "ok"]
    slay = ok[ok["method"] == "S"]
    groups = []  # (key, the design axis it varies, its cases along it)
    for k, g in slay.groupby(list(GROUP_KEYS), sort=True, observed=True, dropna=False):
        variable = design_variable(None, g)
        if variable in g and g[variable].nunique() > 1:
            groups.append((dict(zip(GROUP_KEYS, k, strict=True)), variable,
                           g.sort_values(variable)))
    groups.sort(key=lambda group: float(group[2]["water_depth"].min()))  # shallow first
    # a lay table: one case per water depth (a sweep with several cases at a
    # depth, over a or the current, is drawn against a above instead)
    depth_groups = [(m, g.sort_values("water_depth")) for m, g in ok.groupby("method", sort=True)
                    if g["water_depth"].nunique() > 1 and not g["water_depth"].duplicated().any()]
    panels = len(groups) + 2 * len(depth_groups)
    if panels == 0:
        raise ValueError(f"{root}: nothing to plot: no S-lay scene over several a and no "
                         "method over several water depths")
    cols = 2 if panels > 1 else 1
    fig = figure(math.ceil(panels / cols), cols)
    axes = np.atleast_1d(fig.subplots(math.ceil(panels / cols), cols)).ravel()
    selection = _selection(root)
    limits = _limits(root)
    for ax, (key, variable, g) in zip(axes, groups, strict=False):
        _design_panel(ax, key, variable, g, selection)
    rest = axes[len(groups):]
    for i, (method, g) in enumerate(depth_groups):
        ax_t, ax_u = rest[2 * i], rest[2 * i + 1]
        ax_t.plot(g["water_depth"], g["top_tension"] / 1e3, "o-", color="C0")
        for bound in limits.get("top_tension", ()):  # the tensioner's window
            ax_t.axhline(bound / 1e3, color="C3", lw=1.0, ls="--")
        ax_t.set(xlabel="water depth [m]", ylabel="top tension [kN]",
                 title=f"{method}-lay table: top tension")
        ax_u.plot(g["water_depth"], g["max_utilisation"], "o-", color="C3")
        ax_u.axhline(limits.get("max_utilisation", DEFAULT_MAX_UTILISATION), color="k", lw=1.0,
                     ls="--")
        ax_u.set(xlabel="water depth [m]", ylabel="max utilisation [-]",
                 title=f"{method}-lay table: max utilisation")
        for a in (ax_t, ax_u):
            a.grid(alpha=0.3)
    for ax in axes[panels:]:
        ax.set_visible(False)
    if path is not None:
        save(fig, path)
    return fig


def _design_panel(ax, key: dict, variable: str, g: pd.DataFrame, selection):
    """One group's panel: the overbend and sagbend peaks of von Mises stress
    [MPa] against the design axis ``variable``, the SMYS line, ``select``'s
    feasible range shaded with a line at each end a limit binds (labelled
    with the limit), its equal-peaks and least-stress values and the
    scene's ``reference_a`` (a published a) as vertical lines; the values
    chosen printed as ``select`` prints them
    (:func:`.select_format.design_value`: they lie between grid points)."""
    x = g[variable].to_numpy(dtype=float)
    ax.plot(x, g["overbend_max_von_mises"] / 1e6, "o-", color="C0", label="overbend")
    ax.plot(x, g["sagbend_max_von_mises"] / 1e6, "s-", color="C1", label="sagbend")
    ratio = g["max_von_mises_over_smys"].to_numpy(dtype=float)
    if np.isfinite(ratio).any():  # SMYS = max_von_mises / max_von_mises_over_smys
        i = int(np.nanargmax(ratio))
        smys = float(g["max_von_mises"].iloc[i]) / ratio[i]
        ax.axhline(smys / 1e6, color="C3", lw=1.0, label=f"SMYS {smys / 1e6:.0f} MPa")
    low = _chosen(selection, key, f"{variable}_feasible_min")
    high = _chosen(selection, key, f"{variable}_feasible_max")
    if low is not None and high is not None:
        ax.axvspan(low, high, color="C2", alpha=0.15,
                   label=f"feasible {variable} [{design_value(low)}, {design_value(high)}]")
        for end, side, style in ((low, "min", "-."), (high, "max", (0, (5, 2, 1, 2)))):
            binds = _chosen_text(selection, key, f"feasible_{side}_binds")
            if binds and binds != "grid end":
                ax.axvline(end, color="C2", ls=style, lw=1.2, label=binds)
    for what, style in (("equal_peaks", "--"), ("min_stress", ":")):
        chosen = _chosen(selection, key, f"{variable}_{what}")
        if chosen is not None:
            ax.axvline(chosen, color="C3", ls=style, lw=1.0,
                       label=f"{what.replace('_', ' ')} {variable} = {design_value(chosen)}")
    reference = _chosen(selection, key, "reference_a") if variable == "a" else None
    if reference is not None:  # the scene's published a (its reference_a)
        ax.axvline(reference, color="k", ls="--", lw=0.8, alpha=0.6,
                   label=f"reference a = {design_value(reference)}")
    ax.xaxis.get_major_formatter().set_useOffset(False)
    ax.xaxis.get_major_formatter().set_scientific(False)
    given = [_given(name, key[name]) for name in GIVEN_KEYS if np.isfinite(key[name])]
    ax.set(xlabel=f"{variable} [{AXES[variable][2]}]", ylabel="peak von Mises [MPa]",
           title=f"{key['scene']} {key['dimension']}, depth {g['water_depth'].iloc[0]:g} m, "
                 f"current {key['current_speed']:g} m/s at {key['current_heading_deg']:g} deg"
                 + "".join(f", {t}" for t in given))
    ruled_out = _chosen_text(selection, key, "ruled_out_by")  # (when no grid point is feasible)
    # one clause of the reason a line
    title = ("\n".join(f"no feasible {variable}: {ruled_out}".split("; ")) if ruled_out
             else None)
    ax.legend(fontsize="small", title=title, title_fontsize="x-small")
    ax.grid(alpha=0.3)


def _given(name: str, value: float) -> str:
    """A panel's given tension [kN] or pipe length [m], for its title."""
    label = name.removeprefix("given_").replace("_", " ")
    if name == "given_pipe_length":
        return f"{label} {value:.6g} m"
    return f"{label} {value / 1e3:.6g} kN"


def _limits(root: Path) -> dict:
    """The ``[select]`` limits of ``root/sweep.json``
    (:func:`.limits.check_limits`'); {} without the file or the table."""
    file = root / "sweep.json"
    spec = json.loads(file.read_text()) if file.is_file() else {}
    return check_limits("select", spec.get("select", {}))


def _selection(root: Path):
    """``root/selection.parquet`` as a DataFrame; None when absent."""
    file = root / "selection.parquet"
    return pd.read_parquet(file) if file.is_file() else None


def _chosen_text(selection, key: dict, column: str) -> str:
    """The text column ``column`` of the group ``key``'s selection row ("" when none)."""
    row = _row(selection, key, column)
    return "" if row is None else str(row[column].iloc[0])


def _row(selection, key: dict, column: str):
    """The selection rows of the group ``key`` (NaN keys match NaN), None
    without a selection, the column or a row."""
    if selection is None or column not in selection:
        return None
    match = np.ones(len(selection), dtype=bool)
    for name, value in key.items():
        values = selection[name]
        if isinstance(value, float) and math.isnan(value):
            match &= values.isna().to_numpy()
        else:
            match &= (values == value).to_numpy()
    row = selection[match]
    return None if row.empty else row


def _chosen(selection, key: dict, choice: str):
    """``select``'s choice ``choice`` (a column: ``a_equal_peaks``,
    ``stinger_radius_min_stress``, ...) of the group ``key`` (NaN keys match
    NaN); None when it has none."""
    row = _row(selection, key, choice)
    if row is None or not np.isfinite(row[choice].iloc[0]):
        return None
    return float(row[choice].iloc[0])

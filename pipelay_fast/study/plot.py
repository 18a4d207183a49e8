"""The figure of a sweep's results directory (matplotlib, the ``plot`` extra).

:func:`plot_sweep`: the overbend and sagbend peaks of von Mises stress
against ``a`` for each S-lay scene and current, the chosen ``a``
(``selection.parquet``, from ``select``) marked, as the paper's Figures 3,
5, 7 and 9; and, when a method was solved at several depths, the lay table
against depth (top tension, max utilisation).

Figures are built without pyplot (no display needed, nothing global changed);
``path`` writes them, the format from its suffix (PNG by default, SVG, PDF).
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pandas as pd

from ..output.plot import figure, save
from .dataset import read_summary
from .select import design_variable
from .sweep import AXES

__all__ = ["plot_sweep"]

# the columns that make one curve over a (as select's groups)
GROUP_KEYS = ("scene", "dimension", "current_speed", "current_heading_deg",
              "given_top_tension", "given_bottom_tension", "given_pipe_length")


def plot_sweep(root: str | os.PathLike, path: str | os.PathLike | None = None):
    """The figure of a sweep's results directory ``root``; written to ``path``
    when given. Returns the matplotlib Figure.

    One panel per S-lay scene, dimension, current and given tension whose
    cases span several values of a stinger design axis (``a``, or a roller
    stinger's ``stinger_radius`` or ``roller_shift``): overbend and sagbend
    peak von Mises stress against it, with ``select``'s equal-peaks and
    least-stress values (when ``selection.parquet`` holds them) as vertical
    lines; then, for each
    method solved at several water depths with one case per depth (a lay
    table), top tension and max utilisation against depth.

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
    for ax, (key, variable, g) in zip(axes, groups, strict=False):
        ax.plot(g[variable], g["overbend_max_von_mises"] / 1e6, "o-", color="C0",
                label="overbend")
        ax.plot(g[variable], g["sagbend_max_von_mises"] / 1e6, "s-", color="C1",
                label="sagbend")
        for what, style in (("equal_peaks", "--"), ("min_stress", ":")):
            chosen = _chosen(selection, key, f"{variable}_{what}")
            if chosen is not None:
                ax.axvline(chosen, color="C3", ls=style, lw=1.0,
                           label=f"{what.replace('_', ' ')} {variable} = {chosen:.6g}")
        given = [_given(name, key[name]) for name in GROUP_KEYS[4:] if np.isfinite(key[name])]
        ax.set(xlabel=f"{variable} [{AXES[variable][2]}]", ylabel="peak von Mises [MPa]",
               title=f"{key['scene']} {key['dimension']}, current {key['current_speed']:g} m/s "
                     f"at {key['current_heading_deg']:g} deg" + "".join(f", {t}" for t in given))
        ax.legend(fontsize="small")
        ax.grid(alpha=0.3)
    rest = axes[len(groups):]
    for i, (method, g) in enumerate(depth_groups):
        ax_t, ax_u = rest[2 * i], rest[2 * i + 1]
        ax_t.plot(g["water_depth"], g["top_tension"] / 1e3, "o-", color="C0")
        ax_t.set(xlabel="water depth [m]", ylabel="top tension [kN]",
                 title=f"{method}-lay table: top tension")
        ax_u.plot(g["water_depth"], g["max_utilisation"], "o-", color="C3")
        ax_u.axhline(1.0, color="k", lw=1.0, ls="--")
        ax_u.set(xlabel="water depth [m]", ylabel="max utilisation [-]",
                 title=f"{method}-lay table: max utilisation")
        for a in (ax_t, ax_u):
            a.grid(alpha=0.3)
    for ax in axes[panels:]:
        ax.set_visible(False)
    if path is not None:
        save(fig, path)
    return fig


def _given(name: str, value: float) -> str:
    """A panel's given tension [kN] or pipe length [m], for its title."""
    label = name.removeprefix("given_").replace("_", " ")
    if name == "given_pipe_length":
        return f"{label} {value:.6g} m"
    return f"{label} {value / 1e3:.6g} kN"


def _selection(root: Path):
    """``root/selection.parquet`` as a DataFrame; None when absent."""
    file = root / "selection.parquet"
    return pd.read_parquet(file) if file.is_file() else None


def _chosen(selection, key: dict, choice: str):
    """``select``'s choice ``choice`` (a column: ``a_equal_peaks``,
    ``stinger_radius_min_stress``, ...) of the group ``key`` (NaN keys match
    NaN); None when it has none."""
    if selection is None or choice not in selection:
        return None
    match = np.ones(len(selection), dtype=bool)
    for name, value in key.items():
        column = selection[name]
        if isinstance(value, float) and math.isnan(value):
            match &= column.isna().to_numpy()
        else:
            match &= (column == value).to_numpy()
    row = selection[match]
    if row.empty or not np.isfinite(row[choice].iloc[0]):
        return None
    return float(row[choice].iloc[0])

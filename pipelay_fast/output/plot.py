"""The figure of one solved case (matplotlib, the ``plot`` extra).

:func:`plot_result`: the elevation x-z with the seabed, the water line and
the stinger; the plan y-z (3D); moment, von Mises stress and utilisation (or
extreme-fibre strain without ``[checks]``) along the pipe. ``Result.plot()``
calls it. The sweep's figure is :mod:`pipelay_fast.study.plot`'s.

Figures are built without pyplot (no display needed, nothing global changed);
``path`` writes them, the format from its suffix (PNG by default, SVG, PDF).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .design import lcc_profile

__all__ = ["DPI", "PANEL_SIZE", "figure", "plot_result", "save"]

DPI = 100
PANEL_SIZE = (6.4, 3.0)  # in, width and height of one panel


def figure(rows: int, cols: int = 1):
    """An empty matplotlib Figure of ``rows`` x ``cols`` panels, each
    ``PANEL_SIZE`` [in] at ``DPI``, constrained layout. Raises ImportError
    without matplotlib (the ``plot`` extra)."""
    try:
        from matplotlib.figure import Figure
    except ImportError as err:  # pragma: no cover - the plot extra is missing
        raise ImportError("plots need matplotlib: pip install 'pipelay-fast[plot]'") from err
    width, height = PANEL_SIZE
    return Figure(figsize=(width * cols, height * rows), dpi=DPI, layout="constrained")


def save(fig, path: str | os.PathLike) -> Path:
    """Write ``fig`` to ``path``; the suffix picks the format (none: PNG)."""
    path = Path(path)
    if not path.suffix:
        path = path.with_suffix(".png")
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    return path


def plot_result(result, path: str | os.PathLike | None = None):
    """The figure of one solved case (a :class:`pipelay_fast.Result`); written
    to ``path`` when given. Returns the matplotlib Figure."""
    case, cols, sm = result.case, result.columns, result.summary
    three_d = sm["dimension"] == "3d"
    fig = figure(5 if three_d else 4)
    axes = fig.subplots(5 if three_d else 4, 1)
    s, x, z = cols["s"], cols["x"], cols["z"]
    ax = axes[0]
    ax.plot(z, x, color="C0", label="pipe")
    ax.axhline(0.0, color="saddlebrown", lw=1.0, label="seabed")
    ax.axhline(case.environment.water_depth, color="C9", lw=1.0, ls="--", label="water line")
    stinger = case.lay.stinger
    rollers = result.rollers
    if rollers is not None:  # bearing rollers filled, clear ones open
        on = rollers["in_contact"].to_numpy()
        ax.plot(rollers["z"][on], rollers["x"][on], "o", color="k", ms=4, label="roller, bearing")
        ax.plot(rollers["z"][~on], rollers["x"][~on], "o", color="k", ms=4, mfc="none",
                label="roller, clear")
    elif stinger is not None:
        zs = np.linspace(stinger.lower[1], stinger.upper[1], 101)
        ax.plot(zs, stinger.height(zs), color="k", lw=2.5, alpha=0.5, label="stinger")
    ax.plot([sm["tdp_z"]], [0.0], "v", color="C3", label="touchdown")
    ax.set(xlabel="z [m]", ylabel="x [m]",
           title=f"{case.name}: {sm['method']}-lay {sm['dimension']}, "
                 f"top tension {sm['top_tension'] / 1e3:.0f} kN, layback {sm['layback']:.1f} m")
    ax.legend(loc="upper left", fontsize="small")
    rest = axes[1:]
    if three_d:
        ax = rest[0]
        ax.plot(z, cols["y"], color="C0")
        ax.set(xlabel="z [m]", ylabel="y [m]", title="plan")
        rest = rest[1:]
    ax_m, ax_vm, ax_u = rest
    ax_m.plot(s, cols["moment"] / 1e3, color="C1")
    ax_m.set(xlabel="s [m]", ylabel="moment [kN m]")
    ax_vm.plot(s, cols["von_mises"] / 1e6, color="C2")
    ax_vm.axhline(case.pipe.smys / 1e6, color="C3", lw=1.0, ls="--", label="SMYS")
    ax_vm.set(xlabel="s [m]", ylabel="von Mises [MPa]")
    ax_vm.legend(loc="upper left", fontsize="small")
    _utilisation_panel(ax_u, case, cols, result.functional)
    for a in axes[1:]:
        a.grid(alpha=0.3)
    if path is not None:
        save(fig, path)
    return fig


def _utilisation_panel(ax, case, cols, functional):
    """Per-node overbend strain utilisation and load-controlled utilisation
    (with ``[checks]``), else the extreme-fibre strain [%]."""
    s = cols["s"]
    axial = np.abs(cols["axial_strain"]) if case.pipe.extensible else 0.0
    fibre = axial + cols["curvature"] * (0.5 * case.pipe.outer_diameter)
    checks = case.checks
    if checks is None:
        ax.plot(s, 100.0 * fibre, color="C4")
        ax.set(xlabel="s [m]", ylabel="strain [%]", title="extreme-fibre strain")
        return
    ax.plot(s, fibre / checks.overbend_strain_limit, color="C4", label="strain / limit")
    ax.plot(s, lcc_profile(case, cols, functional), color="C5",
            label="load-controlled (DNVGL-ST-F101)")
    ax.axhline(1.0, color="C3", lw=1.0, ls="--")
    ax.set(xlabel="s [m]", ylabel="utilisation [-]")
    ax.legend(loc="upper left", fontsize="small")

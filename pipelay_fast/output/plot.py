"""The figure of one solved case (matplotlib, the ``plot`` extra).

:func:`plot_result`: every panel against the arc length s from the lower end,
with touchdown, lift-off and the stinger's tip marked on each as vertical
lines (:func:`marks`): the elevation with the seabed (flat, the slope's
plane or the profile, at the pipe's z), its free spans shaded with their
lengths, the water line and the stinger, in the frame the case's lay is
given in (:func:`elevation_offset`); the lateral offset y (3D); the signed
in-plane moment; von Mises stress with the SMYS line; the utilisations where
the code checks apply them (:func:`pipelay_fast.output.design.utilisation_along`),
or the extreme-fibre strain without ``[checks]``. ``Result.plot()`` calls it. The sweep's figure
is :mod:`pipelay_fast.study.plot`'s.

Figures are built without pyplot (no display needed, nothing global changed);
``path`` writes them, the format from its suffix (PNG by default, SVG, PDF).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..input.surface import heights
from .design import bend_regions, fibre_strain, utilisation_along

__all__ = ["DPI", "PANEL_SIZE", "elevation_offset", "figure", "marks", "plot_result", "save"]

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


def marks(result) -> dict:
    """{"touchdown", "lift-off", "tip"}: the arc lengths s [m] of one solved
    case's touchdown, lift-off (S-lay) and stinger tip, None where it has
    none. Touchdown and lift-off are where the profile's z reaches the
    summary's ``tdp_z`` and ``liftoff_z`` (z rises with s, so the inverse of
    the interpolation that gave them: exact at a node); the tip is the
    stinger's lower end (a quadratic stinger's: where z reaches its z; a
    roller stinger's: its last roller's s)."""
    cols, sm, stinger = result.columns, result.summary, result.case.lay.stinger
    s, z = cols["s"], cols["z"]

    def at(z_value):
        return None if not np.isfinite(z_value) else float(np.interp(z_value, z, s))

    tip = None
    if result.rollers is not None:
        tip = float(result.rollers["s"].iloc[-1])
    elif stinger is not None:
        tip = at(stinger.lower[1])
    return {"touchdown": at(sm["tdp_z"]),
            "lift-off": at(sm["liftoff_z"]) if stinger is not None else None, "tip": tip}


MARK_STYLES = {"touchdown": ("C3", "-."), "lift-off": ("C2", "--"), "tip": ("k", ":")}


def plot_result(result, path: str | os.PathLike | None = None):
    """The figure of one solved case (a :class:`pipelay_fast.Result`); written
    to ``path`` when given. Returns the matplotlib Figure.

    Panels, each against s [m] (their x axes shared): elevation x; lateral
    offset y (3D); in-plane moment M_y (< 0 hogging, > 0 sagging); von Mises
    stress with the SMYS line; utilisations, or strain without ``[checks]``.
    Each panel's first line is the pipe's, over the profile's s; touchdown,
    lift-off and the tip (:func:`marks`) are vertical lines on every panel
    (labelled on the first), the tip's solid when the pipe bears on it."""
    case, cols, sm = result.case, result.columns, result.summary
    three_d = sm["dimension"] == "3d"
    rows = 5 if three_d else 4
    fig = figure(rows)
    axes = fig.subplots(rows, 1, sharex=True)
    s = cols["s"]
    at = marks(result)
    _elevation_panel(axes[0], result, at)
    rest = axes[1:]
    if three_d:
        rest[0].plot(s, cols["y"], color="C0")
        rest[0].set(ylabel="y [m]", title="lateral offset")
        rest = rest[1:]
    ax_m, ax_vm, ax_u = rest
    ax_m.plot(s, cols["moment_y"] / 1e3, color="C1")
    ax_m.axhline(0.0, color="k", lw=0.5)
    ax_m.set(ylabel="M_y [kN m]\n< 0 hogging, > 0 sagging", title="in-plane bending moment")
    smys = case.pipe.smys
    ax_vm.plot(s, cols["von_mises"] / 1e6, color="C2", label="von Mises")
    ax_vm.axhline(smys / 1e6, color="C3", lw=1.0, ls="--", label=f"SMYS {smys / 1e6:.0f} MPa")
    ax_vm.set(ylabel="von Mises [MPa]",
              title=f"von Mises stress: peak {sm['max_von_mises_over_smys']:.3f} SMYS"
                    + (", yielded" if sm["yielded"] else ""))
    ax_vm.legend(loc="upper left", fontsize="small")
    _utilisation_panel(ax_u, result, at["touchdown"], at["lift-off"])
    ax_u.set(xlabel="s [m] from the lower end")
    for i, ax in enumerate(axes):
        _mark(ax, at, bool(sm["bears_on_tip"]), label=i == 0)
        if i:
            ax.grid(alpha=0.3)
    axes[0].legend(loc="upper left", fontsize="small", ncols=2)
    if path is not None:
        save(fig, path)
    return fig


def _mark(ax, at: dict, bears: bool, label: bool):
    """Vertical lines at touchdown, lift-off and the tip (``at``, as
    :func:`marks` gives), labelled when ``label``; the tip's solid when the
    pipe ``bears`` on it."""
    for name, where in at.items():
        if where is None:
            continue
        color, style = MARK_STYLES[name]
        text = name
        if name == "tip" and bears:
            style, text = "-", "tip (pipe bears on it)"
        ax.axvline(where, color=color, ls=style, lw=1.0, label=text if label else None)


def elevation_offset(case) -> tuple[float, str]:
    """(offset [m], axis label) of the elevation panel in the frame ``case``'s
    lay is given in (``lay.frame``): the plotted elevation is x - offset, x
    the height above the reference seabed (where ``environment.water_depth``
    is measured). Waterline frame: the elevation about the still water
    (offset = water_depth, the water line at 0); seabed frame: x itself
    (offset 0, the water line at water_depth)."""
    if case.given_lay.frame == "waterline":
        return case.environment.water_depth, "elevation [m] above still water"
    return 0.0, "x [m] above the reference seabed"


def _elevation_panel(ax, result, at: dict):
    """The elevation against s in the case's frame (:func:`elevation_offset`),
    with the seabed under the pipe (its profile or slope, at the pipe's z),
    each free span shaded between the pipe and the seabed (a collection of
    gid "span" per row of ``result.spans``) and labelled with its length, the
    water line, the stinger (a quadratic one at the pipe's s over it; rollers
    at the s of the material point over each) and the tip bearing's
    reaction."""
    case, cols, sm = result.case, result.columns, result.summary
    s = cols["s"]
    offset, label = elevation_offset(case)
    pipe = cols["x"] - offset
    bed = heights(case.seabed, case.environment.water_depth, cols["z"]) - offset
    ax.plot(s, pipe, color="C0", label="pipe")
    ax.plot(s, bed, color="saddlebrown", lw=1.0, label="seabed")
    spans = result.spans
    for k, (s0, s1, length) in enumerate(zip(spans["start_s"], spans["end_s"], spans["length"],
                                             strict=True)):
        on = (s >= s0) & (s <= s1)
        ax.fill_between(s[on], bed[on], pipe[on], color="C1", alpha=0.35, lw=0,
                        label="free span" if k == 0 else None, gid="span")
        top = float(pipe[on].max()) if on.any() else float(np.interp(s0, s, pipe))
        ax.annotate(f"{length:.1f} m", (0.5 * (s0 + s1), top), xytext=(0, 3),
                    textcoords="offset points", ha="center", va="bottom", fontsize="x-small",
                    color="C1", gid="span length")
    ax.axhline(case.environment.water_depth - offset, color="C9", lw=1.0, ls="--",
               label="water line")
    stinger, rollers = case.lay.stinger, result.rollers
    if rollers is not None:  # bearing rollers filled, clear ones open
        on = rollers["in_contact"].to_numpy()
        rx = rollers["x"].to_numpy() - offset
        ax.plot(rollers["s"][on], rx[on], "o", color="k", ms=4, label="roller, bearing")
        ax.plot(rollers["s"][~on], rx[~on], "o", color="k", ms=4, mfc="none",
                label="roller, clear")
    elif stinger is not None:
        zs = np.linspace(stinger.lower[1], stinger.upper[1], 101)
        ax.plot(np.interp(zs, cols["z"], s), stinger.height(zs) - offset, color="k", lw=2.5,
                alpha=0.5, label="stinger")
    if sm["bears_on_tip"] and at["tip"] is not None:  # a roller stinger's tip: its last roller
        reaction = (sm["tip_reaction"] if rollers is None
                    else float(rollers["reaction"].iloc[-1]))
        ax.plot([at["tip"]], [np.interp(at["tip"], s, pipe)], "*", color="C3", ms=10,
                label=f"bears on tip, {reaction / 1e3:.0f} kN")
    ax.set(ylabel=label,
           title=f"{case.name}: {sm['method']}-lay {sm['dimension']}, "
                 f"top tension {sm['top_tension'] / 1e3:.0f} kN, layback {sm['layback']:.1f} m")


def _utilisation_panel(ax, result, s_tdp: float, s_liftoff: float | None):
    """The utilisations where the code checks apply them
    (:func:`pipelay_fast.output.design.utilisation_along`: the overbend
    strain over its limit on the overbend, the load-controlled criterion on
    the sagbend) and the line at 1; without ``[checks]`` the extreme-fibre
    strain [%]."""
    case, cols = result.case, result.columns
    s = cols["s"]
    checks = case.checks
    if checks is None:
        ax.plot(s, 100.0 * fibre_strain(case.pipe, cols), color="C4")
        ax.set(ylabel="strain [%]", title="extreme-fibre strain")
        return
    hog, sag = bend_regions(cols, s_tdp, s_liftoff, case.lay.stinger is not None)
    over, sagbend = utilisation_along(case, cols, s_tdp, hog, sag, result.functional)
    ax.plot(s, sagbend, color="C5", label="sagbend: load-controlled (DNV-ST-F101)")
    ax.plot(s, over, color="C4",
            label=f"overbend: strain / {100 * checks.overbend_strain_limit:.3g} %")
    ax.axhline(1.0, color="C3", lw=1.0, ls="--")
    ax.set(ylabel="utilisation [-]",
           title=f"utilisation: max {result.summary['max_utilisation']:.3f}")
    ax.legend(loc="upper left", fontsize="small")

"""Lay design answers of one solved case: the summary columns a lay tool reports.

Layback, tip clearance, departure angle and touchdown tension come from the
profile; peak strains and utilisations from the profile and the code checks of
:mod:`pipelay_fast.input.checks` (NaN without a ``[checks]`` table).
"""

from __future__ import annotations

import math

import numpy as np

from ..input.checks import design_load_effects, lcc_axial_ratio, lcc_utilisation
from ..kernels.geometry import point_clearance

__all__ = ["DESIGN_UNITS", "bend_regions", "design_columns", "fibre_strain", "functional_effects",
           "interior_peak", "lcc_sections", "tip_clearance", "utilisation_along"]

DESIGN_UNITS = {
    "layback": "m", "tip_clearance": "m", "departure_angle_deg": "deg", "tdp_tension": "N",
    "overbend_max_strain": "-", "sagbend_max_strain": "-",
    "overbend_strain_utilisation": "-", "sagbend_lcc_utilisation": "-",
    "sagbend_lcc_axial_ratio": "-", "max_utilisation": "-",
}


SAMPLES = 33  # per element, where the foot of the normal is sought from


def interior_peak(values) -> float:
    """Largest interior local maximum (the sagbend peak), ignoring a peak that sits
    at an end of the span (a clamped top's moment); the plain maximum if none."""
    v = np.asarray(values, dtype=float)
    if v.size < 3:
        return float(v.max())
    inner = (v[1:-1] >= v[:-2]) & (v[1:-1] >= v[2:])
    return float(v[1:-1][inner].max()) if inner.any() else float(v.max())


def bend_regions(cols: dict, s_tdp: float, s_liftoff: float | None, stinger: bool):
    """(overbend, sagbend): boolean masks of the nodes of each region of the
    profile ``cols`` with touchdown at ``s_tdp`` and lift-off at
    ``s_liftoff`` [m] (None: the top). Above touchdown the hogging nodes
    (in-plane moment ``moment_y`` < 0) are the overbend, the others up to
    lift-off the sagbend. Without a stinger (J-lay): (None, None), the span
    above touchdown having no overbend and its sagbend peak being
    :func:`interior_peak`'s."""
    if not stinger:
        return None, None
    s = cols["s"]
    beyond = s >= s_tdp
    hog = beyond & (cols["moment_y"] < 0.0)
    sag = beyond & ~hog & (s <= (s_liftoff if s_liftoff is not None else s[-1]))
    return hog, sag


def fibre_strain(pipe, cols: dict) -> np.ndarray:
    """Extreme-fibre strain [-] of every section: |axial strain| (an
    extensible pipe's) plus the bending strain kappa D/2."""
    axial = np.abs(cols["axial_strain"]) if pipe.extensible else 0.0
    return axial + cols["curvature"] * (0.5 * pipe.outer_diameter)


def utilisation_along(case, cols: dict, s_tdp: float, overbend, sagbend,
                      functional: dict | None = None):
    """(overbend [-], sagbend [-]): the utilisations of every section of the
    profile ``cols`` where :func:`design_columns` checks them, NaN elsewhere
    (masks as :func:`bend_regions` gives them). Overbend: the extreme-fibre
    strain over ``checks.overbend_strain_limit`` on the ``overbend`` nodes;
    sagbend: the load-controlled utilisation (:func:`lcc_sections`) on the
    ``sagbend`` nodes, or without a stinger (``sagbend`` None) above
    touchdown less the rise to an end above :func:`interior_peak` (a
    clamped top's). Their largest value is ``max_utilisation``. Both all
    NaN without ``[checks]``."""
    over, sag, _axial = _utilisations(case, cols, s_tdp, overbend, sagbend, functional)
    return over, sag


def _utilisations(case, cols: dict, s_tdp: float, overbend, sagbend, functional):
    """:func:`utilisation_along`'s two profiles and the load-controlled
    check's axial ratio of every section (:func:`lcc_sections`; all NaN
    without ``[checks]``)."""
    s, checks = cols["s"], case.checks
    over = np.full(s.size, math.nan)
    sag = over.copy()
    if checks is None:
        return over, sag, over.copy()
    if overbend is not None:
        strain = fibre_strain(case.pipe, cols) / checks.overbend_strain_limit
        over[overbend] = strain[overbend]
    lcc, axial = lcc_sections(case, cols, functional)
    if sagbend is None:
        behind = s >= s_tdp
        sag[behind] = lcc[behind]
        if behind.any():
            sag[sag > interior_peak(lcc[behind])] = math.nan  # (NaN compares False)
    else:
        sag[sagbend] = lcc[sagbend]
    return over, sag, axial


def _peak(values) -> float:
    """The largest finite value of ``values``; NaN when none is finite."""
    v = np.asarray(values)
    finite = np.isfinite(v)
    return float(v[finite].max()) if finite.any() else math.nan


def tip_clearance(r, rp, s, tip, up) -> float:
    """Distance [m] from the point ``tip`` to the pipe's centreline, signed by
    the side of ``up`` (the stinger's outward normal there) it lies on.

    The centreline is each element's cubic Hermite. The nearest point is
    sought on the four elements around the node nearest the tip, all at
    once: each sampled at SAMPLES points, then refined between the neighbours of
    its nearest sample by Newton (guarded by bisection, to round-off) on the
    foot-of-normal condition (r - tip) . dr/dxi = 0, so the distance is
    normal to the pipe (or at an end of the element, where the distance
    falls towards it); the nearest of the refined points is the answer
    (:func:`pipelay_fast.kernels.geometry.point_clearance`). ``r`` [m],
    ``rp`` [-]: nodal positions and slopes (nn, nd); ``s`` [m]: the nodes'
    arc lengths; ``tip`` [m], ``up`` [-]: vectors of nd.
    """
    r, rp, s = (np.ascontiguousarray(v, dtype=float) for v in (r, rp, s))
    nd = r.shape[1]
    return float(point_clearance(r, rp, s, np.asarray(tip, dtype=float),
                                 np.asarray(up, dtype=float), SAMPLES,
                                 np.empty(nd), np.empty(nd), np.empty(nd)))


def _moment_vectors(cols: dict) -> np.ndarray:
    """The moment vectors of a profile (with a torque, it is in them: its
    check is then on the moment's magnitude with the torque, conservative)."""
    return np.stack([cols["moment_x"], cols["moment_y"], cols["moment_z"]], axis=1)


def functional_effects(cols: dict, still: dict):
    """(moment vectors [N m], effective tensions [N]) of the functional load
    case (weight and tension: the case without its current, whose profile
    columns are ``still``) at the sections of the profile ``cols``, matched
    by unstretched length from the top (the top is the same point in both)."""
    down, still_down = cols["s"][-1] - cols["s"], still["s"][-1] - still["s"]
    order = np.argsort(still_down)
    moment = np.stack([np.interp(down, still_down[order], m[order])
                       for m in _moment_vectors(still).T], axis=1)
    tension = np.interp(down, still_down[order], still["effective_tension"][order])
    return moment, tension


def lcc_sections(case, cols: dict, functional: dict | None = None):
    """(utilisation [-], |S_Sd|/S_p [-]) of every section of the profile
    ``cols``, with ``functional`` the profile columns of the case's
    functional load case (:meth:`pipelay_fast.input.checks.Checks.splits_current`:
    required when it splits the current off, ignored otherwise): the load-controlled criterion
    (:func:`pipelay_fast.input.checks.lcc_utilisation`) of the design load
    effects under the load effect factor combination giving the larger
    utilisation there (:attr:`pipelay_fast.input.checks.Checks.load_combinations`),
    and that combination's axial ratio
    (:func:`pipelay_fast.input.checks.lcc_axial_ratio`); NaN without
    ``[checks]``. Raises ValueError when the check splits the current off
    and ``functional`` is None."""
    checks = case.checks
    if checks is None:
        nan = np.full(cols["s"].size, math.nan)
        return nan, nan.copy()
    if checks.splits_current(case):
        if functional is None:
            raise ValueError(f"case {case.name!r}: its load-controlled check splits the current "
                             "off (checks.current_load = 'environmental') and needs the "
                             "functional load case's profile")
        functional = functional_effects(cols, functional)
    else:
        functional = None
    moments, tension = _moment_vectors(cols), cols["effective_tension"]
    p_e, p_i = case.external_pressure(cols["x"]), case.internal_pressure(cols["x"])
    gamma = np.array(checks.load_combinations, dtype=float)  # (combinations, 2): all at once
    m_sd, s_sd = design_load_effects(checks, (gamma[:, :1], gamma[:, 1:]), moments, tension,
                                     functional)
    utilisation = lcc_utilisation(case.pipe, checks, m_sd, s_sd, p_e, p_i)
    ratio = lcc_axial_ratio(case.pipe, checks, s_sd)
    governing = np.argmax(utilisation, axis=0)
    at = np.arange(cols["s"].size)
    return utilisation[governing, at], ratio[governing, at]


def design_columns(case, cols: dict, r, rp, s_tdp: float, overbend, sagbend,
                   bearing: bool, departure_angle: float,
                   roller_clearance: float | None = None, functional: dict | None = None) -> dict:
    """The columns of ``DESIGN_UNITS`` of a solved case.

    ``cols``: the profile columns; ``r``, ``rp``: nodal position and slope in
    the solve's dimension [m, -]; ``overbend``, ``sagbend``: boolean masks of
    the nodes of each region (``sagbend`` None: the J-lay span above
    touchdown, whose peak is its interior maximum); ``bearing``: the pipe
    bears on the stinger's tip; ``departure_angle``: the angle where the
    pipe leaves the stinger (S-lay) or the vessel (J-lay) [deg];
    ``roller_clearance``: a roller stinger's clearance at its last roller
    [m], its ``tip_clearance``; ``functional``: the functional load case's
    profile columns (:func:`lcc_sections`).
    """
    s = cols["s"]
    pipe, checks, stinger = case.pipe, case.checks, case.lay.stinger
    at_tdp = {name: float(np.interp(s_tdp, s, cols[name])) for name in ("y", "z",
                                                                         "effective_tension")}
    layback = math.hypot(cols["z"][-1] - at_tdp["z"], cols["y"][-1] - at_tdp["y"])
    if stinger is None:
        clearance = math.nan
    elif roller_clearance is not None:  # a roller stinger's: its last roller's
        clearance = roller_clearance
    elif bearing:
        clearance = 0.0
    else:
        x_l, z_l = stinger.lower
        slope = float(stinger.slope(z_l))
        up2 = np.array([1.0, -slope]) / math.hypot(1.0, slope)  # (x, z) normal, upwards
        nd = r.shape[1]
        tip = np.array([x_l, z_l]) if nd == 2 else np.array([x_l, 0.0, z_l])
        up = up2 if nd == 2 else np.array([up2[0], 0.0, up2[1]])
        clearance = tip_clearance(r, rp, s, tip, up)
    fibre = fibre_strain(pipe, cols)
    nan = math.nan
    behind = s >= s_tdp
    over_strain = float(fibre[overbend].max()) if overbend is not None and overbend.any() else nan
    if sagbend is None:
        sag_strain = interior_peak(fibre[behind])
    else:
        sag_strain = float(fibre[sagbend].max()) if sagbend.any() else nan
    over_u = sag_u = sag_axial = nan
    if checks is not None:
        # the peaks of the profiles the figure draws (utilisation_along)
        over, sag, lcc_axial = _utilisations(case, cols, s_tdp, overbend, sagbend, functional)
        over_u, sag_u = _peak(over), _peak(sag)
        if sag_u > 0.0:
            sag_axial = float(lcc_axial[np.argmax(sag == sag_u)])
    values = [u for u in (over_u, sag_u) if not math.isnan(u)]
    return {
        "layback": float(layback),
        "tip_clearance": float(clearance),
        "departure_angle_deg": float(departure_angle),
        "tdp_tension": at_tdp["effective_tension"],
        "overbend_max_strain": over_strain,
        "sagbend_max_strain": sag_strain,
        "overbend_strain_utilisation": over_u,
        "sagbend_lcc_utilisation": sag_u,
        "sagbend_lcc_axial_ratio": sag_axial,
        "max_utilisation": max(values) if values else nan,
    }

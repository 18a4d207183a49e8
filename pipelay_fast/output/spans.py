"""Free spans: the stretches of pipe behind touchdown that the seabed does
not carry, between two stretches that it does.

A node rests on the seabed when its clearance ``gap`` [m] (the pipe's axis
height above the seabed under it, less nothing: the engine's x is the axis)
is not positive: on a rigid seabed the contact holds it at 0, on an elastic
one the foundation pushes where the pipe has sunk (gap < 0). A span runs
from the last node resting before it to the first resting after it; its ends
lie where the clearance, linear between the two nodes on each side, is 0.
The suspended pipe from touchdown up to the vessel rests on nothing above
it, so it is not a span.

Units: arc length ``s`` and ``z`` [m], clearance [m].
"""

from __future__ import annotations

import numpy as np

from ..engine.state import interpolate_state
from ..input.surface import heights

SPAN_UNITS = {
    "span": "-",
    "start_s": "m", "end_s": "m", "length": "m",
    "start_z": "m", "end_z": "m",
    "max_gap": "m", "max_gap_s": "m", "max_gap_z": "m",
}
"""The span table's columns: its number from the lower end (0, 1, ...), the
arc lengths and z of its ends (the clearance's zeros), its length along the
pipe, its largest clearance and where it is."""


def _crossing(s, gap, k: int) -> float:
    """Where the clearance, linear between nodes k and k + 1 of opposite
    sides of 0 (one resting, gap <= 0, the other free, gap > 0), is 0."""
    g0, g1 = gap[k], gap[k + 1]
    return float(s[k] + (s[k + 1] - s[k]) * (0.0 - g0) / (g1 - g0))


def find_spans(s, z, gap) -> dict:
    """The free spans of a pipe with nodes at arc length ``s`` (ascending from
    the lower end), horizontal position ``z`` and clearance ``gap`` above the
    seabed (each (nn,) [m]): the columns of ``SPAN_UNITS`` as numpy arrays,
    one entry per span, lower end first (empty arrays: no span).

    The largest clearance is the largest nodal one in the span (a node's
    value: on the mesh that carries the answer, not an interpolant's)."""
    s = np.asarray(s, dtype=float)
    z = np.asarray(z, dtype=float)
    gap = np.asarray(gap, dtype=float)
    if not (s.shape == z.shape == gap.shape and s.ndim == 1):
        raise ValueError(f"find_spans: s, z and gap must be 1D arrays of one length, "
                         f"got shapes {s.shape}, {z.shape}, {gap.shape}")
    rest = np.flatnonzero(gap <= 0.0)
    rows = {name: [] for name in SPAN_UNITS}
    for a, b in zip(rest[:-1], rest[1:], strict=True):
        if b == a + 1:  # resting on both nodes: no free pipe between
            continue
        s0 = _crossing(s, gap, a)
        s1 = _crossing(s, gap, b - 1)
        k = a + 1 + int(np.argmax(gap[a + 1:b]))
        rows["span"].append(len(rows["span"]))
        rows["start_s"].append(s0)
        rows["end_s"].append(s1)
        rows["length"].append(s1 - s0)
        rows["start_z"].append(float(np.interp(s0, s, z)))
        rows["end_z"].append(float(np.interp(s1, s, z)))
        rows["max_gap"].append(float(gap[k]))
        rows["max_gap_s"].append(float(s[k]))
        rows["max_gap_z"].append(float(z[k]))
    return {name: np.asarray(v, dtype=np.int64 if name == "span" else float)
            for name, v in rows.items()}


def span_summary(spans: dict) -> dict:
    """The summary's span columns of a span table (:func:`find_spans`):
    ``n_spans`` [-], ``max_span_length`` and ``max_span_gap`` [m] (0.0 when
    there is no span: the longest free stretch has no length)."""
    n = int(spans["length"].size)
    return {
        "n_spans": n,
        "max_span_length": float(spans["length"].max()) if n else 0.0,
        "max_span_gap": float(spans["max_gap"].max()) if n else 0.0,
    }


SUBDIVISIONS = 8
"""The points per element at which :func:`laid_spans` evaluates the laid
pipe's clearance (its Hermite interpolant), so that a span's ends and its
largest gap are the element's, not a straight line's between its nodes."""


def laid_spans(s, u, nd: int, heights, s_td: float) -> dict:
    """The free spans (:func:`find_spans`) of the pipe with unknowns ``u`` on
    nodes ``s`` [m] in dimension ``nd`` behind its touchdown at arc length
    ``s_td`` [m], over the seabed whose height x_b [m] at z [m] (an array)
    is ``heights(z)`` (:func:`pipelay_fast.input.surface.heights`): its clearance x - x_b(z)
    at SUBDIVISIONS points per element of the cubic
    Hermite interpolant of its nodal positions and tangents."""
    s = np.asarray(s, dtype=float)
    if s_td <= s[0]:
        return find_spans(np.zeros(0), np.zeros(0), np.zeros(0))
    last = int(np.searchsorted(s, s_td))
    nodes = np.append(s[:last][s[:last] < s_td], s_td)
    steps = np.arange(SUBDIVISIONS) / SUBDIVISIONS
    fine = np.append((nodes[:-1, None] + np.diff(nodes)[:, None] * steps).ravel(), s_td)
    uf = interpolate_state(s, u, nd, fine)
    ndn = 2 * nd + 1
    x, z = uf[0::ndn], uf[nd - 1::ndn]
    return find_spans(fine, z, x - heights(z))


TOUCHDOWN_UNITS = {"tdp_x": "m", "seabed_depth_at_tdp": "m", "n_spans": "-",
                   "max_span_length": "m", "max_span_gap": "m"}
"""The summary's touchdown and span columns (:func:`touchdown_columns`)."""


def span_table(case, sol) -> dict:
    """The free spans behind touchdown (:func:`laid_spans`) of the solution
    ``sol`` of ``case``: the columns of ``SPAN_UNITS``; none on a rigid
    seabed (the contact holds the laid pipe on it from its lower end to
    touchdown)."""
    if case.seabed.is_rigid:
        return find_spans(np.zeros(0), np.zeros(0), np.zeros(0))
    depth = case.environment.water_depth
    return laid_spans(sol.s, sol.u, sol.nd, lambda z: heights(case.seabed, depth, z), sol.s_tdp)


def touchdown_columns(case, sol, cols: dict, spans: dict) -> dict:
    """The columns of ``TOUCHDOWN_UNITS``: touchdown's height [m] above the
    reference level (where ``environment.water_depth`` is measured; on an
    elastic seabed the pipe's axis where it leaves the foundation), the
    water depth under it [m] and :func:`span_summary` of ``spans``."""
    s = cols["s"]
    z_tdp = float(np.interp(sol.s_tdp, s, cols["z"]))
    depth = case.environment.water_depth
    return {"tdp_x": float(np.interp(sol.s_tdp, s, cols["x"])),
            "seabed_depth_at_tdp": depth - float(heights(case.seabed, depth, np.array([z_tdp]))[0]),
            **span_summary(spans)}

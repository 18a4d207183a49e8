"""The first guess's pipe near the seabed profile: a tensioned beam on the
elastic foundation, small slopes, by finite differences (engine layer).

The laid pipe follows the profile's features only where its bending
stiffness and tension let it: it bridges a trench and spans down from a
hump. Started on the profile itself, Newton has to find those spans through
the foundation's kink; started here, it starts near them. The beam runs
from the lower end, a free end pulled by the tension (no moment, no shear:
the model's), through touchdown to a point of the suspended span, where it
takes the catenary guess's height and slope: touchdown itself then lands
where the profile lets it (on a hump's flank, over a trench), not where the
flat seabed's catenary put it. It is the minimum of the discrete energy,
on a uniform grid of spacing d along z, with w the pipe's height,

    sum EI/2 (w'')^2 d + sum H/2 (w')^2 d + sum (k a/2 (w - x_b)^2 + w_s w) d,

w'' the second differences at interior points, w' the first on each
interval, a = 1 where w < x_b (else 0): the contact set by fixed point
(active set) from all in contact, until the set repeats (settled, or a cycle).

Where the seabed under touchdown is not at the reference level (a slope, a
profile), the suspended span's catenary touches down at the seabed's
height there, which depends on where it touches down: a fixed point
(:func:`on_seabed`; :func:`seabed_span` for a J-lay).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import solve_banded

from ..input.case import Case
from ..input.profile import bed_heights
from .catenary import Catenary, from_top_tension
from .supports import seabed_height


def laid_on_foundation(knots, z0: float, z1: float, x1: float, slope1: float, ei: float,
                       h: float, ws: float, k: float, z_at) -> tuple[np.ndarray, np.ndarray]:
    """(height x [m], slope angle [rad]) at ``z_at`` [m] (within [z0, z1]) of
    the pipe from its free lower end at ``z0`` to ``z1`` [m], where its
    height is ``x1`` [m] and its slope ``slope1`` [-] (module docstring),
    with bending stiffness ``ei`` [N m2], tension ``h`` [N], submerged weight
    ``ws`` [N/m] on the foundation of stiffness ``k`` [N/m per m] over the
    profile with ``knots``."""
    lf = (4.0 * ei / k) ** 0.25
    # (no cap: the pipe's elements on a profile are at most one lf long,
    # :func:`.problem._mesh_sizes`, so n is at most 4 per mesh element, a
    # banded solve cheaper than one Newton iteration; at least the stencil's
    # 3 intervals: two fixed nodes at z1 and a second difference)
    n = int(max(3, np.ceil((z1 - z0) / (0.25 * lf))))
    z = np.linspace(z0, z1, n + 1)
    d = z[1] - z[0]
    xb = bed_heights(knots, z)[0]
    # the energy's matrix, banded (band[2 + i - j, j] = A[i, j]): EI d D2'D2 + H d D1'D1
    band = np.zeros((5, n + 1))
    for coef, stencil in ((ei / d**3, (1.0, -2.0, 1.0)), (h / d, (-1.0, 1.0))):
        rows = n + 1 - len(stencil) + 1  # the differences taken
        for a, ca in enumerate(stencil):
            for b, cb in enumerate(stencil):
                band[2 + a - b, b:b + rows] += coef * ca * cb
    weight = np.full(n + 1, d)
    weight[[0, -1]] *= 0.5
    # w_n = x1, w_(n-1) = x1 - d slope1: the free unknowns are w_0 .. w_(n-2)
    fixed = np.array([x1 - d * slope1, x1])
    m = n - 1
    coupling = np.zeros(m)
    for j in (m, n):
        for i in (j - 2, j - 1):
            if i < m:
                coupling[i] += band[2 + i - j, j] * fixed[j - m]
    band = band[:, :m].copy()
    band[3, m - 1] = band[4, m - 2:] = 0.0  # (rows past the free block)
    main = band[2].copy()
    active = np.ones(n + 1, dtype=bool)
    w = np.empty(n + 1)
    w[m:] = fixed
    seen = set()
    while True:  # active-set sweeps, until the set repeats (settled, or a cycle)
        ka = k * weight * active
        band[2] = main + ka[:m]
        w[:m] = solve_banded((2, 2), band, ka[:m] * xb[:m] - ws * weight[:m] - coupling)
        now = w < xb
        if np.array_equal(now, active) or now.tobytes() in seen:
            break
        seen.add(active.tobytes())
        active = now
    return np.interp(z_at, z, w), np.arctan(np.interp(z_at, z, np.gradient(w, d)))


def on_seabed(start: float, first, under, enough: float):
    """(x, payload): touchdown's height x [m] on a sloped seabed or a
    profile, where
    ``under(x)`` = (the seabed's height [m] under the touchdown of the
    catenary that touches down at height x, that catenary's payload) meets
    x. Secant steps on r(x) = under(x)[0] - x from ``start`` (``first`` its
    ``under``) while |r| shrinks, until it is below ``enough`` [m] (r is
    nearly linear: a few steps). The guess's own error sets ``enough``:
    touchdown is a flexural length sqrt(EI/h) off along the seabed
    (:mod:`.guess`), its height that times the seabed's slope there."""
    xa = start
    ya, pa = first
    ra = ya - xa
    xb = ya
    yb, pb = under(xb)
    rb = yb - xb
    while enough <= abs(rb) < abs(ra):
        xc = xb - rb * (xb - xa) / (rb - ra)
        yc, pc = under(xc)
        xa, ra, pa = xb, rb, pb
        xb, rb, pb = xc, yc - xc, pc
    return (xb, pb) if abs(rb) <= abs(ra) else (xa, pa)


def seabed_span(case: Case, flat: Catenary, knots: np.ndarray):
    """(the J-lay catenary from ``lay.top_tension`` touching down on the
    seabed's surface, touchdown's height x [m] there), from the level
    seabed's ``flat``: touchdown's z depends on the span's height above the
    reference level, so its height is the surface's under the catenary that
    starts there (:func:`on_seabed`), to within the surface's slope there
    times the flexural length sqrt(EI/h) (the guess's error along the
    seabed). The surface is data: on a slope the plane
    (:func:`.supports.seabed_height`), the catenary touching down tangent
    to it; over a profile the profile's ``knots``
    (:func:`..input.profile.bed_knots`), the catenary touching down level."""
    lay = case.lay
    x_top, z_top = lay.top
    depth = case.environment.water_depth
    if case.seabed.profile is not None:
        tan0 = 0.0

        def surface(z):
            x, slope = bed_heights(knots, np.array([z]))
            return float(x[0]), float(slope[0])
    else:
        tan0 = math.tan(case.seabed.slope)

        def surface(z):
            return float(seabed_height(case, z)), tan0

    def under(x_td):
        cat = from_top_tension(lay.top_tension, flat.w1, flat.w2, depth - x_td, x_top - x_td,
                               tan0)
        return surface(z_top - cat.span)[0], cat

    start, slope = surface(z_top - flat.span)
    enough = abs(slope) * math.sqrt(case.pipe.bending_stiffness / flat.h)
    x_td, cat = on_seabed(start, under(start), under, enough)
    return cat, x_td

"""The first guess's laid pipe on a seabed profile: a tensioned beam on the
elastic foundation, small slopes, by finite differences (engine layer).

The laid pipe follows the profile's features only where its bending
stiffness and tension let it: it bridges a trench and spans down from a
hump. Started on the profile itself, Newton has to find those spans through
the foundation's kink; started here, it starts near them. On a uniform grid
of spacing d along z, with w the pipe's height,

    EI w'''' - H w'' + k a (w - x_b) = -w_s,   a = 1 where w < x_b, else 0,

the contact set ``a`` by fixed point (active set) from all in contact; both
ends at rest on the seabed (w = x_b - w_s/k, w' = 0).
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import solve_banded

from ..input.profile import bed_heights

MAX_SWEEPS = 50  # active-set sweeps (it settles in a few on the tests' profiles)


def laid_on_foundation(knots, z0: float, z1: float, ei: float, h: float, ws: float, k: float,
                       z_at) -> tuple[np.ndarray, np.ndarray]:
    """(height x [m], slope angle [rad]) at ``z_at`` [m] of the laid pipe from
    ``z0`` to ``z1`` [m] (module docstring) with bending stiffness ``ei`` [N
    m2], tension ``h`` [N], submerged weight ``ws`` [N/m] on the foundation
    of stiffness ``k`` [N/m per m] over the profile with ``knots``."""
    lf = (4.0 * ei / k) ** 0.25
    n = int(min(4000, max(16, np.ceil((z1 - z0) / (0.25 * lf)))))
    z = np.linspace(z0, z1, n + 1)
    d = z[1] - z[0]
    xb = bed_heights(knots, z)[0]
    rest = xb - ws / k
    c4, c2 = ei / d**4, h / d**2
    active = np.ones(n + 1, dtype=bool)
    w = rest.copy()
    for _ in range(MAX_SWEEPS):
        ab = np.zeros((5, n + 1))
        rhs = -ws + k * active * xb
        ab[2] = 6.0 * c4 + 2.0 * c2 + k * active
        ab[1, 1:] = ab[3, :-1] = -4.0 * c4 - c2
        ab[0, 2:] = ab[4, :-2] = c4
        for i in (0, 1, n - 1, n):  # w = rest at both ends, and at their neighbours (w' = 0)
            for band in range(5):
                col = i + 2 - band
                if 0 <= col <= n:
                    ab[band, col] = 0.0
            ab[2, i] = 1.0
            rhs[i] = rest[0] if i < 2 else rest[-1]
        # (rows i of the banded storage: ab[2 + i - j, j] = A[i, j]; zeroed above)
        w = solve_banded((2, 2), ab, rhs)
        now = w < xb
        if np.array_equal(now, active):
            break
        active = now
    return np.interp(z_at, z, w), np.arctan(np.interp(z_at, z, np.gradient(w, d)))

"""The seabed profile's depth, independently of the engine: scipy's PCHIP
through a ``seabed.profile`` table, held at its ends."""

from __future__ import annotations

import numpy as np
from scipy.interpolate import PchipInterpolator


def profile_depth(rows, z) -> np.ndarray:
    """The water depth [m] at ``z`` [m] (any shape) of a ``seabed.profile``
    table ``rows`` ([z, depth] pairs, z increasing): scipy's PCHIP through
    them, level beyond the table's ends. (Its end slopes are the engine's,
    zero, where the table's end rows are level.)"""
    table = np.asarray(rows, dtype=float)
    pchip = PchipInterpolator(table[:, 0], table[:, 1])
    return pchip(np.clip(z, table[0, 0], table[-1, 0]))

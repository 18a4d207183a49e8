"""The paper's pipe (Table 1) and E, which the paper does not state (207 GPa, as
in ``pipelay_fast/examples/``), computed here by hand for the reference solutions
and their tests (SI units)."""

from __future__ import annotations

import math

G, RHO_W = 9.81, 1025.0  # [m/s2], [kg/m3]
DO, DI, DC = 0.61, 0.58, 0.71  # steel outer, inner, coating outer diameter [m]
A_STEEL = math.pi * (DO**2 - DI**2) / 4  # [m2]
A_COAT = math.pi * (DC**2 - DO**2) / 4  # [m2]
W_DRY = G * (7900.0 * A_STEEL + 3000.0 * A_COAT)  # [N/m] ~ 5224
W_SUB = W_DRY - RHO_W * G * math.pi * DC**2 / 4  # [N/m] ~ 1243
EI = 207e9 * math.pi * (DO**4 - DI**4) / 64  # [N m^2] ~ 2.570e8

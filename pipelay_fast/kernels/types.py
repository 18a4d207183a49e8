"""The named tuples of arrays the kernels take, one per concern.

A kernel's inputs are grouped by what they describe instead of passed as a
long positional list. Each field is a float64 array (int8 for masks, int64
for node indices) or a scalar; numba compiles one specialisation per tuple
type, and the tuples are rebuilt by the Python layer for every call (cheap:
they hold references, not copies).

* :data:`Model`: what an element reads, the case's data (the scene's
  ``props``, the current ``table``), the load path's ``factors``
  (:mod:`.layout`, ``F_*``) and the pipe's ``section``, a row per element
  ((n_elements, N_SECTION), layout ``S_*``) and the seabed profile's knots
  ``bed`` ((n, 3): z [m], height x [m], dx/dz [-], :mod:`.bed`; (0, 3), the
  default: none).
* :data:`Mesh`: the element lengths and the mesh's map onto the contact
  boundaries (node i at s_a[i] + sum_b s_b[b, i] s_bd[b]; ``bnodes[b]`` the
  node on boundary b, -1 none).
* :data:`Supports`: the constraints and contacts: prescribed unknowns, nodal
  frames, the supports' table (one row per support, row b contact boundary
  b's: ``kind`` (n_sup,) int64, :mod:`.layout` ``SUP_*``; ``geom`` (n_sup,
  N_GEOM) its parameters, ``SB_*``, ``ST_*``, ``PT_*``, a rigid point's
  branch and reaction among them; ``active`` (n_sup, nn) int8 the nodes it
  holds; its geometry read through :mod:`.supports`), the friction springs
  (the seabed's), and the lateral hold (bool per node) the Newton kernel
  writes: the nodes the stinger held on its plane in the last iteration (the
  converged set when it returns OK, which the results read).
* :data:`Ends`: the nodal loads, the load path's residual offset, and the ends'
  tensions: the bottom tension (an unknown when the top tension is given) and
  the top's target.
* :data:`Settings`: tolerance, reference force and length, iteration cap,
  whether the iteration may hold the contact boundaries (False for a call
  that starts from a state in balance), and the largest move [m] of a
  contact boundary per Newton step.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from . import layout as L

Model = namedtuple("Model", ["props", "table", "factors", "section", "bed"],
                   defaults=(np.zeros((0, 3)),))
Mesh = namedtuple("Mesh", ["s_el", "s_a", "s_b", "s_bd", "bnodes"])
Supports = namedtuple("Supports", ["fix_mask", "fix_val", "phi_r", "phi_rp", "kind", "geom",
                                   "active", "fric", "y_held"])
Ends = namedtuple("Ends", ["f_node", "g_off", "tb", "slide_dof", "top_node", "top_target",
                           "slide_angle"], defaults=(0.0,))
Settings = namedtuple("Settings", ["tol", "fref", "href", "maxit", "hold", "bstep"])


def load_factors(current: float, friction: bool) -> np.ndarray:
    """A Model's ``factors`` (layout ``F_*``): the current's drag factor and
    whether seabed friction acts."""
    f = np.zeros(L.N_FACTORS)
    f[L.F_CURRENT] = current
    f[L.F_FRICTION] = 1.0 if friction else 0.0
    return f

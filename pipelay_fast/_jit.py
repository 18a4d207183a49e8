"""The one JIT policy of pipelay_fast.

Every kernel is compiled with :func:`jit`, never with a bare ``numba.njit``:

* ``cache=True`` so that worker processes and later sessions load machine code
  from ``__pycache__`` instead of recompiling (measured by
  ``benchmarks/bench_jlay.py``: a cold import and first solve about 26 s, a
  cached one about 0.9 s). Numba does not notice edits to a callee defined in
  another module: delete ``__pycache__`` after changing a kernel;
* ``nopython`` (``njit``): no object mode, no Python objects inside kernels;
* ``error_model="numpy"``: a division by zero gives inf/nan instead of raising,
  so kernels need no exception handling; kernels report failure through status
  codes that the Python layer turns into :class:`pipelay_fast.SolveError`;
* ``fastmath`` stays off: the 2D and 3D kernels must agree to round-off and the
  finite-difference tangent tests compare to ~1e-7.
"""

from __future__ import annotations

import numba


def jit(func=None, **overrides):
    """Decorate a kernel with the project's numba policy (see module docstring)."""
    options = {"cache": True, "nogil": True, "error_model": "numpy"}
    options.update(overrides)
    if func is None:
        return lambda f: numba.njit(**options)(f)
    return numba.njit(**options)(func)

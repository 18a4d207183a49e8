"""pipelay_fast: static nonlinear 2D/3D analysis of offshore pipelaying.

>>> import pipelay_fast as pf
>>> case = pf.load_case("j125.toml")
>>> result = pf.solve(case)
>>> result.summary["tdp_z"], result.profile[["s", "x", "z", "von_mises"]]
"""

from .case import Case, load_case
from .results import Result
from .solver import SolveError, solve

__all__ = ["Case", "Result", "SolveError", "load_case", "solve"]
__version__ = "0.1.0"

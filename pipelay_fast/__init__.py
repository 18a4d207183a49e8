"""pipelay_fast: static nonlinear 2D/3D analysis of offshore pipelaying.

>>> import pipelay_fast as pf
>>> case = pf.load_case("j125.toml")
>>> result = pf.solve(case)
>>> result.summary["tdp_z"], result.profile[["s", "x", "z", "von_mises"]]
>>> pf.solve_for(case, target={"sagbend_lcc_utilisation": 0.3}, vary="lay.top_tension",
...              bounds=(400e3, 700e3)).case.lay.top_tension
"""

from .case import Case, load_case
from .results import Result
from .solver import SolveError, solve
from .target import TargetError, solve_for

__all__ = ["Case", "Result", "SolveError", "TargetError", "load_case", "solve", "solve_for"]
__version__ = "0.1.0"

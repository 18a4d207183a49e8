"""pipelay_fast: static nonlinear 2D/3D analysis of offshore pipelaying.

>>> import pipelay_fast as pf
>>> case = pf.load_case("j125")  # a bundled example; or a case file's path
>>> result = pf.solve(case)
>>> result.summary["tdp_z"], result.profile[["s", "x", "z", "von_mises"]]
>>> pf.solve_for(case, target={"sagbend_lcc_utilisation": 0.3}, vary="lay.top_tension",
...              bounds=(400e3, 700e3)).case.lay.top_tension
"""

from ._version import __version__
from .api.solve import solve
from .api.target import TargetError, solve_for
from .input.case import Case, load_case
from .input.errors import SolveError
from .output.results import Result

__all__ = ["__version__", "Case", "Result", "SolveError", "TargetError", "load_case", "solve",
           "solve_for"]

"""``pipelay_fast.solve``: one case from its validated input to its result.

The engine (:func:`pipelay_fast.engine.solver.solve_problem`) finds the
equilibrium; the output layer (:mod:`pipelay_fast.output.results`) builds the
profile and the summary from it; this module refuses an answer that is not
finite or lies outside the model.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ..engine.solver import solve_problem
from ..engine.state import Problem
from ..input.case import Case
from ..input.errors import SolveError
from ..input.limits import strain_beyond_line
from ..output.results import Result, build_profile, build_rollers, build_summary
from ..output.sensitivity import sensitivity_table
from ..output.spans import span_table
from .notice import announce_compile, case_cached


def solve(case: Case, *, warm: Result | None = None,
          sensitivities: Sequence[str] | None = None) -> Result:
    """Solve one case.

    ``warm``: the result of a neighbouring case (same dimension and lay method,
    e.g. the previous `a` of a sweep); Newton starts from its solution on its
    mesh instead of from the catenary guess, and falls back to the catenary
    guess if that fails (or if its answer is refused).

    ``sensitivities``: dotted numeric case keys (``"lay.stinger.a"``,
    ``"lay.top_tension"``, ``"environment.water_depth"``,
    ``"environment.current.speed"``, ...); the result's ``.sensitivities``
    is then the derivative of every numeric summary column (and of its
    peaks' arc lengths) by each, the solved regime held, NaN with a reason
    where a column is not differentiable
    (:func:`pipelay_fast.output.sensitivity.sensitivity_table`).

    Returns
    -------
    Result
        ``.summary`` (dict, the columns of
        ``pipelay_fast.output.results.SUMMARY_UNITS``) and ``.profile``
        (DataFrame, one row per node), SI units.

    Raises
    ------
    SolveError
        When Newton and the load-path fallback both fail, or
        solver.max_iterations_total Newton iterations are spent (each start,
        warm and cold, has its own budget); the message names the case, the
        load step, the residual and the reason. Also when the answer is
        refused: non-finite, strained beyond solver.max_strain, or lifting
        off below the stinger's tip
        (:func:`pipelay_fast.engine.solver.solve_problem`). An answer whose
        contact pulls is not refused: the contact boundaries' equations
        leave none (checked on the grids and random cases of
        ``benchmarks/bench_contact.py``).
    ValueError
        When a key of ``sensitivities`` is not numeric in the case, when
        the mesh would exceed solver.max_elements (checked before it is
        built), when ``warm`` is not a Result of :func:`solve` or is of
        another dimension, lay method (stinger kind) or roller count, or when
        the inputs give no first guess (a floating pipe, a tension too low
        to hold it).

    The first call in a process whose kernels (the case's family,
    :func:`pipelay_fast.engine.model.scene_of`) are not in numba's cache
    logs that they compile (:mod:`pipelay_fast.api.notice`).
    """
    announce_compile(case_cached(case))
    if warm is not None and not isinstance(getattr(warm, "state", None), Problem):
        raise ValueError("warm: expected a Result from pipelay_fast.solve, got "
                         f"{type(warm).__name__}")
    result = None
    if warm is not None:
        try:
            result = _checked_solve(case, warm.state)
        except SolveError:  # a neighbour too far away: start from the catenary
            pass
    if result is None:
        result = _checked_solve(case)
    if sensitivities:
        result.sensitivities = sensitivity_table(case, result.state, list(sensitivities),
                                                 result.functional)
    return result


def _checked_solve(case: Case, warm: Problem | None = None) -> Result:
    """Solve from ``warm`` (a solved Problem) or cold, build the result and
    refuse it (SolveError) if its regime is outside the model, it is not
    finite or it is strained beyond solver.max_strain."""
    pb, sol = solve_problem(case, warm)
    columns = build_profile(case, sol)
    rollers = build_rollers(case, sol)
    functional = _functional_case(case)
    spans = span_table(case, sol)
    summary = build_summary(case, sol, columns, rollers, functional, spans=spans)
    bad = [key for key, val in summary.items() if isinstance(val, float) and math.isinf(val)]
    bad += [key for key, col in columns.items()
            if col.dtype.kind == "f" and not np.isfinite(col).all()]
    if bad:
        raise SolveError(f"case {case.name!r}: the solution has non-finite values in "
                         f"{', '.join(bad)}; it is not returned")
    beyond = strain_beyond_line(case, columns)
    if beyond is not None:
        raise SolveError(f"case {case.name!r}: {beyond}")
    return Result(case, summary, columns, state=pb, roller_columns=rollers,
                  functional=functional, span_columns=spans)


def _functional_case(case: Case) -> dict | None:
    """The profile columns of ``case`` without its current (the functional
    load case of its code check, solved from its own guess) when the check
    splits the current off (:meth:`pipelay_fast.input.checks.Checks.splits_current`);
    None otherwise.

    Raises
    ------
    SolveError
        When the case without current does not solve.
    """
    if case.checks is None or not case.checks.splits_current(case):
        return None
    try:
        return _checked_solve(case.with_changes({"environment.current": None})).columns
    except SolveError as err:
        raise SolveError(f"case {case.name!r}: its functional load case (no current, for "
                         f"checks.current_load = 'environmental') did not solve: {err}") from err


__all__ = ["SolveError", "solve"]

"""The reference of the sensitivities with seabed friction on the current's
path (3D under a cross current): central differences of Newton solves of
the case at p +- h, each from the answer with its friction anchors carried
and its slip set held (the sensitivities' definition,
:func:`pipelay_fast.engine.sensitivity.held_answer`), each side meshed and
solved to the case's tolerance as the sensitivities' base is
(:func:`pipelay_fast.engine.sensitivity.base_solution`): the nonlinear
solves that the sensitivities' linear response stands for. Shared by the
tests and benchmarks/bench_sensitivity.py."""

from __future__ import annotations

import math

from pipelay_fast.engine.problem import guess_sizes
from pipelay_fast.engine.sensitivity import base_solution, held_answer
from pipelay_fast.input.validate import get_path
from pipelay_fast.output import sensitivity as S


def held_slip_central(case, result, key: str, h: float, names) -> dict:
    """{column: (f(p + h) - f(p - h)) / 2h} for the summary columns
    ``names`` (those finite on both sides) by ``key`` at its value p in
    ``case``, from ``result`` (``pf.solve(case)``'s) answer, as the module
    docstring says. Raises AssertionError where a side has no solution."""
    p = float(get_path(case.to_dict(), key))
    sides = []
    for value in (p + h, p - h):
        moved = case.with_number(key, value)
        held, why = held_answer(moved, result.state)
        assert held is not None, why
        _problem, solution, why = base_solution(moved, held, guess_sizes(moved))
        assert solution is not None, why
        sides.append(S._side(moved, solution, result.functional)[0])
    return {name: (sides[0][name] - sides[1][name]) / (2.0 * h) for name in names
            if isinstance(sides[0][name], float) and math.isfinite(sides[0][name])
            and math.isfinite(sides[1][name])}

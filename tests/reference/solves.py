"""References made of full solves (``pf.solve``), shared by the tests and
the benchmarks: central finite differences of the summary, Richardson-
extrapolated, and a root of a summary's function by brentq on cold solves.
They use nothing of ``pipelay_fast`` but its public solve."""

from __future__ import annotations

import math

from scipy.optimize import brentq

import pipelay_fast as pf


def _central(case, key: str, p: float, h: float, names) -> dict:
    """Central differences (f(p + h) - f(p - h)) / 2h of the summary columns
    ``names`` (those in the summary, a float, finite at p + h) by ``key`` at
    ``p``."""
    up = pf.solve(case.with_changes({key: p + h})).summary
    down = pf.solve(case.with_changes({key: p - h})).summary
    return {name: (up[name] - down[name]) / (2.0 * h) for name in names
            if isinstance(up.get(name), float) and math.isfinite(up[name])}


def richardson(case, key: str, p: float, h: float, names) -> dict:
    """{column: d column / d ``key``} at the key's value ``p`` of ``case``:
    the Richardson extrapolation (4 D(h) - D(2h)) / 3 of the central
    differences D of full solves at the steps ``h`` and 2 ``h`` (error
    O(h^4) where the answer is smooth), for the summary columns ``names``."""
    fine, coarse = _central(case, key, p, h, names), _central(case, key, p, 2.0 * h, names)
    return {name: (4.0 * fine[name] - coarse[name]) / 3.0 for name in fine}


def direct_root(case, key: str, f, lo: float, hi: float, xtol: float) -> tuple[float, int]:
    """(the root of ``f`` (a function of a summary) in ``key`` between
    ``lo`` and ``hi`` by brentq on cold solves of ``case`` to ``xtol``, the
    solves it took)."""
    count = [0]

    def g(value):
        count[0] += 1
        return f(pf.solve(case.with_changes({key: value})).summary)

    return brentq(g, lo, hi, xtol=xtol), count[0]

"""A root of a function of one parameter in a bracket, by Newton guarded
by bisection, to round-off with no tolerance.

The caller evaluates f and df/dx at ``x`` and passes them to
:func:`bracketed_step` with the bracket [lo, hi] (f changes sign across it;
f(lo) has the sign ``sign_lo``) and the length of the last step taken; it
gets the next point to evaluate, the bracket updated by the sign of f(x)
and whether x is the answer. Newton's step is taken while it stays
strictly inside the bracket and is shorter than the last step; otherwise
the bracket is bisected. The answer is x when Newton's step no longer
moves it (a fixed point in floating point) or when the bracket is two
neighbouring floats (the computed f changes sign between them).

It ends: every point evaluated lies strictly inside the bracket, so each
evaluation replaces one end by a point strictly between them, and a
bracket of floats can shrink only so often. Newton from a good start takes
a few steps; where round-off keeps its step from shrinking before the step
vanishes, bisection and Newton alternate until the bracket closes on the
root (a few dozen evaluations at most on the elements of
tests/test_roots.py).
"""

from __future__ import annotations

from ._jit import jit


@jit(_nrt=False)
def bracketed_step(x, f, df, lo, hi, sign_lo, last):
    """One step of Newton guarded by bisection from ``x`` (f(x) = ``f`` != 0,
    f'(x) = ``df``) in the bracket [``lo``, ``hi``] whose lower end has the
    sign ``sign_lo`` (+1 or -1), after a step of length ``last`` (inf at the
    start). Returns (next x, lo, hi, the step's length, done); when done,
    the next x is ``x``, the answer."""
    if (f > 0.0) == (sign_lo > 0.0):
        lo = x
    else:
        hi = x
    new = x - f / df  # (df = 0: inf or nan, which no comparison below takes)
    step = abs(new - x)
    if lo < new < hi and step < last:
        return new, lo, hi, step, False
    if new == x:
        return x, lo, hi, last, True
    mid = 0.5 * (lo + hi)
    if not lo < mid < hi:
        return x, lo, hi, last, True
    return mid, lo, hi, abs(mid - x), False

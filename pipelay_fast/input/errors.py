"""The error a solve raises when it has no answer to return (input layer, so
that every layer above can raise and catch it)."""

from __future__ import annotations


class SolveError(RuntimeError):
    """A case that did not converge, or whose answer is refused (beyond the
    model, or not a valid solution): the message names the step, residual and
    reason, or the limit."""

"""Validation helpers for :mod:`pipelay_fast.input.case` and its tables.

Each helper checks one value and raises :class:`ValueError` whose message names
the key by its dotted path and shows the offending value; none clamps or guesses.
The dict helpers address nested case tables by dotted paths ("lay.stinger.a").
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import numbers
import tomllib
from collections.abc import Callable, Mapping
from pathlib import Path

import numpy as np


def from_toml(path: Path, build: Callable[[Mapping], object]):
    """``build(tables)`` of the TOML file ``path``; a syntax error or a
    ValueError of ``build`` is raised as a ValueError prefixed by the path."""
    with path.open("rb") as stream:
        try:
            tables = tomllib.load(stream)
        except tomllib.TOMLDecodeError as err:
            raise ValueError(f"{path}: invalid TOML: {err}") from None
    try:
        return build(tables)
    except ValueError as err:
        raise ValueError(f"{path}: {err}") from None


def fail(path, value, problem):
    """Raise ``ValueError("<path> = <value> <problem>")``."""
    raise ValueError(f"{path} = {value!r} {problem}")


def assign(obj, name, value):
    """Set a field of a frozen dataclass (used to normalise it in ``__post_init__``)."""
    object.__setattr__(obj, name, value)


def number(path, value):
    """A finite real number as float; bool is not a number."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        fail(path, value, "must be a number")
    value = float(value)
    if not math.isfinite(value):
        fail(path, value, "must be finite")
    return value


def set_numbers(obj, prefix, *, positive=(), non_negative=(), finite=()):
    """Convert the named fields of ``obj`` to float and check their sign."""
    rules = (
        (positive, lambda v: v > 0, "must be positive"),
        (non_negative, lambda v: v >= 0, "must not be negative"),
        (finite, lambda v: True, ""),
    )
    for names, ok, problem in rules:
        for name in names:
            path = f"{prefix}.{name}"
            value = number(path, getattr(obj, name))
            if not ok(value):
                fail(path, value, problem)
            assign(obj, name, value)


def vector(path, value, n):
    """A list of ``n`` numbers as a tuple of floats."""
    if not isinstance(value, (tuple, list, np.ndarray)) or len(value) != n:
        fail(path, value, f"must be a list of {n} numbers")
    return tuple(number(f"{path}[{i}]", v) for i, v in enumerate(value))


def choice(path, value, allowed):
    """One of the ``allowed`` strings (case-sensitive)."""
    if not isinstance(value, str) or value not in allowed:
        fail(path, value, f"must be one of {', '.join(map(repr, allowed))}")
    return value


def flag(path, value):
    """A TOML boolean; 0 and 1 are not booleans."""
    if not isinstance(value, (bool, np.bool_)):
        fail(path, value, "must be true or false")
    return bool(value)


def integer(path, value, minimum):
    """An integer >= ``minimum``; bool and float are refused."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        fail(path, value, "must be an integer")
    if value < minimum:
        fail(path, value, f"must be at least {minimum}")
    return int(value)


def instance(path, value, cls):
    """Refuse a value that is not a ``cls``."""
    if not isinstance(value, cls):
        fail(path, value, f"must be a {cls.__name__}")


def vectorised(x, func):
    """Evaluate ``func`` on ``x`` as a float array; a scalar in gives a scalar out
    (a float in is evaluated as a NumPy float: the same arithmetic as a 0-d
    array's, without building one)."""
    if isinstance(x, float):
        return func(np.float64(x))[()]
    return func(np.asarray(x, dtype=np.float64))[()]


def did_you_mean(word, names, prefix="") -> str:
    """`` (did you mean <prefix><name>?)`` for the name of ``names`` closest to
    ``word`` (:func:`difflib.get_close_matches`), or "" when none is close."""
    close = difflib.get_close_matches(str(word), list(names), n=1)
    return f" (did you mean {prefix}{close[0]}?)" if close else ""


def reject_unknown(table, allowed, prefix, *, listed=False):
    """Refuse keys of ``table`` not in ``allowed``, suggesting a close match;
    ``listed``: the message lists ``allowed`` too."""
    for key in table:
        if key not in allowed:
            kind = "table" if not prefix and isinstance(table[key], Mapping) else "key"
            valid = f"; one of {', '.join(map(str, allowed))}" if listed else ""
            raise ValueError(f"unknown {kind} {prefix}{key}{did_you_mean(key, allowed, prefix)}"
                             f"{valid}")


def plain(value):
    """Dataclasses to dicts (None and empty values dropped), tuples to lists."""
    if dataclasses.is_dataclass(value):
        pairs = ((f.name, getattr(value, f.name)) for f in dataclasses.fields(value))
        return {k: plain(v) for k, v in pairs if v is not None and v != ()}
    if isinstance(value, Mapping):
        return {k: plain(v) for k, v in value.items()}
    if isinstance(value, (tuple, list)):
        return [plain(v) for v in value]
    return value


def get_path(tree, path):
    """Value at a dotted path of nested dicts, None if absent."""
    for key in path.split("."):
        if not isinstance(tree, Mapping) or key not in tree:
            return None
        tree = tree[key]
    return tree


def number_at(tree, path) -> float | None:
    """The value at a dotted path of nested dicts as a float, None where it
    is not a number there (absent, a bool, text, a table)."""
    value = get_path(tree, path)
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        return None
    return float(value)


def put_path(tree, path, value):
    """Set a dotted path of nested dicts, creating tables; None removes the key."""
    *parents, last = path.split(".")
    for key in parents:
        tree = tree.setdefault(key, {})
        if not isinstance(tree, dict):
            raise ValueError(f"unknown key {path}")
    if value is None:
        tree.pop(last, None)
    else:
        tree[last] = value

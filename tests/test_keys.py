"""The case-file key reference (docs/reference/keys.md) is the registry's
rendering (pipelay_fast.input.keys), every key is documented, and the checks
it lists are the ones a case refuses."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import pytest

import pipelay_fast as pf
from pipelay_fast.input import keys as registry
from pipelay_fast.input.examples import example_names

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "reference" / "keys.md"
KEYS = registry.keys()


def test_committed_reference_is_the_registry_rendering():
    assert PAGE.read_text() == registry.render(), (
        "docs/reference/keys.md is stale: regenerate it with "
        "`python -m pipelay_fast.input.keys > docs/reference/keys.md`")


def test_every_key_is_documented_with_a_unit():
    assert registry.undocumented(KEYS) == []


def test_every_key_of_the_loader_is_in_the_registry():
    """Each table class's fields are the keys and subtables the loader
    accepts; every key a bundled example gives is in the registry."""
    paths = {key.path for key in KEYS}
    for name in example_names():
        assert _dotted(pf.load_case(name).to_dict()) <= paths, name


def _dotted(tree: dict, prefix: str = "") -> set[str]:
    """The dotted paths of a nested dict's leaves."""
    found = set()
    for key, value in tree.items():
        if isinstance(value, dict):
            found |= _dotted(value, f"{prefix}{key}.")
        else:
            found.add(f"{prefix}{key}")
    return found


@dataclass(frozen=True)
class _Inner:
    """A table.

    Attributes
    ----------
    length : float
        A length [m].
    count : int
        How many, with no unit.
    """

    length: float = 1.0
    count: int = 2
    label: str = "x"


@dataclass(frozen=True)
class _Outer:
    """The top.

    Attributes
    ----------
    inner : _Inner
        A table.
    """

    inner: _Inner = dataclasses.field(default_factory=_Inner)


def test_a_key_added_without_documentation_is_reported():
    """A number without a unit, and a key without an entry, are named."""
    found = registry.keys(_Outer)
    assert [k.path for k in found] == ["inner.length", "inner.count", "inner.label"]
    problems = registry.undocumented(found)
    assert len(problems) == 2
    assert problems[0].startswith("inner.count ") and "unit" in problems[0]
    assert problems[1].startswith("inner.label ") and "no entry" in problems[1]


def _bad_value(check: str):
    """A value the check refuses, or None for a check not probed here."""
    if check == "> 0":
        return 0
    if check == ">= 0":
        return -1.0
    if check.startswith("one of"):
        return "no-such-choice"
    if check.startswith("an integer >= "):
        return int(check.rsplit(" ", 1)[1]) - 1
    if check == "true or false":
        return 1
    if check.startswith("a list of "):
        return [1.0] * (int(check.split()[3]) + 1)
    return None


def _base_case(key):
    """The first bundled example with the key's table, of the key's class."""
    for name in example_names():
        case = pf.load_case(name)
        table = case
        for part in key.table.split(".") if key.table else ():
            table = getattr(table, part, None)
        if isinstance(table, key.owner):
            return case
    return None


PROBES = [(key, check) for key in KEYS for check in key.check.split("; ")
          if _bad_value(check) is not None]


@pytest.mark.parametrize(("key", "check"), PROBES,
                         ids=[f"{key.path}:{check}" for key, check in PROBES])
def test_a_listed_check_refuses_its_value(key, check):
    """A value the reference says is refused raises ValueError naming the key."""
    case = _base_case(key)
    if case is None:
        pytest.skip(f"no bundled example has a {key.owner.__name__} table")
    with pytest.raises(ValueError, match=key.path.replace(".", r"\.")):
        case.with_changes({key.path: _bad_value(check)})

"""Shared fixtures: the paper's J125 case and access to tests/reference."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

_HERE = str(Path(__file__).resolve().parent)
if _HERE not in sys.path:  # tests/ has no __init__.py
    sys.path.insert(0, _HERE)

import pipelay_fast as pf  # noqa: E402

EXAMPLES = Path(pf.__file__).resolve().parent / "examples"


@pytest.fixture(scope="session")
def j125():
    """The paper's J-lay scene as bundled (``pipelay_fast/examples/j125.toml``)."""
    return pf.load_case(EXAMPLES / "j125.toml")

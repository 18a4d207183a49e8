"""Shared fixtures: the paper's J125 case and access to tests/reference."""

from __future__ import annotations

import pytest

import pipelay_fast as pf
from tests.helpers import EXAMPLES


@pytest.fixture(scope="session")
def j125():
    """The paper's J-lay scene as bundled (``pipelay_fast/examples/j125.toml``)."""
    return pf.load_case(EXAMPLES / "j125.toml")

"""Shared fixtures: the paper's J125 case, access to tests/reference, peer engines."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

_HERE = str(Path(__file__).resolve().parent)
if _HERE not in sys.path:  # tests/ has no __init__.py
    sys.path.insert(0, _HERE)

import pipelay_fast as pf  # noqa: E402

EXAMPLES = Path(pf.__file__).resolve().parent / "examples"
# set by .ci/run: a peer engine that cannot load fails its tests instead of skipping them
REQUIRE_PEERS = "PIPELAY_FAST_REQUIRE_PEERS"


def require_peer(load):
    """What ``load()`` returns (a peer engine's module); when it raises ImportError
    (the engine is not installed or cannot load), skip the test, or the test
    module when called at import, with the error's message as the reason, or
    fail when the environment sets PIPELAY_FAST_REQUIRE_PEERS=1."""
    try:
        return load()
    except ImportError as err:
        reason = str(err)
    if os.environ.get(REQUIRE_PEERS) == "1":
        pytest.fail(f"{reason} ({REQUIRE_PEERS}=1)", pytrace=False)
    pytest.skip(reason, allow_module_level=True)


@pytest.fixture(scope="session")
def j125():
    """The paper's J-lay scene (DESIGN section 6) as bundled."""
    return pf.load_case(EXAMPLES / "j125.toml")

"""The README's Outputs section lists exactly the columns a solve writes."""

from __future__ import annotations

import re
from pathlib import Path

import pipelay_fast as pf
from pipelay_fast.results import PROFILE_UNITS, SUMMARY_UNITS

README = Path(__file__).resolve().parents[1] / "README.md"


def readme_columns(label: str) -> list[str]:
    """The backquoted column list after ``label`` in the README's Outputs section."""
    section = README.read_text().split("\n## Outputs\n", 1)[1].split("\n## ", 1)[0]
    match = re.search(rf"{label}[^`]*`([^`]*)`", section)
    assert match, f"no {label!r} list in the README's Outputs"
    return [name.strip() for name in match.group(1).split(",")]


def test_readme_lists_the_columns_a_solve_writes(j125):
    result = pf.solve(j125)
    assert readme_columns("Summary columns") == list(SUMMARY_UNITS) == list(result.summary)
    assert readme_columns("Profile columns") == list(PROFILE_UNITS) == list(result.profile.columns)

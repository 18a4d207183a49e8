"""The README: its Outputs section lists exactly the columns a solve writes;
its one figure is what its first set-up command writes, never a committed file."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

import pipelay_fast as pf
from pipelay_fast.output.results import PROFILE_UNITS, SUMMARY_UNITS

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"


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


def test_readme_figure_is_written_by_the_first_set_up_command():
    """The README shows one image, RESULTS_DIR/sweep.png of the first set-up
    command's sweep, which its last step ``pipelay-fast plot RESULTS_DIR``
    writes (the default file, tests/test_plot.py), under a path git ignores;
    the README states that command next to the link."""
    text = README.read_text()
    images = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", text)
    assert len(images) == 1
    first = re.search(r"```bash\n(.*?)\n```", text, re.S).group(1)
    results = re.search(r"pipelay-fast sweep \S+ --out (\S+)", first).group(1)
    assert first.rstrip().endswith(f"pipelay-fast plot {results}")
    assert images[0] == f"{results}/sweep.png"
    after = text.split(images[0] + ")", 1)[1][:400]
    assert f"`pipelay-fast plot {results}`" in after
    ignored = (ROOT / ".gitignore").read_text().split()
    assert images[0].split("/")[0] + "/" in ignored


def test_no_generated_figure_is_committed():
    if shutil.which("git") is None:
        pytest.skip("git is not installed")
    listed = subprocess.run(["git", "ls-files", "*.png", "*.svg", "*.pdf"], cwd=ROOT,
                            capture_output=True, text=True)
    if listed.returncode != 0:
        pytest.skip(f"not a git checkout: {listed.stderr.strip()}")
    assert listed.stdout.split() == []

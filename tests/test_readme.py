"""The README: its Outputs section lists exactly the columns a solve writes;
its one figure is what its first set-up command writes, never a committed file;
its install brings what its snippets import, and they run outside the repository."""

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


def readme_snippets() -> list[str]:
    """The README's Python code blocks, in order."""
    return re.findall(r"```python\n(.*?)```", README.read_text(), re.S)


def readme_extras() -> set[str]:
    """The extras of the README's install commands (``pip install ".[a,b]"``)."""
    found = re.findall(r"""pip install ["']?\.\[([^\]]*)\]""", README.read_text())
    return {extra.strip() for group in found for extra in group.split(",")}


def test_the_readme_install_brings_what_its_snippets_import():
    """Every module a README snippet imports is the package's own or comes
    with its dependencies and the extras the README's set-up command installs
    (the first's, ``plot``: the figures and the duckdb query)."""
    import ast
    import importlib.metadata
    import tomllib

    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    first = re.search(r"```bash\n(.*?)\n```", README.read_text(), re.S).group(1)
    extras = set(re.findall(r"""pip install ["']?\.\[([^\]]*)\]""", first)[0].split(","))
    assert extras <= readme_extras() <= set(project["optional-dependencies"])
    required = project["dependencies"] + [req for extra in extras
                                          for req in project["optional-dependencies"][extra]]
    installed = {re.split(r"[\s<>=\[;]", req)[0].lower() for req in required}
    distributions = importlib.metadata.packages_distributions()
    modules = {(alias.name if isinstance(node, ast.Import) else node.module).split(".")[0]
               for snippet in readme_snippets() for node in ast.walk(ast.parse(snippet))
               if isinstance(node, ast.Import | ast.ImportFrom) for alias in node.names}
    assert {"pipelay_fast", "pandas", "duckdb"} <= modules
    for module in modules - {"pipelay_fast"}:
        assert {d.lower() for d in distributions.get(module, [module])} & installed, module


def test_the_readme_snippets_run_outside_the_repository(tmp_path):
    """Each Python snippet of the README runs as a script in a folder outside
    the repository, so that it imports the installed package (not the source
    tree) and names no file of the repository; the results it reads are those
    of a small sweep written where the README's sweep writes them."""
    import sys

    from pipelay_fast.study.runner import run_sweep
    from pipelay_fast.study.sweep_file import load_sweep

    sweep = load_sweep({"name": "paper", "set": {"solver.element_length": 8.0},
                        "scenes": [{"name": "S67", "case": "s67"}],
                        "vary": {"a": [-0.0012, -0.0013]}})
    run_sweep(sweep, tmp_path / "results" / "paper", workers=1, progress=False)
    snippets = readme_snippets()
    assert any("pf.load_case(" in snippet for snippet in snippets)
    for snippet in snippets:
        script = snippet + "\nimport pipelay_fast\nprint(pipelay_fast.__file__)\n"
        done = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, capture_output=True,
                              text=True, timeout=900)
        assert done.returncode == 0, f"{snippet}\n{done.stderr}"
        imported = Path(done.stdout.split()[-1]).resolve()
        assert imported.name == "__init__.py" and not imported.is_relative_to(tmp_path)

"""The package's layers import only downward, and no module imports itself
back through others: input < kernels < engine < output < api < study < cli;
and modules and functions stay small enough to read.

Every import counts, those inside functions and under ``TYPE_CHECKING``
included. Read from the sources with :mod:`ast`, nothing imported."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "pipelay_fast"
LAYERS = ("input", "kernels", "engine", "output", "api", "study", "cli")
# what any layer may import: the version string
BASE = {"pipelay_fast._version"}
# the only third-party packages a kernel may import
KERNEL_IMPORTS = {"numba", "numpy"}


def module_names() -> dict[str, Path]:
    names = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        names[".".join(parts)] = path
    return names


MODULES = module_names()


def imports_of(name: str) -> tuple[set[str], set[str]]:
    """(the package's modules ``name`` imports, the top-level names of the
    other packages it imports), wherever the import stands."""
    path = MODULES[name]
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    ours, theirs = set(), set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            for alias in node.names:
                (ours if alias.name.split(".")[0] == "pipelay_fast" else theirs).add(
                    alias.name if alias.name.split(".")[0] == "pipelay_fast"
                    else alias.name.split(".")[0])
        elif isinstance(node, ast.ImportFrom):
            if node.level == 0 and not (node.module or "").startswith("pipelay_fast"):
                theirs.add(node.module.split(".")[0])
                continue
            base = package.split(".")
            base = base[:len(base) - node.level + 1] if node.level else []
            target = ".".join(base + ([node.module] if node.module else []))
            for alias in node.names:  # a submodule imported by name, else its package
                sub = f"{target}.{alias.name}"
                ours.add(sub if sub in MODULES else target)
    return {m for m in ours if m != name}, theirs - {"__future__"}


def layer_of(name: str) -> int:
    """The rank of module ``name`` in LAYERS; the package itself is the api's facade."""
    if name == "pipelay_fast":
        return LAYERS.index("api")
    top = name.split(".")[1]
    return LAYERS.index("cli" if top in ("cli", "__main__") else top)


def test_every_module_belongs_to_a_layer():
    for name in MODULES:
        if name in BASE or name == "pipelay_fast":
            continue
        assert name.split(".")[1] in LAYERS + ("__main__",), f"{name} is in no layer"


@pytest.mark.parametrize("name", sorted(MODULES))
def test_imports_go_only_downward(name):
    if name in BASE:
        assert not imports_of(name)[0], f"{name} is importable from every layer: it imports none"
        return
    ours, theirs = imports_of(name)
    upward = sorted(m for m in ours - BASE if layer_of(m) > layer_of(name))
    assert not upward, f"{name} ({LAYERS[layer_of(name)]}) imports from above: {upward}"
    if name != "pipelay_fast":
        assert "pipelay_fast" not in ours, f"{name} imports the package's facade"
    if layer_of(name) == LAYERS.index("kernels"):
        stdlib = {"collections", "gc", "math", "typing", "hashlib", "inspect", "os", "sys",
                  "tempfile", "types"}
        assert theirs <= KERNEL_IMPORTS | stdlib, f"{name} imports {sorted(theirs - stdlib)}"


def test_no_import_cycles():
    graph = {name: imports_of(name)[0] & MODULES.keys() for name in MODULES}
    state: dict[str, int] = {}  # 1 on the path, 2 done
    path: list[str] = []

    def visit(name):
        state[name] = 1
        path.append(name)
        for dep in sorted(graph[name]):
            if state.get(dep) == 1:
                cycle = path[path.index(dep):] + [dep]
                raise AssertionError("import cycle: " + " -> ".join(cycle))
            if dep not in state:
                visit(dep)
        path.pop()
        state[name] = 2

    for name in sorted(graph):
        if name not in state:
            visit(name)


def test_the_checks_find_what_they_look_for(tmp_path, monkeypatch):
    """The reader sees an import inside a function and under TYPE_CHECKING."""
    source = ("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n"
              "    from ..study.sweep import Sweep\n"
              "def f():\n    from . import layout\n    import scipy.linalg\n")
    fake = tmp_path / "pipelay_fast" / "kernels" / "fake.py"
    fake.parent.mkdir(parents=True)
    fake.write_text(source)
    monkeypatch.setitem(MODULES, "pipelay_fast.kernels.fake", fake)
    ours, theirs = imports_of("pipelay_fast.kernels.fake")
    assert ours == {"pipelay_fast.study.sweep", "pipelay_fast.kernels.layout"}
    assert theirs == {"typing", "scipy"}
    with pytest.raises(AssertionError, match="imports from above"):
        test_imports_go_only_downward("pipelay_fast.kernels.fake")


MAX_MODULE_LINES = 500
MAX_FUNCTION_LINES = 120


@pytest.mark.parametrize("name", sorted(MODULES))
def test_modules_and_functions_stay_small(name):
    """No module over MAX_MODULE_LINES lines, no function (its docstring
    included) over MAX_FUNCTION_LINES."""
    text = MODULES[name].read_text()
    assert text.count("\n") <= MAX_MODULE_LINES, f"{name}: {text.count(chr(10))} lines"
    long = [f"{node.name} ({node.end_lineno - node.lineno + 1} lines)"
            for node in ast.walk(ast.parse(text))
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)
            and node.end_lineno - node.lineno + 1 > MAX_FUNCTION_LINES]
    assert not long, f"{name}: {', '.join(long)}"

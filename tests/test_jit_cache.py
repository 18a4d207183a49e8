"""The kernels' on-disk cache follows their sources (``pipelay_fast._jit``)."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numba
import numba.core.caching as caching
import pytest

import pipelay_fast as pf
from pipelay_fast.kernels import _jit, loads
from tests.helpers import EXAMPLES

PACKAGE = Path(pf.__file__).resolve().parent

# effective_weight (kernels/loads.py) reads sec[S_W_DRY], S_W_DRY a constant of kernels/layout.py
PROBE = """
import json, numpy as np
from pipelay_fast.kernels import layout, loads
props = np.zeros(layout.N_PROPS)
sec = 100.0 + np.arange(layout.N_SECTION)
weight = loads.effective_weight(props, sec, 1e9)  # above the sea and the contents: the dry weight
stats = loads.effective_weight.from_python().stats  # the copy Python calls (_jit.Kernel)
print(json.dumps({"file": loads.__file__, "weight": weight, "cache": stats.cache_path,
                  "hits": sum(stats.cache_hits.values())}))
"""


def _probe(root: Path, cache_dir: Path | None) -> dict:
    """Import the package copy under ``root`` in a fresh process and call the probe kernel."""
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["PYTHONPATH"] = str(root)
    if cache_dir is not None:
        env["NUMBA_CACHE_DIR"] = str(cache_dir)
    done = subprocess.run([sys.executable, "-c", PROBE], cwd=root, env=env, capture_output=True,
                          text=True, timeout=120, check=True)
    answer = json.loads(done.stdout.splitlines()[-1])
    # the copy, not the installed package
    assert Path(answer["file"]).resolve().is_relative_to(root.resolve())
    return answer


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert text.count(old) == 1, f"{old!r} not found once in {path}"
    path.write_text(text.replace(old, new))


@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="no machine code without the JIT")
@pytest.mark.parametrize("numba_cache_dir", [False, True], ids=["in-tree", "NUMBA_CACHE_DIR"])
def test_an_edit_in_another_module_reaches_the_cached_kernel(tmp_path, numba_cache_dir):
    shutil.copytree(PACKAGE, tmp_path / "pipelay_fast",
                    ignore=shutil.ignore_patterns("__pycache__"))
    layout = tmp_path / "pipelay_fast" / "kernels" / "layout.py"
    jit_module = tmp_path / "pipelay_fast" / "kernels" / "_jit.py"
    cache_dir = tmp_path / "numba-cache" if numba_cache_dir else None

    first = _probe(tmp_path, cache_dir)
    assert first["weight"] == 100.0 + 2 and first["hits"] == 0  # S_W_DRY = 2, compiled
    expected_cache = (tmp_path / "pipelay_fast" / "kernels" / "__pycache__" if cache_dir is None
                      else cache_dir)
    assert Path(first["cache"]).resolve().is_relative_to(expected_cache.resolve())
    assert (Path(first["cache"]) / _jit.STAMP_NAME).is_file()

    _edit(layout, "S_W_DRY = 2  #", "S_W_DRY = 7  #")
    # numba alone: loads.py is unchanged, so its cached machine code (S_W_DRY = 2) is loaded
    original = jit_module.read_text()
    _edit(jit_module, "\nexpire_stale_cache()\n", "\n")
    stale = _probe(tmp_path, cache_dir)
    assert stale["weight"] == 100.0 + 2 and stale["hits"] == 1

    jit_module.write_text(original)
    fresh = _probe(tmp_path, cache_dir)
    assert fresh["weight"] == 100.0 + 7 and fresh["hits"] == 0  # recompiled with S_W_DRY = 7
    again = _probe(tmp_path, cache_dir)
    assert again["weight"] == 100.0 + 7 and again["hits"] == 1  # and cached again


def _locator(name: str):
    """numba's cache locator class ``name`` (named with a leading underscore before 0.60)."""
    return getattr(caching, name, None) or getattr(caching, "_" + name)


def test_cache_dirs_are_numbas(monkeypatch, tmp_path):
    func = loads.effective_weight.py_func
    path = loads.__file__
    in_tree = _locator("InTreeCacheLocator")(func, path).get_cache_path()
    user_wide = _locator("UserWideCacheLocator")(func, path).get_cache_path()
    monkeypatch.setattr(numba.config, "CACHE_DIR", "")
    assert _jit.cache_dirs(os.path.dirname(path)) == [in_tree, user_wide]

    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path))
    provided = _locator("UserProvidedCacheLocator")(func, path).get_cache_path()
    assert _jit.cache_dirs(os.path.dirname(path)) == [provided]


def test_expire_deletes_only_the_kernels_cache_files(tmp_path):
    kernel_files = ["loads.effective_weight-15.py311.nbi", "loads.effective_weight-15.py311.1.nbc"]
    others = ["loads.cpython-311.pyc", "select.choose-3.py311.nbi"]
    for name in kernel_files + others:
        (tmp_path / name).write_bytes(b"x")

    assert _jit.expire(str(tmp_path), "digest 1", {"loads", "layout"})
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(others + [_jit.STAMP_NAME])
    assert (tmp_path / _jit.STAMP_NAME).read_text() == "digest 1"

    (tmp_path / kernel_files[0]).write_bytes(b"x")  # compiled under the current stamp
    assert _jit.expire(str(tmp_path), "digest 1", {"loads"})
    assert (tmp_path / kernel_files[0]).exists()
    assert _jit.expire(str(tmp_path), "digest 2", {"loads"})
    assert not (tmp_path / kernel_files[0]).exists()
    assert (tmp_path / _jit.STAMP_NAME).read_text() == "digest 2"


def test_expire_reports_an_unwritable_directory(tmp_path):
    blocked = tmp_path / "a file" / "cache"  # below a file: cannot be created
    (tmp_path / "a file").write_text("")
    assert not _jit.expire(str(blocked), "digest", {"loads"})


def test_every_module_with_kernels_is_hashed():
    uses_jit = {str(path) for path in PACKAGE.rglob("*.py")
                if re.search(r"^from \.+_jit import", path.read_text(), flags=re.MULTILINE)}
    assert uses_jit and uses_jit <= {str(Path(p).resolve()) for p in _jit.kernel_sources()}


def test_the_input_modules_the_kernels_import_are_hashed():
    """A kernel bakes in the constants it takes from the input layer
    (kernels/tuning.py's ROUNDOFF is input/limits.py's): each module a kernel
    module imports from ``..input`` is among the hashed sources, so an edit
    there expires the cache too."""
    kernels = PACKAGE / "kernels"
    taken = {m for path in kernels.glob("*.py")
             for m in re.findall(r"^from \.\.input\.(\w+) import", path.read_text(),
                                 flags=re.MULTILINE)}
    assert "limits" in taken
    hashed = {str(Path(p).resolve()) for p in _jit.kernel_sources()}
    assert {str((PACKAGE / "input" / f"{m}.py").resolve()) for m in taken} <= hashed


# two kernels under the project's policy: an entry and the callee it calls
TWO_KERNELS = """
from pipelay_fast.kernels._jit import jit

@jit(_nrt=False)
def inner(x):
    return 2.0 * x + 1.0

@jit(entry=True, _nrt=False)
def outer(x):
    return inner(x) - 1.0
"""

CALLS = """
import json, sys
import two_kernels as k
first = sys.argv[1]
values = [k.outer(3.0), k.inner(3.0)] if first == "outer" else [k.inner(3.0), k.outer(3.0)]
print(json.dumps({"values": values, "outer_hits": sum(k.outer.stats.cache_hits.values()),
                  "copy_hits": sum(k.inner.from_python().stats.cache_hits.values())}))
"""


@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="no machine code without the JIT")
def test_a_callee_called_from_python_has_a_cache_of_its_own(tmp_path):
    """A callee is cached without numba's CPython wrapper (``_jit.Kernel``);
    numba's cache index does not tell the two kinds apart, so Python's copy must
    never load it (numba's own call of it would crash the process)."""
    (tmp_path / "two_kernels.py").write_text(TWO_KERNELS)
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"),
           "PYTHONPATH": os.pathsep.join([str(tmp_path), str(PACKAGE.parent)])}
    runs = []
    for first in ("outer", "inner", "outer"):  # compiled, then each loaded from the cache
        done = subprocess.run([sys.executable, "-c", CALLS, first], cwd=tmp_path, env=env,
                              capture_output=True, text=True, timeout=120)
        assert done.returncode == 0, done.stderr
        runs.append(json.loads(done.stdout.splitlines()[-1]))
    for run, first in zip(runs, ("outer", "inner", "outer"), strict=True):
        assert run["values"] == ([6.0, 7.0] if first == "outer" else [7.0, 6.0])
    assert [run["outer_hits"] for run in runs] == [0, 1, 1]
    assert [run["copy_hits"] for run in runs] == [0, 1, 1]  # Python's copy is cached too


def test_a_solve_calls_only_the_entry_kernels_from_python():
    """Every kernel the Python layer calls is compiled with the CPython wrapper
    (``jit(entry=True)``): a call of any other goes to a second compilation."""
    before = _jit.CALLS_FROM_PYTHON.copy()
    for scene in ("j125", "s67_3d", "s67_rollers"):
        result = pf.solve(pf.load_case(EXAMPLES / f"{scene}.toml"))
        result.profile  # noqa: B018 (built when read)
    assert _jit.CALLS_FROM_PYTHON == before


def test_a_kernel_says_whether_it_allocates():
    def kernel(x):
        return x

    with pytest.raises(TypeError, match="whether it allocates"):
        _jit.jit(kernel)
    inner = _jit.jit(kernel, _nrt=False)
    assert inner.targetoptions["_nrt"] is False
    entry = _jit.jit(kernel, entry=True, _nrt=False)
    # no C wrapper; Python's wrapper for the entries only
    assert inner.targetoptions["no_cfunc_wrapper"] and entry.targetoptions["no_cfunc_wrapper"]
    assert inner.targetoptions["no_cpython_wrapper"] and isinstance(inner, _jit.Kernel)
    assert not entry.targetoptions["no_cpython_wrapper"] and not isinstance(entry, _jit.Kernel)
    assert "_nrt" not in _jit.phase(kernel).targetoptions  # inlined: its caller's


RESIDUAL_FIRST = """
import numpy as np
import pipelay_fast as pf
from pipelay_fast.engine.problem import build_problem
from pipelay_fast.kernels.system import system_2d
pb = build_problem(pf.load_case(__import__("sys").argv[1]))
g, nb = np.zeros_like(pb.u), pb.bnodes.size
system_2d(pb.s_el, pb.u, pb.model(), np.zeros(pb.nn - 1), np.zeros((2, 2)).T, g,
          pb.kernel_ends(np.zeros_like(pb.u)), False, np.zeros((nb, pb.nn)),
          np.full(nb, -1, dtype=np.int64), np.zeros((nb, 1)))
print(float(np.abs(g).max()))
"""


@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="no machine code without the JIT")
def test_the_residual_compiles_before_the_newton_kernel(tmp_path):
    """``system_2d`` compiles the residual's kernels (``_system``, the
    element) before the Newton kernel: a kernel compiled first from a
    caller with another reference-counting setting inherits it (an
    allocating one then failed to compile, and every solve of the process
    after it)."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    done = subprocess.run([sys.executable, "-c", RESIDUAL_FIRST, str(EXAMPLES / "s67.toml")],
                          env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert float(done.stdout.splitlines()[-1]) > 0.0  # the guess is out of balance


@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="no machine code without the JIT")
def test_a_compile_leaves_the_collectors_frozen_objects_as_they_were():
    """An entry's compile freezes the objects before it out of the cyclic
    collector's reach and unfreezes them when it returns; a program's own
    frozen objects stay frozen, none added."""
    import gc

    def kernel(x):
        return x + 1

    entry = _jit.jit(kernel, entry=True, _nrt=False, cache=False)
    assert isinstance(entry, _jit.Entry)
    assert gc.get_freeze_count() == 0
    assert entry(1) == 2
    assert gc.get_freeze_count() == 0
    gc.freeze()
    try:
        frozen = gc.get_freeze_count()
        assert entry(1.5) == 2.5  # a new signature: a compile
        # none of the compiler's objects frozen (a few of the program's freed)
        assert 0.99 * frozen < gc.get_freeze_count() <= frozen
    finally:
        gc.unfreeze()

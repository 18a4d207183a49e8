"""A first compile in two processes (``pipelay_fast.engine.cobuild``): the
helper compiles exactly the signatures the solving process needs, which then
loads them from the cache, and the answer is the same to the bit."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numba
import pytest

from tests.helpers import EXAMPLES

# A first solve in a fresh cache. "plain": no helper. "helper": the helper
# started as the solve starts it, and waited for before the Newton kernel
# compiles, so that it has compiled all it would: the solving process then
# compiles only the Newton kernel itself, the rest loaded from the cache.
SOLVE = """
import hashlib, json, sys
import numpy as np
from numba.core import event
from numba.core.caching import NullCache
import pipelay_fast as pf
from pipelay_fast.engine import cobuild

mode, case_file = sys.argv[1:3]
start = cobuild.start
started = []

def start_and_wait(module, name, scene, args):
    if mode == "plain":
        return None
    proc = start(module, name, scene, args)
    started.append(proc.wait(timeout=1200))
    return None

cobuild.start = start_and_wait
compiled = []  # pipelay_fast's cached kernels the solve compiles: (name, inside Newton's compile)
newton = []  # the Newton kernel's compile in progress

class Compiles(event.Listener):
    def on_start(self, ev):
        d = ev.data["dispatcher"]
        name = d.py_func.__qualname__
        if d.py_func.__module__.startswith("pipelay_fast") and not isinstance(d._cache, NullCache):
            compiled.append((name, bool(newton)))
        if name.startswith("_newton_kernel"):
            newton.append(name)

    def on_end(self, ev):
        if ev.data["dispatcher"].py_func.__qualname__.startswith("_newton_kernel"):
            newton.pop()

event.register("numba:compile", Compiles())
result = pf.solve(pf.load_case(case_file))
digest = hashlib.sha256()
for key in sorted(result.columns):
    column = np.asarray(result.columns[key])
    data = column.tobytes() if column.dtype.kind in "fiub" else repr(column.tolist()).encode()
    digest.update(key.encode() + data)
summary = {k: v for k, v in result.summary.items() if k != "solve_seconds"}
print(json.dumps({"digest": digest.hexdigest(), "summary": repr(summary),
                  "compiled": compiled, "helper": started}))
"""


def _first_solve(mode: str, case: str, cache) -> dict:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    done = subprocess.run([sys.executable, "-c", SOLVE, mode, str(EXAMPLES / f"{case}.toml")],
                          env=env, capture_output=True, text=True, timeout=1800)
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.splitlines()[-1])


@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="no machine code without the JIT")
def test_the_helper_compiles_the_solves_signatures_and_the_answer_is_the_same(tmp_path):
    plain = _first_solve("plain", "j125", tmp_path / "plain")
    helped = _first_solve("helper", "j125", tmp_path / "helper")
    assert helped["helper"] == [0]  # the helper ran and ended well
    newton = [name for name, _ in plain["compiled"] if name.startswith("_newton_kernel")]
    assert len(newton) == 1
    # without the helper the Newton kernel's compile compiles its callees ...
    assert sum(inside for _, inside in plain["compiled"]) > 10
    # ... with it, none: each is loaded from the helper's cache entry
    assert [name for name, inside in helped["compiled"] if inside] == []
    assert [name for name, _ in helped["compiled"]].count(newton[0]) == 1
    assert helped["digest"] == plain["digest"] and helped["summary"] == plain["summary"]


KERNELS = """
from pipelay_fast.kernels._jit import jit, phase

@jit(_nrt=False)
def leaf(x):
    return 2.0 * x

@jit(by_dimension=True, _nrt=False)
def middle(nd, x):
    return leaf(x) + nd

@phase
def inlined(nd, x):
    return middle(nd, x) + leaf(x)

@jit(entry=True, _nrt=False)
def entry(x, n):
    return inlined(3, x) * n
"""


@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="no machine code without the JIT")
def test_typed_calls_lists_the_compiles_in_order_and_compiles_none(tmp_path, monkeypatch):
    (tmp_path / "cobuild_kernels.py").write_text(KERNELS)
    monkeypatch.syspath_prepend(str(tmp_path))
    import cobuild_kernels as k
    from numba.core import types

    from pipelay_fast.engine import cobuild

    calls = cobuild.typed_calls(k.entry, (types.float64, types.int64))
    names = [c.kernel.py_func.__name__ for c in calls]
    assert names == ["leaf", "middle", "entry"]  # callees first, the phase inlined
    assert [c.callees for c in calls] == [[], [0], [0, 1]]
    assert calls[1].args == (types.literal(3), types.float64)  # nd kept literal
    assert not any(c.kernel.overloads for c in calls)  # typed, not compiled
    assert cobuild.build(calls) == 2  # all but the entry, whose compile then loads them
    assert all(c.kernel.overloads for c in calls[:2]) and not k.entry.overloads
    assert k.entry(1.5, 2) == 2 * (2 * 1.5 + 3 + 2 * 1.5)
    assert len(k.middle.overloads) == 1 and len(k.entry.overloads) == 1

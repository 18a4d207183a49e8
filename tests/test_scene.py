"""The Newton kernel compiled per scene family (``pipelay_fast.kernels.scene``):
a family leaves out the code of the features its scenes lack, is cached
apart from the others, and gives the same answers as every feature."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numba
import numpy as np
import pytest

import pipelay_fast as pf
from pipelay_fast.engine import problem
from pipelay_fast.engine.model import scene_of
from pipelay_fast.kernels.scene import ALL, Scene, in_scene, tag
from tests.helpers import EXAMPLES

PACKAGE = Path(pf.__file__).resolve().parent

# a feature's code behind a flag, one level down from the entry
FEATURE_KERNELS = """
from pipelay_fast.kernels._jit import jit, phase
from pipelay_fast.kernels.scene import FRICTION

@jit(_nrt=False)
def feature(x):
    return 10.0 * x

@phase
def step(x):
    y = x + 1.0
    if FRICTION:
        y += feature(x)
    return y

@jit(_nrt=False)
def inner(x):
    return 2.0 * step(x)

@jit(entry=True, _nrt=False)
def outer(x):
    return inner(x) - 1.0

@jit(entry=True, _nrt=False)
def plain(x):
    return x + 0.5
"""

CALLS = """
import json, sys
import feature_kernels as k
from pipelay_fast.kernels.scene import ALL, Scene, in_scene
scene = ALL if sys.argv[1] == "all" else Scene(friction=False, stinger=True)
entry = in_scene(k.outer, scene)
value = entry(3.0)
print(json.dumps({"value": value, "hits": sum(entry.stats.cache_hits.values()),
                  "feature_compiled": len(k.feature.signatures),
                  "plain_shared": in_scene(k.plain, scene) is k.plain}))
"""


@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="no machine code without the JIT")
def test_a_family_compiles_none_of_a_missing_features_code_and_is_cached_apart(tmp_path):
    """Without friction the flag's branch, inlined from a phase, is pruned and
    the kernel it calls is never compiled; each family has its own cache
    entry, loaded by the next process, whichever family was compiled first."""
    (tmp_path / "feature_kernels.py").write_text(FEATURE_KERNELS)
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"),
           "PYTHONPATH": os.pathsep.join([str(tmp_path), str(PACKAGE.parent)])}
    runs = []
    for family in ("without", "all", "without", "all"):
        done = subprocess.run([sys.executable, "-c", CALLS, family], cwd=tmp_path, env=env,
                              capture_output=True, text=True, timeout=120)
        assert done.returncode == 0, done.stderr
        runs.append(json.loads(done.stdout.splitlines()[-1]))
    # 2 (x + 1) - 1, and with the feature 2 (x + 1 + 10 x) - 1, at x = 3
    assert [run["value"] for run in runs] == [7.0, 67.0, 7.0, 67.0]
    assert [run["hits"] for run in runs] == [0, 0, 1, 1]
    assert runs[0]["feature_compiled"] == 0 and runs[1]["feature_compiled"] == 1
    assert all(run["plain_shared"] for run in runs)  # reads no flag: one kernel for all


def test_the_scene_of_each_example():
    """Friction where a coefficient acting in the case's dimension is above 0
    (the examples' axial one is 0, their lateral one 0.5: 3D only); the
    stinger in S-lay, rollers included."""
    expect = {"j125": Scene(False, False), "j125_3d": Scene(True, False),
              "s67": Scene(False, True), "s67_3d": Scene(True, True),
              "s67_rollers": Scene(False, True)}
    for name, scene in expect.items():
        case = pf.load_case(EXAMPLES / f"{name}.toml")
        assert case.seabed.axial_friction == 0.0 and case.seabed.lateral_friction > 0.0
        assert scene_of(case) == scene, name
    assert tag(ALL) == "" and tag(Scene(False, True)) == "without_friction"
    assert tag(Scene(False, False)) == "without_friction_stinger"


@pytest.mark.parametrize("name", ["j125", "j125_3d", "s67"])
def test_a_family_gives_the_answer_of_every_feature_to_the_bit(name, monkeypatch):
    """The case solved with its family's kernels and with every feature's
    (ALL) gives the same numbers, to the bit."""
    case = pf.load_case(EXAMPLES / f"{name}.toml")
    assert scene_of(case) != ALL
    family = pf.solve(case)
    monkeypatch.setattr(problem, "scene_of", lambda case: ALL)
    every = pf.solve(case)
    assert family.state.scene == scene_of(case) and every.state.scene == ALL

    def timeless(summary):  # (the solve's time apart; NaN equal to NaN)
        return {k: v for k, v in summary.items() if k != "solve_seconds"}

    np.testing.assert_equal(timeless(family.summary), timeless(every.summary))
    assert family.columns.keys() == every.columns.keys()
    for key, column in family.columns.items():
        np.testing.assert_array_equal(column, every.columns[key], err_msg=f"{name} {key}")


def test_a_kernel_reading_no_flag_is_shared():
    from pipelay_fast.kernels import banded, newton

    scene = Scene(False, False)
    assert in_scene(banded.band_factor, scene) is banded.band_factor
    assert in_scene(newton.newton_2d, ALL) is newton.newton_2d
    if not numba.config.DISABLE_JIT:
        copy = in_scene(newton.newton_2d, scene)
        assert copy is not newton.newton_2d and copy is in_scene(newton.newton_2d, scene)
        assert copy.py_func.__qualname__.endswith("__without_friction_stinger")


def test_a_sweeps_cases_share_one_kernel_per_dimension():
    """A sweep compiles each dimension's cases with the features any of them
    has (study.runner.sweep_scenes), within engine.model.shared_scenes only."""
    from types import SimpleNamespace

    from pipelay_fast.engine.model import shared_scenes
    from pipelay_fast.study.runner import sweep_scenes

    cases = {name: pf.load_case(EXAMPLES / f"{name}.toml")
             for name in ("j125", "s67", "j125_3d", "s67_3d")}
    chain = [SimpleNamespace(case=cases["j125"]), SimpleNamespace(case=None)]
    mixed = [SimpleNamespace(case=cases["s67"]), SimpleNamespace(case=cases["j125_3d"])]
    tasks = [[chain], [mixed]]
    scenes = sweep_scenes(tasks)
    assert scenes == {2: Scene(False, True), 3: Scene(True, False)}
    assert sweep_scenes([[chain]]) == {2: Scene(False, False)}
    with shared_scenes(scenes):
        assert scene_of(cases["j125"]) == Scene(False, True)  # the 2D sweep's stinger
        assert scene_of(cases["s67_3d"]) == ALL  # its own features kept
        with shared_scenes({}):
            assert scene_of(cases["j125"]) == Scene(False, False)
        assert scene_of(cases["j125"]) == Scene(False, True)
    assert scene_of(cases["j125"]) == Scene(False, False)


def test_shared_scenes_are_per_thread():
    """Two threads of one process (dask's threaded workers) in shared_scenes
    at once, the first leaving first: each sees its own scenes, and none is
    left behind in either thread or the main one (with one dictionary for the
    process, the second thread restored the first's scenes on leaving)."""
    import threading

    from pipelay_fast.engine.model import shared_scenes

    j125 = pf.load_case(EXAMPLES / "j125.toml")
    own, seen = scene_of(j125), {}
    a_in, b_in, a_out = threading.Event(), threading.Event(), threading.Event()

    def first():
        with shared_scenes({2: ALL}):
            a_in.set()
            b_in.wait(10)
            seen["first"] = scene_of(j125)
        a_out.set()
        seen["first after"] = scene_of(j125)

    def second():
        a_in.wait(10)
        with shared_scenes({2: Scene(False, True)}):
            b_in.set()
            a_out.wait(10)
            seen["second"] = scene_of(j125)
        seen["second after"] = scene_of(j125)

    threads = [threading.Thread(target=first), threading.Thread(target=second)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(20)
    assert seen == {"first": ALL, "second": Scene(False, True),
                    "first after": own, "second after": own}
    assert scene_of(j125) == own == Scene(False, False)

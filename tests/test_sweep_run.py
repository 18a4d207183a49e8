"""Running sweeps: workers, the Parquet dataset, failures, resuming, backends, choice of a.

The sweep (coarse 8 m mesh, a few seconds) mixes a J-lay current chain, a
J-lay scene in 3D, an S67 chain over a, and two impossible cases: a negative
bottom tension and a concave-up stinger (a > 0). Summaries are checked
against ``pf.solve`` of the same cases run here directly.
"""

from __future__ import annotations

import io
import math
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

import pipelay_fast as pf
from pipelay_fast.cli import main
from pipelay_fast.output.io import read_units
from pipelay_fast.study import runner
from pipelay_fast.study.dataset import read_profiles, read_summary
from pipelay_fast.study.runner import progress_bar, run_sweep
from pipelay_fast.study.sweep import chains
from pipelay_fast.study.sweep_file import load_sweep

ROOT = Path(__file__).resolve().parents[1]
SPEC = {
    "name": "tiny",
    "set": {"solver.element_length": 8.0},
    "vary": {"current_speed": [0.0, 0.5, 1.0]},
    "scenes": [
        {"name": "J125", "case": "j125",
         "vary": {"bottom_tension": [-1e4, 2.5e5, 3.5e5]}},
        {"name": "J125_3d", "case": "j125_3d", "set": {"seabed.lateral_friction": 0.0},
         "vary": {"current_speed": [0.5, 1.0]}},
        {"name": "S67", "case": "s67", "reference_a": -0.0012,
         "vary": {"current_speed": [1.0], "a": [-0.0011, -0.0012, 0.02, -0.0013]}},
    ],
}
TIMING = ["solve_seconds"]  # wall-clock columns: differ between any two runs


@pytest.fixture(scope="module")
def sweep():
    return load_sweep(SPEC)


@pytest.fixture(scope="module")
def one_worker(sweep, tmp_path_factory):
    out = tmp_path_factory.mktemp("one") / "results"
    report = run_sweep(sweep, out, workers=1, chunk_size=4, progress=False)
    return out, report


@pytest.fixture(scope="module")
def two_workers(sweep, tmp_path_factory):
    out = tmp_path_factory.mktemp("two") / "results"
    report = run_sweep(sweep, out, workers=2, chunk_size=4, progress=False)
    return out, report


def by_case(out) -> pd.DataFrame:
    return read_summary(out).drop(columns=TIMING).set_index("case_id").sort_index()


def assert_same_table(left: pd.DataFrame, right: pd.DataFrame):
    """Same case ids and columns, strings equal, numbers equal to 1e-12 (relative)."""
    assert list(left.index) == list(right.index) and list(left.columns) == list(right.columns)
    for column in left.columns:
        a, b = left[column], right[column]
        if a.dtype.kind == "f":
            np.testing.assert_allclose(a, b, rtol=1e-12, atol=0, err_msg=column)
        else:
            assert a.astype(str).tolist() == b.astype(str).tolist(), column


def test_one_and_two_workers_give_the_same_summary(sweep, one_worker, two_workers):
    (out1, report1), (out2, report2) = one_worker, two_workers
    n = len(sweep.cases())
    assert report1.solved == report2.solved == n and report1.skipped == 0
    assert len(report2.worker_pids) == 2 and os.getpid() not in report2.worker_pids
    left, right = by_case(out1), by_case(out2)
    assert len(left) == n and left.index.is_unique
    assert_same_table(left, right)


def test_a_cold_cache_puts_one_task_of_each_dimension_first(sweep):
    tasks = runner.pack(chains(sweep.cases()), 4)

    def dims(task):
        return {chain[0].case.resolved_dimension for chain in task if chain[0].case is not None}

    ordered, first = runner.compile_first(tasks)
    assert first == 2 and sorted(ordered, key=id) == sorted(tasks, key=id)
    assert ordered[0] is next(t for t in tasks if dims(t)) and dims(ordered[0]) == {"2d"}
    assert ordered[1] is next(t for t in tasks if "3d" in dims(t))
    assert ordered[2:] == [t for t in tasks if t is not ordered[0] and t is not ordered[1]]
    planar = [t for t in tasks if "3d" not in dims(t)]
    assert runner.compile_first(planar) == (planar, 0)


def test_the_cold_cache_order_gives_the_same_summary(sweep, one_worker, tmp_path, monkeypatch):
    monkeypatch.setattr(runner, "kernels_cached", lambda family=None: False)
    rounds = []
    compile_first = runner.compile_first

    def recorded(tasks):
        ordered, first = compile_first(tasks)
        rounds.append(first)
        return ordered, first

    monkeypatch.setattr(runner, "compile_first", recorded)
    report = run_sweep(sweep, tmp_path / "results", workers=2, chunk_size=4, progress=False)
    assert rounds == [2] and report.solved == len(sweep.cases())
    assert_same_table(by_case(tmp_path / "results"), by_case(one_worker[0]))


def test_summary_equals_direct_solves_along_each_chain(sweep, one_worker):
    """Each chain replayed with pf.solve (warm from the previous case) gives the
    sweep's rows; its first case is a plain cold pf.solve."""
    table = by_case(one_worker[0])
    for chain in chains(sweep.cases()):
        previous = None
        for position, sc in enumerate(chain):
            if sc.case is None:
                continue
            warm = previous if previous is not None and \
                previous.summary["dimension"] == sc.case.resolved_dimension else None
            result = pf.solve(sc.case, warm=warm)
            previous = result
            row = table.loc[sc.case_id]
            assert row["warm_started"] == (warm is not None)
            assert row["warm_started"] or position == 0 or chain[position - 1].case is None
            for name, value in result.summary.items():
                if name in TIMING or name == "case_id":
                    continue
                if isinstance(value, float):
                    np.testing.assert_allclose(row[name], value, rtol=1e-12, err_msg=name)
                elif value is None:  # (written as null)
                    assert pd.isna(row[name]), name
                else:
                    assert row[name] == value, name


def test_impossible_cases_fail_alone_with_their_message(sweep, one_worker):
    table = read_summary(one_worker[0])
    failed = table[table["status"] == "failed"]
    assert len(table) == len(sweep.cases())
    negative = failed[failed["given_bottom_tension"] == -1e4]
    dip = failed[failed["a"] == 0.02]
    assert len(negative) == 3 and len(dip) == 1 and len(failed) == 4
    assert all("lay.bottom_tension = -10000.0 must be positive" in m for m in negative["message"])
    assert "lay.stinger.a = 0.02 must not be positive" in dip["message"].iloc[0]
    assert dip["scene"].iloc[0] == "S67" and dip["method"].iloc[0] == "S"
    assert failed["max_von_mises"].isna().all() and failed["n_elements"].isna().all()
    ok = table[table["status"] == "ok"]
    assert (ok["message"] == "").all() and ok["max_von_mises"].notna().all()
    # the S67 case after the failed one still starts warm from the last solution
    s67 = table[table["scene"] == "S67"].sort_values("chain_position")
    assert s67["warm_started"].tolist() == [False, True, False, True]


def test_every_column_has_its_unit_in_the_schema(one_worker):
    out = one_worker[0]
    files = sorted(out.glob("summary/scene=*/*.parquet")) + sorted(
        out.glob("profiles/scene=*/*.parquet"))
    assert len(files) >= 6
    for path in files:
        schema = pq.read_schema(path)
        units = read_units(path)
        assert set(units) == set(schema.names)
        for field in schema:
            assert field.metadata[b"unit"].decode() == units[field.name]
    summary = read_units(next(out.glob("summary/scene=S67/*.parquet")))
    assert (summary["a"], summary["max_von_mises"], summary["given_bottom_tension"],
            summary["current_heading_deg"]) == ("1/m", "Pa", "N", "deg")
    profile = read_units(next(out.glob("profiles/scene=S67/*.parquet")))
    assert (profile["von_mises"], profile["z"], profile["case_id"]) == ("Pa", "m", "")


def test_pandas_and_duckdb_read_partitions(sweep, one_worker):
    duckdb = pytest.importorskip("duckdb", reason="duckdb is in the test extra")
    out = one_worker[0]
    expected = {c.case_id for c in sweep.cases() if c.scene == "S67"}
    s67 = pd.read_parquet(out / "summary", filters=[("scene", "=", "S67")])
    assert set(s67["case_id"]) == expected and len(s67) == len(expected)
    both = pd.read_parquet(out / "summary", filters=[("scene", "in", ["S67", "J125_3d"]),
                                                     ("status", "=", "ok")])
    assert sorted(both["scene"].astype(str).unique()) == ["J125_3d", "S67"]
    assert len(both) == 3 + 2
    sql = duckdb.sql(
        f"SELECT case_id, dimension FROM read_parquet('{out}/summary/*/*.parquet', "
        "hive_partitioning = true) WHERE scene = 'J125_3d'").df()
    expected_3d = {c.case_id for c in sweep.cases() if c.scene == "J125_3d"}
    assert set(sql["case_id"]) == expected_3d and set(sql["dimension"]) == {"3d"}
    nodes = duckdb.sql(
        f"SELECT s.case_id, count(*) AS nodes, any_value(s.n_elements) AS n_elements "
        f"FROM read_parquet('{out}/profiles/*/*.parquet', hive_partitioning = true) p "
        f"JOIN read_parquet('{out}/summary/*/*.parquet', hive_partitioning = true) s "
        "USING (case_id) WHERE p.scene = 'S67' GROUP BY s.case_id").df()
    assert len(nodes) == 3 and (nodes["nodes"] == nodes["n_elements"] + 1).all()
    profile = read_profiles(out, filters=[("scene", "=", "J125_3d")])
    assert set(profile["case_id"]) == expected_3d
    assert (profile.groupby("case_id")["node"].min() == 0).all()


def test_rerun_skips_what_is_written(sweep, tmp_path):
    out = tmp_path / "results"
    run_sweep(sweep, out, workers=1, progress=False)
    stamps = {p: p.stat().st_mtime_ns for p in out.rglob("*.parquet")}
    again = run_sweep(sweep, out, workers=1, progress=False)
    assert (again.solved, again.skipped, again.chunks) == (0, len(sweep.cases()), 0)
    assert {p: p.stat().st_mtime_ns for p in out.rglob("*.parquet")} == stamps


KILL_SWEEP = """\
name = "killed"
case = "j125"
[set]
"solver.element_length" = 1.0
[vary]
current_speed = [0.2, 0.6, 1.0]
top_tension = { start = 5.0e5, stop = 6.4e5, num = 8 }
"""


def test_killed_sweep_resumes_without_recomputing_or_duplicates(tmp_path):
    path, out = tmp_path / "killed.toml", tmp_path / "results"
    path.write_text(KILL_SWEEP)
    total = len(load_sweep(path).cases())
    command = [sys.executable, "-m", "pipelay_fast", "sweep", str(path), "--out", str(out),
               "--workers", "1", "--chunk-size", "3", "--quiet"]
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 120
    try:
        while not list(out.glob("summary/scene=*/*.parquet")):
            assert process.poll() is None, process.stderr.read().decode()
            assert time.monotonic() < deadline, "no chunk written in 120 s"
            time.sleep(0.005)
        process.send_signal(signal.SIGKILL)
    finally:
        process.wait(timeout=60)
        process.stderr.close()
    assert process.returncode == -signal.SIGKILL
    first = {p: p.stat().st_mtime_ns for p in out.glob("summary/scene=*/*.parquet")}
    written = len(read_summary(out))
    assert 0 < written < total  # killed part way

    report = run_sweep(load_sweep(path), out, workers=1, progress=False)
    assert report.skipped == written and report.solved == total - written
    table = read_summary(out)
    assert len(table) == total and table["case_id"].is_unique
    assert (table["status"] == "ok").all()
    for chunk, stamp in first.items():  # the finished chunks were not rewritten
        assert chunk.stat().st_mtime_ns == stamp
    profiles = read_profiles(out)
    assert profiles.groupby("case_id").size().sum() == len(profiles)
    assert set(profiles["case_id"]) == set(table["case_id"])
    nodes = profiles.groupby("case_id")["node"].nunique().sort_index()
    assert nodes.tolist() == (table.set_index("case_id")["n_elements"] + 1).sort_index().tolist()
    assert not list(out.rglob("*.tmp")) and not (out / ".lock").exists()


def test_dask_backend_gives_the_loky_table(sweep, two_workers, tmp_path):
    pytest.importorskip("distributed", reason="dask.distributed is the optional 'dask' extra")
    from distributed import Client, LocalCluster

    out = tmp_path / "results"
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                      dashboard_address=None) as cluster, Client(cluster):
        report = run_sweep(sweep, out, workers=2, backend="dask", chunk_size=4, progress=False)
    assert report.solved == len(sweep.cases())
    assert_same_table(by_case(out), by_case(two_workers[0]))


def test_ray_backend_gives_the_loky_table(sweep, two_workers, tmp_path):
    """Ray started by the run on 2 CPUs (tasks dispatched in rounds: Ray's joblib
    backend does not stream results) gives the loky rows, and is shut down after."""
    ray = pytest.importorskip("ray", reason="Ray is the optional 'ray' extra (and in 'test')")
    out = tmp_path / "results"
    try:
        report = run_sweep(sweep, out, workers=2, backend="ray", chunk_size=4, progress=False)
        assert not ray.is_initialized()
    finally:
        ray.shutdown()  # left running only if the run failed
    assert report.solved == len(sweep.cases())
    assert os.getpid() not in report.worker_pids
    assert_same_table(by_case(out), by_case(two_workers[0]))


def test_progress_in_a_log_is_sparse_lines_with_the_failed_count(sweep, tmp_path, capsys):
    """stderr not a terminal (captured here): one line at the start, one at the
    end and one per 10 s at most between, none redrawn with a carriage return;
    the last counts every case, the 4 impossible ones failed, and no time left."""
    start = time.perf_counter()
    run_sweep(sweep, tmp_path / "results", workers=1, chunk_size=4)
    seconds = time.perf_counter() - start
    err = capsys.readouterr().err
    n = len(sweep.cases())
    assert "\r" not in err and err.endswith("\n")
    lines = err.splitlines()
    assert 2 <= len(lines) <= 2 + seconds // 10
    assert all(len(line) <= 80 for line in lines)
    assert re.fullmatch(rf"  0%\|\s+\| 0/{n} \[00:00<\?, \? cases/s, failed=0\]", lines[0])
    assert re.fullmatch(rf"100%\|#+\| {n}/{n} \[\d\d:\d\d<00:00, +[\d.]+ cases/s, failed=4\]",
                        lines[-1]), lines[-1]


def test_progress_on_a_terminal_is_redrawn_in_place(monkeypatch):
    monkeypatch.setattr(runner, "_terminal", lambda stream: True)
    stream = io.StringIO()
    with progress_bar(10, stream=stream) as bar:
        bar.set_postfix(failed=1, refresh=False)
        bar.update(4)
        bar.set_postfix(failed=2, refresh=False)
        bar.update(6)
    draws = stream.getvalue().split("\r")
    assert draws[0] == "" and len(draws) >= 3  # the first draw and the last, each after a \r
    assert " 10/10 [" in draws[-1] and draws[-1].rstrip().endswith("failed=2]")
    assert draws[-1].endswith("\n") and "\n" not in "".join(draws[:-1])


def test_select_finds_the_equal_peaks_and_the_stress_minimum(one_worker, capsys):
    out = one_worker[0]
    assert main(["select", str(out)]) == 0
    printed = capsys.readouterr().out
    table = pd.read_parquet(out / "selection.parquet")
    assert read_units(out / "selection.parquet")["a_equal_peaks"] == "1/m"
    (row,) = table.itertuples()  # one S-lay scene, one current
    assert (row.scene, row.n_grid, row.reference_a) == ("S67", 3, -0.0012)
    assert "S67" in printed and "-0.001200" in printed

    grid = read_summary(out, filters=[("scene", "=", "S67"), ("status", "=", "ok")])
    gap = grid["overbend_max_von_mises"] - grid["sagbend_max_von_mises"]
    crossing = np.flatnonzero(np.diff(np.sign(gap.to_numpy())))
    assert len(crossing) == 1
    lo, hi = sorted(grid["a"].iloc[crossing[0]:crossing[0] + 2])
    assert lo < row.a_equal_peaks < hi
    case = pf.load_case(ROOT / "pipelay_fast" / "examples" / "s67.toml").with_changes(
        {"solver.element_length": 8.0, "lay.stinger.a": row.a_equal_peaks})
    at_root = pf.solve(case).summary
    peak = at_root["sagbend_max_von_mises"]
    assert abs(at_root["overbend_max_von_mises"] - peak) < 1e-4 * peak
    assert math.isclose(row.equal_peaks_von_mises, at_root["max_von_mises"], rel_tol=1e-6)
    # the lay's answers there (the example's [checks])
    assert math.isclose(row.equal_peaks_max_utilisation, at_root["max_utilisation"], rel_tol=1e-6)
    # (a 0.3 mm clearance, a cubic of the distance to lift-off: the warm and
    # cold solves of the refinement differ by under a micrometre)
    assert math.isclose(row.equal_peaks_tip_clearance, at_root["tip_clearance"], abs_tol=1e-5)
    # the refined stress minimum is no worse than the best grid point
    assert row.min_max_von_mises <= grid["max_von_mises"].min()
    assert grid["a"].min() <= row.a_min_stress <= grid["a"].max()


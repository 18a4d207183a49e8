"""Sweep throughput: cases per second on worker processes, warm chains against
cold solves, and the share of the time the sweep layer itself takes.

    python benchmarks/bench_sweep.py [--workers 2] [--cases 1200] [--no-profiles]

Scenes: J125 at the 8 m element length (0.03 % stress error, README), 2D
(current along the lay) and 3D (current across it, frictionless seabed: the
friction slip path is timed separately with --friction, few cases, as it is far
slower). Each sweep varies the surface current (the chain axis, 20 values) and
the top tension. Compilation and worker start-up are done and timed first; the
throughput runs then reuse the same warm workers. Every run writes a fresh
dataset (summary and profiles) into a temporary directory.

Overhead of the sweep layer = 1 - (time in pf.solve summed over workers) /
(workers x wall time): building the cases, scheduling, encoding the Parquet
chunks (in the workers), moving them to the parent, writing them, and idle
workers. "CPU overhead %" is the same from processor times (1 - CPU time in
pf.solve / CPU time of the workers' tasks and the parent): it leaves out idle
workers and is not skewed by other programs on the machine. "write %" is the
parent's share of the wall time spent writing files.
"""

from __future__ import annotations

import argparse
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import joblib
import numba
import numpy as np
import pandas as pd
import pyarrow

import pipelay_fast as pf
from pipelay_fast.study.runner import run_sweep
from pipelay_fast.study.sweep_file import load_sweep

ROOT = Path(__file__).resolve().parents[1]


def scene_sweep(dimension: str, n_cases: int, friction: bool = False):
    speeds = [round(0.05 * (i + 1), 2) for i in range(20)]  # m/s, the chain axis
    tensions = np.linspace(450e3, 700e3, max(1, n_cases // len(speeds)))
    scene = {"name": f"J125_{dimension}", "case": "j125",
             "set": {"environment.current.heading": 0.0 if dimension == "2d" else 90.0,
                     "seabed.lateral_friction": 0.5 if friction else 0.0}}
    return load_sweep({"name": f"bench_{dimension}", "set": {"solver.element_length": 8.0},
                       "vary": {"current_speed": speeds, "top_tension": tensions.tolist()},
                       "scenes": [scene]})


def timed_run(sweep, workers, profiles, warm_start=True):
    with tempfile.TemporaryDirectory() as folder:
        report = run_sweep(sweep, Path(folder) / "out", workers=workers, profiles=profiles,
                           progress=False, warm_start=warm_start)
    assert report.failed == 0, f"{report.failed} cases failed"
    return report


def machine() -> str:
    try:
        rev = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, text=True,
                             capture_output=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--", "pipelay_fast"],
                               cwd=ROOT, text=True, capture_output=True).stdout.strip()
        rev += " (pipelay_fast modified)" if dirty else ""
    except (OSError, subprocess.CalledProcessError):
        rev = "unknown"
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as info:
            cpu = next(line.split(":", 1)[1].strip() for line in info
                       if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    return (f"{cpu}, {os.cpu_count()} cpus, {platform.platform()}\n"
            f"Python {platform.python_version()}, pipelay_fast {pf.__version__}, numba "
            f"{numba.__version__}, numpy {np.__version__}, pandas {pd.__version__}, pyarrow "
            f"{pyarrow.__version__}, joblib {joblib.__version__}; git {rev}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--cases", type=int, default=1200, help="cases per sweep (>= 1000)")
    parser.add_argument("--no-profiles", action="store_true", help="summary table only")
    parser.add_argument("--friction", type=int, default=0, metavar="N",
                        help="also time N 3D cases on the friction slip path")
    args = parser.parse_args(argv)
    profiles = not args.no_profiles
    print(machine())
    print(f"workers: {args.workers}, profiles written: {profiles}\n")

    t0 = time.perf_counter()
    for dimension in ("2d", "3d"):  # compile (or load from cache) in this process
        timed_run(scene_sweep(dimension, 20), 1, False)
    compile_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    for dimension in ("2d", "3d"):  # start the workers, each loads its kernels once
        timed_run(scene_sweep(dimension, 4 * 20 * args.workers), args.workers, False)
    start_s = time.perf_counter() - t0
    print(f"compile/load in this process: {compile_s:.1f} s; worker start-up and kernel "
          f"load: {start_s:.1f} s (not in the figures below)\n")

    rows = []
    runs = [(d, w, True) for d in ("2d", "3d") for w in (1, args.workers)]
    runs += [(d, args.workers, False) for d in ("2d", "3d")]
    for dimension, workers, warm in runs:
        sweep = scene_sweep(dimension, args.cases)
        report = timed_run(sweep, workers, profiles, warm)
        rows.append({
            "scene": f"J125 {dimension}", "chains": "warm" if warm else "cold",
            "workers": workers, "cases": report.solved, "wall s": report.seconds,
            "cases/s": report.solved / report.seconds,
            "ms/solve": 1e3 * report.solve_seconds / report.solved,
            "overhead %": 100 * report.overhead_share,
            "CPU overhead %": 100 * report.cpu_overhead_share,
            "write %": 100 * report.write_seconds / report.seconds,
        })
        print(f"  {rows[-1]['scene']} {rows[-1]['chains']:<4} x{workers}: "
              f"{rows[-1]['cases/s']:.0f} cases/s", file=sys.stderr)
    if args.friction:
        sweep = load_sweep({"name": "bench_friction", "set": {"solver.element_length": 8.0},
                            "case": "j125_3d",
                            "vary": {"current_speed": [round(0.1 * (i + 1), 1) for i in
                                                       range(10)],
                                     "top_tension": np.linspace(500e3, 650e3, max(
                                         1, args.friction // 10)).tolist()}})
        report = timed_run(sweep, args.workers, profiles)
        rows.append({"scene": "J125 3d friction", "chains": "warm", "workers": args.workers,
                     "cases": report.solved, "wall s": report.seconds,
                     "cases/s": report.solved / report.seconds,
                     "ms/solve": 1e3 * report.solve_seconds / report.solved,
                     "overhead %": 100 * report.overhead_share,
                     "CPU overhead %": 100 * report.cpu_overhead_share,
                     "write %": 100 * report.write_seconds / report.seconds})
    table = pd.DataFrame(rows)
    print("| " + " | ".join(table.columns) + " |")
    print("|" + " --- |" * len(table.columns))
    for row in table.itertuples(index=False):
        cells = [f"{v:.1f}" if isinstance(v, float) else str(v) for v in row]
        print("| " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()

"""Compile time: the first solve in a fresh environment, and a cached start.

    python benchmarks/bench_compile.py [--scenes j125 s67 s67_3d]
    python benchmarks/bench_compile.py --trees BASE NEW [NEW2 ...] [--pairs 3]
    python benchmarks/bench_compile.py --trees BASE NEW --sweep [--pairs 3]

For each scene, two fresh interpreters in turn, sharing one NUMBA_CACHE_DIR
that starts empty: the first compiles every kernel the scene's solve uses
(*first*), the second loads them from the cache (*cached*). Each reports the
import and the first solve apart, as wall-clock and as the process's CPU
seconds (``time.process_time``, all threads): compilation is CPU-bound, so
the CPU seconds depend much less on other load on the machine (the table
gives the load average over each run, and the CPU seconds of the solving
process's own child processes apart). Scenes are
compiled into caches of their own, so a 3D scene's figure does not include
the planar kernels. Machine and versions are printed with the table
(markdown on stdout).

With ``--trees``, each directory holding a ``pipelay_fast`` package (a git
worktree each) is run with ``PYTHONPATH`` set to it, first solves only, in
``--pairs`` rounds that interleave the trees (A, B, A, B, ...) so that a
drift in the machine's load falls on all of them; the table gives the
medians over the rounds and each tree's ratio to the first. With
``--sweep``, each round runs the README's main job instead,
``pipelay-fast sweep sweeps/paper.toml`` on its default 2 workers into a
fresh results directory and a fresh cache: its wall-clock seconds, and the
CPU seconds of the command and its worker processes (``RUSAGE_CHILDREN``).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench_jlay import STARTUP_SCRIPT, check_imported, machine_info

import pipelay_fast as pf

EXAMPLES = Path(pf.__file__).parent / "examples"


def startup(case_file: Path, cache_dir: str, tree: Path | None = None) -> dict:
    """Import and first-solve seconds (wall and CPU) of a fresh interpreter using ``cache_dir``."""
    env = {**os.environ, "NUMBA_CACHE_DIR": cache_dir}
    if tree is not None:
        env["PYTHONPATH"] = str(tree)
    out = subprocess.run([sys.executable, "-c", STARTUP_SCRIPT, str(case_file)], env=env,
                         cwd=tree, capture_output=True, text=True, check=True).stdout
    answer = json.loads(out.strip().splitlines()[-1])
    if tree is not None:
        check_imported(tree, answer["file"])
    return answer


SWEEP_SCRIPT = "import sys; from pipelay_fast.cli import main; sys.exit(main(sys.argv[1:]))"


def sweep_run(tree: Path) -> dict:
    """Wall and CPU seconds of the README's main sweep run from ``tree`` in a fresh cache."""
    with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as out:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache, "PYTHONPATH": str(tree)}
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-c", SWEEP_SCRIPT, "sweep", "sweeps/paper.toml",
                        "--out", os.path.join(out, "paper")], env=env, cwd=tree,
                       capture_output=True, text=True, check=True)
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    return {"first_solve_s": wall, "first_solve_cpu_s": cpu, "max_rss_mb": after.ru_maxrss / 1024}


def compare_trees(trees: list[Path], scenes: list[str], pairs: int) -> None:
    """Interleaved first solves of ``scenes`` in each tree (the scene "sweep":
    :func:`sweep_run`); medians and ratios to trees[0]."""
    runs = {(scene, i): [] for scene in scenes for i in range(len(trees))}
    for _ in range(pairs):
        for scene in scenes:
            for i, tree in enumerate(trees):
                load = os.getloadavg()[0]
                if scene == "sweep":
                    run = sweep_run(tree)
                else:
                    with tempfile.TemporaryDirectory() as cache:
                        run = startup(EXAMPLES / f"{scene}.toml", cache, tree)
                run["load"] = (load + os.getloadavg()[0]) / 2
                runs[scene, i].append(run)
                print(f"{scene} [{i}]: CPU {run['first_solve_cpu_s']:.1f} s (child processes "
                      f"{run.get('children_cpu_s', 0.0):.1f} s), wall "
                      f"{run['first_solve_s']:.1f} s, peak RSS {run['max_rss_mb']:.0f} MB, "
                      f"load {run['load']:.1f}",
                      file=sys.stderr, flush=True)
    print(f"\n{pairs} interleaved rounds; trees: "
          + ", ".join(f"[{i}] {tree}" for i, tree in enumerate(trees)))
    print("\n| scene | tree | first solve CPU s (median) | / [0] | wall s (median) | / [0] "
          "| CPU s, each round | wall s, each round | child processes' CPU s (median) "
          "| load (1 min, median) | peak RSS MB |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for scene in scenes:
        cpu0 = statistics.median(r["first_solve_cpu_s"] for r in runs[scene, 0])
        wall0 = statistics.median(r["first_solve_s"] for r in runs[scene, 0])
        for i in range(len(trees)):
            cpu = statistics.median(r["first_solve_cpu_s"] for r in runs[scene, i])
            wall = statistics.median(r["first_solve_s"] for r in runs[scene, i])
            each = " ".join(f"{r['first_solve_cpu_s']:.1f}" for r in runs[scene, i])
            walls = " ".join(f"{r['first_solve_s']:.1f}" for r in runs[scene, i])
            kids = statistics.median(r.get("children_cpu_s", 0.0) for r in runs[scene, i])
            load = statistics.median(r["load"] for r in runs[scene, i])
            rss = statistics.median(r["max_rss_mb"] for r in runs[scene, i])
            print(f"| {scene} | [{i}] | {cpu:.1f} | {cpu / cpu0:.3f} | {wall:.1f} | "
                  f"{wall / wall0:.3f} | {each} | {walls} | {kids:.1f} | {load:.1f} | {rss:.0f} |",
                  flush=True)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", nargs="+", default=["j125", "s67", "s67_3d"])
    parser.add_argument("--trees", nargs="+", type=Path, help="source trees to compare")
    parser.add_argument("--pairs", type=int, default=3, help="interleaved rounds with --trees")
    parser.add_argument("--sweep", action="store_true",
                        help="with --trees: the README's main sweep instead of --scenes")
    args = parser.parse_args(argv)
    if args.sweep:
        args.scenes = ["sweep"]
    info = machine_info()
    print("## Machine\n")
    for key, value in info.items():
        print(f"- {key}: {value}")
    if args.trees:
        compare_trees(args.trees, args.scenes, args.pairs)
        return
    print("\n| scene | first: import s | first: solve s | first: solve CPU s "
          "| cached: import s | cached: solve s |")
    print("| --- | --- | --- | --- | --- | --- |")
    for scene in args.scenes:
        with tempfile.TemporaryDirectory() as cache:
            first = startup(EXAMPLES / f"{scene}.toml", cache)
            cached = startup(EXAMPLES / f"{scene}.toml", cache)
        print(f"| {scene} | {first['import_s']:.2f} | {first['first_solve_s']:.1f} | "
              f"{first['first_solve_cpu_s']:.1f} | {cached['import_s']:.2f} | "
              f"{cached['first_solve_s']:.2f} |", flush=True)


if __name__ == "__main__":
    main()

"""Solve times of two source trees of pipelay_fast, measured one after the
other on the same machine: the "no cost" check of a restructuring.

    python benchmarks/compare_trees.py BEFORE AFTER [--repeats 20] [--rounds 3]
                                       [--scenes j125 s67 ...] [--out DIR]

BEFORE and AFTER are directories holding a ``pipelay_fast`` package (a git
worktree each, e.g. ``git worktree add /tmp/before <rev>``). Each round runs
one fresh process per tree, BEFORE then AFTER, with ``PYTHONPATH`` set to the
tree: it imports the package, solves every scene once (compiling or loading
the kernels, timed apart), then times ``--repeats`` solves of each scene and
reports their median. Rounds alternate the two trees so that a drift in the
machine's load falls on both. The table gives, per scene, the median over
the rounds of each tree's medians and their ratio AFTER / BEFORE, wall
clock and the solving thread's CPU time (which other tenants of a shared
machine disturb less), with the range of the ratios of the rounds' pairs, and checks
that both trees give the same summary (every column but the solve time).
Writes ``compare_trees.md`` and ``.json`` into --out (default benchmarks/out).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

from bench_jlay import check_imported, machine_info

REPO = Path(__file__).resolve().parents[1]
SCENES = ("j125", "s67", "s125", "j125_3d", "s67_3d", "s125_3d", "s67_rollers")

CHILD = r"""
import json, math, statistics, sys, time
from pathlib import Path
import pipelay_fast as pf
scenes, repeats = sys.argv[1].split(","), int(sys.argv[2])
examples = Path(pf.__file__).parent / "examples"
cases = {name: pf.load_case(examples / f"{name}.toml") for name in scenes}
t0 = time.perf_counter()
first = {name: pf.solve(case) for name, case in cases.items()}
warm_up = time.perf_counter() - t0
out = {"file": pf.__file__, "warm_up_s": warm_up, "median_ms": {}, "cpu_median_ms": {},
       "summary": {}}
for name, case in cases.items():
    times, cpu = [], []
    for _ in range(repeats):
        t, c = time.perf_counter(), time.thread_time()
        pf.solve(case)
        cpu.append(time.thread_time() - c)
        times.append(time.perf_counter() - t)
    out["median_ms"][name] = 1e3 * statistics.median(times)
    out["cpu_median_ms"][name] = 1e3 * statistics.median(cpu)
    out["summary"][name] = {k: (None if isinstance(v, float) and math.isnan(v) else v)
                            for k, v in first[name].summary.items() if k != "solve_seconds"}
print(json.dumps(out))
"""


def run_tree(tree: Path, scenes, repeats: int) -> dict:
    """One process on ``tree``: warm-up time, median solve time per scene, summaries."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    done = subprocess.run([sys.executable, "-c", CHILD, ",".join(scenes), str(repeats)],
                          env=env, cwd=tree, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise RuntimeError(f"{tree}: {done.stderr[-2000:]}")
    answer = json.loads(done.stdout.splitlines()[-1])
    check_imported(tree, answer["file"])
    return answer


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("before", type=Path)
    parser.add_argument("after", type=Path)
    parser.add_argument("--repeats", type=int, default=20, help="timed solves per scene")
    parser.add_argument("--rounds", type=int, default=3, help="processes per tree, alternating")
    parser.add_argument("--scenes", nargs="+", default=list(SCENES))
    parser.add_argument("--out", type=Path, default=REPO / "benchmarks" / "out")
    args = parser.parse_args()
    runs = {"before": [], "after": []}
    for _ in range(args.rounds):
        for key, tree in (("before", args.before), ("after", args.after)):
            runs[key].append(run_tree(tree, args.scenes, args.repeats))
    lines = ["# Solve times, two trees one after the other", "", "```"]
    lines += [f"{k}: {v}" for k, v in machine_info().items()]
    lines += [f"before: {args.before}", f"after: {args.after}",
              f"{args.rounds} rounds x {args.repeats} solves per scene", "```", "",
              "| scene | before [ms] | after [ms] | after / before (pairs' range) "
              "| CPU before [ms] | CPU after [ms] | CPU after / before (pairs' range) "
              "| same summary |",
              "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    table = {}
    for name in args.scenes:
        row = {"same_summary": runs["before"][0]["summary"][name]
               == runs["after"][0]["summary"][name]}
        cells = []
        for key, label in (("median_ms", ""), ("cpu_median_ms", "cpu_")):
            before, after = (statistics.median(r[key][name] for r in runs[k])
                             for k in ("before", "after"))
            pairs = [a[key][name] / b[key][name]
                     for b, a in zip(runs["before"], runs["after"], strict=True)]
            row.update({f"{label}before_ms": before, f"{label}after_ms": after,
                        f"{label}ratio": after / before, f"{label}pair_ratios": pairs})
            cells.append(f"{before:.2f} | {after:.2f} | {after / before:.3f} "
                         f"({min(pairs):.3f}-{max(pairs):.3f})")
        table[name] = row
        lines.append(f"| {name} | {' | '.join(cells)} | "
                     f"{'yes' if row['same_summary'] else 'NO'} |")
    for key in ("before", "after"):
        warm = statistics.median(r["warm_up_s"] for r in runs[key])
        lines.append(f"\n{key}: first solves of every scene in a process (kernels loaded from "
                     f"the cache) {warm:.2f} s (median of {args.rounds})")
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "compare_trees.md").write_text("\n".join(lines) + "\n")
    (args.out / "compare_trees.json").write_text(json.dumps(
        {"machine": machine_info(), "table": table, "runs": runs}, indent=1, default=str))
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())

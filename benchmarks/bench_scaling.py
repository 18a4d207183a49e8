"""Scaling: time per solve against the number of elements, 2D and 3D.

    python benchmarks/bench_scaling.py [--quick] [--out DIR]

J125 (no current) on uniform meshes (grading off) of 50 to 20 000 elements.
For each size: the median wall time of ``pf.solve`` after a warm-up (3 repeats
below 2000 elements, 1 above), the Newton iterations, and the time per
iteration and element [us], which stays flat when the cost grows linearly.
The peak resident memory of a fresh process that imports, compiles and solves
the largest mesh is measured (``ru_maxrss``), beside that of the same process
before the large solve: the import and compilation usually set the peak.
Machine and versions are printed with the table; the CSV
goes to --out (default benchmarks/out/scaling.csv).
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
from bench_jlay import machine_info

import pipelay_fast as pf

CASE_FILE = Path(pf.__file__).parent / "examples" / "j125.toml"
SIZES = (50, 100, 200, 500, 1000, 2000, 5000, 10000, 20000)
QUICK_SIZES = (50, 200, 1000, 5000)

MEMORY_SCRIPT = """
import json, resource, sys
import pipelay_fast as pf
case = pf.load_case(sys.argv[1])
pf.solve(case.with_changes({"solver.element_length": 8.0}))
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
pf.solve(case.with_changes(json.loads(sys.argv[2])))
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(json.dumps({"base_kib": base, "peak_kib": peak}))
"""


def settings(case, n, dim):
    """Uniform mesh of about ``n`` elements over the modelled pipe [m]."""
    total = pf.solve(case.with_changes({"solver.dimension": dim})).profile["s"].iloc[-1]
    h = total / n
    return {"solver.dimension": dim, "solver.grading": False, "solver.element_length": h,
            "solver.min_element_length": h}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="four sizes up to 5000")
    parser.add_argument("--out", default=str(Path(__file__).parent / "out"))
    args = parser.parse_args(argv)
    info = machine_info()
    print(json.dumps(info, indent=1))
    case = pf.load_case(CASE_FILE)
    rows = []
    for dim in ("2d", "3d"):
        for n in QUICK_SIZES if args.quick else SIZES:
            variant = case.with_changes(settings(case, n, dim))
            row = {"dimension": dim, "target_elements": n}
            try:
                pf.solve(variant)  # warm-up (and the mesh)
                times = []
                for _ in range(3 if n < 2000 else 1):
                    t0 = time.perf_counter()
                    summary = pf.solve(variant).summary
                    times.append(time.perf_counter() - t0)
                ms = 1e3 * statistics.median(times)
                row |= {"n_elements": summary["n_elements"], "ms": ms,
                        "iterations": summary["n_iterations"],
                        "us_per_iteration_element": 1e3 * ms / (summary["n_iterations"]
                                                                * summary["n_elements"]),
                        "max_von_mises_mpa": summary["max_von_mises"] / 1e6, "status": "ok"}
            except pf.SolveError as err:
                row["status"] = f"failed: {err}"
            rows.append(row)
            print(row, flush=True)
    table = pd.DataFrame(rows)
    largest = max(QUICK_SIZES if args.quick else SIZES)
    memory = {}
    for dim in ("2d", "3d"):
        proc = subprocess.run(
            [sys.executable, "-c", MEMORY_SCRIPT, str(CASE_FILE),
             json.dumps(settings(case, largest, dim))],
            capture_output=True, text=True, check=True)
        m = json.loads(proc.stdout.strip().splitlines()[-1])
        memory[dim] = {"elements": largest, "peak_mib": m["peak_kib"] / 1024,
                       "solve_mib": (m["peak_kib"] - m["base_kib"]) / 1024}
    print("peak memory:", json.dumps(memory))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    table.to_csv(out / "scaling.csv", index=False)
    (out / "scaling.json").write_text(json.dumps({"machine": info, "memory": memory}, indent=1))
    print(table.to_string(index=False))


if __name__ == "__main__":
    main()

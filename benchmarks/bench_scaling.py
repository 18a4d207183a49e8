"""Scaling: time per solve against the number of elements, 2D and 3D.

    python benchmarks/bench_scaling.py [--quick] [--out DIR]

J125 (no current) on uniform meshes (grading off) of 50 to 20 000 elements.
For each size: the median wall time of ``pf.solve`` after a warm-up (3 repeats
below 2000 elements, 1 above), the Newton iterations, and the time per
iteration and element [us], which stays flat when the cost grows linearly.
The peak resident memory of a fresh process that imports, compiles and solves
the largest mesh is measured (``ru_maxrss``), beside that of the same process
before the large solve: the import and compilation usually set the peak.
Machine and versions are printed with the table; the CSV, a JSON of the
machine and memory, and the figure ``scaling.png`` (time per solve and time per
iteration and element against elements, log-log, with a line of slope 1) go
to --out (default benchmarks/out).
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import subprocess
import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from bench_jlay import machine_info  # noqa: E402

import pipelay_fast as pf  # noqa: E402

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


def plot(table: pd.DataFrame, memory: dict, info: dict, path: Path) -> None:
    """Time per solve and per iteration and element against elements (log-log)."""
    ok = table[table["status"] == "ok"]
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    for dim, marker in (("2d", "o"), ("3d", "s")):
        d = ok[ok["dimension"] == dim].sort_values("n_elements")
        if d.empty:
            continue
        peak = memory.get(dim, {}).get("peak_mib", math.nan)
        ax.loglog(d["n_elements"], d["ms"], marker=marker,
                  label=f"{dim.upper()} (peak RSS {peak:.0f} MiB at {d['n_elements'].max()})")
        ax2.semilogx(d["n_elements"], d["us_per_iteration_element"], marker=marker,
                     label=dim.upper())
        n0, t0 = d["n_elements"].iloc[0], d["ms"].iloc[0]
        n = np.array([n0, d["n_elements"].max()])
        ax.loglog(n, t0 * n / n0, ls=":", color="grey", lw=1)
    ax.plot([], [], ls=":", color="grey", label="slope 1 (linear cost)")
    ax.set_xlabel("elements")
    ax.set_ylabel("time per solve [ms]")
    ax.set_title("J125, uniform mesh, median after JIT warm-up")
    ax.legend(fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    ax2.set_xlabel("elements")
    ax2.set_ylabel("time per Newton iteration and element [us]")
    ax2.set_ylim(bottom=0.0)
    ax2.grid(True, which="both", alpha=0.3)
    ax2.legend(fontsize=8)
    fig.suptitle(f"{info.get('cpu', '')}, {info.get('cores', '')} cores, "
                 f"numba {info.get('numba', '')}, git {info.get('git', '')}", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def run(quick: bool = False, log=print) -> dict:
    """Measure every size in 2D and 3D and the peak memory of the largest;
    returns the table (pandas), the memory figures and the machine."""
    info = machine_info()
    case = pf.load_case(CASE_FILE)
    sizes = QUICK_SIZES if quick else SIZES
    rows = []
    for dim in ("2d", "3d"):
        for n in sizes:
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
            log(row)
    largest = max(sizes)
    memory = {}
    for dim in ("2d", "3d"):
        proc = subprocess.run(
            [sys.executable, "-c", MEMORY_SCRIPT, str(CASE_FILE),
             json.dumps(settings(case, largest, dim))],
            capture_output=True, text=True, check=True)
        m = json.loads(proc.stdout.strip().splitlines()[-1])
        memory[dim] = {"elements": largest, "peak_mib": m["peak_kib"] / 1024,
                       "solve_mib": (m["peak_kib"] - m["base_kib"]) / 1024}
    log(f"peak memory: {json.dumps(memory)}")
    return {"table": pd.DataFrame(rows), "memory": memory, "machine": info}


def write(res: dict, out: Path) -> None:
    """The CSV, the JSON (machine, memory) and the figure into ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    res["table"].to_csv(out / "scaling.csv", index=False)
    (out / "scaling.json").write_text(
        json.dumps({"machine": res["machine"], "memory": res["memory"]}, indent=1))
    plot(res["table"], res["memory"], res["machine"], out / "scaling.png")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="four sizes up to 5000")
    parser.add_argument("--out", default=str(Path(__file__).parent / "out"))
    args = parser.parse_args(argv)
    res = run(args.quick)
    print(json.dumps(res["machine"], indent=1))
    write(res, Path(args.out))
    print(res["table"].to_string(index=False))


if __name__ == "__main__":
    main()

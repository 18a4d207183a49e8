"""Benchmark the J125 J-lay solve: startup costs, run time and mesh convergence.

    python benchmarks/bench_jlay.py [--repeats N] [--quick] [--out DIR]

1. Machine and versions.
2. Startup in fresh subprocesses, so nothing is already imported or compiled:
   *cold* with an empty NUMBA_CACHE_DIR (every kernel compiles), then *cached*
   with the same, now filled, cache directory.
3. In-process, after a warm-up solve: the median and minimum wall time of
   ``pf.solve`` for 2D and 3D over a series of element lengths, and the errors
   of the summary against a mesh-converged 2D reference.
4. The table as CSV (plus a JSON of machine, startup and reference details) in
   --out, and as markdown on stdout. See benchmarks/README.md for the columns.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np
import pandas as pd

import pipelay_fast as pf

REPO = Path(__file__).resolve().parents[1]
CASE_FILE = Path(pf.__file__).parent / "examples" / "j125.toml"
LENGTHS = (8.0, 4.0, 2.0, 1.0, 0.5, 0.25)  # m, target element length
QUICK_LENGTHS = (4.0, 1.0, 0.5)
REFERENCE = {"solver.element_length": 0.1, "solver.min_element_length": 0.05,
             "solver.dimension": "2d"}
# Used only if the reference fails at the case's own tolerance (the run says so).
REFERENCE_FALLBACK_TOLERANCE = 1e-6
VM_HEADLINE_RTOL = 1e-3  # headline: fastest solve with max_von_mises error <= 0.1 %
RELATIVE = ("max_von_mises", "sagbend_max_moment")
ABSOLUTE = ("tdp_z", "top_angle_deg")

# Run in a fresh interpreter: import and first solve, timed separately.
STARTUP_SCRIPT = """
import json, resource, sys, time
t0, c0 = time.perf_counter(), time.process_time()
import pipelay_fast as pf
t1, c1 = time.perf_counter(), time.process_time()
pf.solve(pf.load_case(sys.argv[1]))
t2, c2 = time.perf_counter(), time.process_time()
kids = resource.getrusage(resource.RUSAGE_CHILDREN)
print(json.dumps({"import_s": t1 - t0, "first_solve_s": t2 - t1, "import_cpu_s": c1 - c0,
                  "first_solve_cpu_s": c2 - c1, "file": pf.__file__,
                  "children_cpu_s": kids.ru_utime + kids.ru_stime,
                  "max_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""


def check_imported(tree: Path, file: str) -> None:
    """RuntimeError unless ``file`` (the ``pipelay_fast.__file__`` a child
    process imported) lies in the source tree ``tree`` it was run on."""
    if not Path(file).resolve().is_relative_to(tree.resolve()):
        raise RuntimeError(f"{tree}: imported {file} instead (an installed copy?)")


def machine_info() -> dict:
    """Platform, CPU, versions and the git revision of the package."""
    cpu = platform.processor() or "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    info = {
        "platform": platform.platform(),
        "cpu": cpu,
        "cores": os.cpu_count(),
        "cores_usable": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else None,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "numba": numba.__version__,
        "pipelay_fast": pf.__version__,
        "git": _git_revision(),
    }
    return info


def _git_revision() -> str:
    """Short HEAD hash, with "-dirty" if the package sources differ from it."""
    def git(*args):
        return subprocess.run(["git", *args], cwd=REPO, capture_output=True, text=True,
                              check=True).stdout.strip()
    try:
        rev = git("rev-parse", "--short", "HEAD")
        return rev + ("-dirty" if git("status", "--porcelain", "--", "pipelay_fast") else "")
    except (OSError, subprocess.CalledProcessError):
        return "unavailable"


def startup_run(cache_dir: str) -> dict:
    """Import + first J125 solve in a fresh interpreter with NUMBA_CACHE_DIR = cache_dir [s]."""
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-c", STARTUP_SCRIPT, str(CASE_FILE)], env=env,
                          capture_output=True, text=True, check=True)
    wall = time.perf_counter() - t0
    times = json.loads(proc.stdout.strip().splitlines()[-1])
    times["total_s"] = times["import_s"] + times["first_solve_s"]
    times["process_wall_s"] = wall  # includes interpreter start-up and exit
    return times


def startup_costs() -> dict:
    with tempfile.TemporaryDirectory(prefix="pf-numba-cache-") as cache_dir:
        cold = startup_run(cache_dir)
        cached = startup_run(cache_dir)
    return {"cold": cold, "cached": cached}


def solve_reference(case: pf.Case) -> tuple[dict, dict, float]:
    """Summary of the mesh-converged reference, the settings used and its solve time [s]."""
    settings = dict(REFERENCE)
    try:
        summary, times = time_solve(case.with_changes(settings), 1)
    except pf.SolveError as err:
        print(f"NOTE: reference failed at solver.tolerance = {case.solver.tolerance:g}:\n"
              f"      {err}\n      retrying with solver.tolerance = "
              f"{REFERENCE_FALLBACK_TOLERANCE:g}")
        settings["solver.tolerance"] = REFERENCE_FALLBACK_TOLERANCE
        summary, times = time_solve(case.with_changes(settings), 1)
    return summary, settings, times[0]


def time_solve(case: pf.Case, repeats: int) -> tuple[dict, list[float]]:
    """Summary of the last solve and the wall time of each solve [s]."""
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = pf.solve(case)
        times.append(time.perf_counter() - t0)
    return result.summary, times


def sweep(case: pf.Case, ref: dict, lengths, repeats: int) -> pd.DataFrame:
    rows = []
    for dim in ("2d", "3d"):
        for h in lengths:
            row = {"dimension": dim, "element_length_m": h}
            variant = case.with_changes({"solver.element_length": h, "solver.dimension": dim})
            try:
                s, times = time_solve(variant, repeats)
            except pf.SolveError as err:
                rows.append(row | {"status": f"failed: {err}"})
                continue
            row |= {
                "solved_dimension": s["dimension"],
                "n_elements": s["n_elements"],
                "n_iterations": s["n_iterations"],
                "median_ms": 1e3 * statistics.median(times),
                "min_ms": 1e3 * min(times),
            }
            for key in RELATIVE:
                row[f"{key}_rel_err"] = abs(s[key] - ref[key]) / abs(ref[key])
            for key in ABSOLUTE:
                row[f"{key}_abs_err"] = abs(s[key] - ref[key])
            rows.append(row | {"status": "ok"})
    return pd.DataFrame(rows)


def markdown(df: pd.DataFrame) -> str:
    """A markdown table (no tabulate dependency); floats in 4 significant digits."""
    def cell(v):
        if isinstance(v, float):
            return "nan" if np.isnan(v) else f"{v:.4g}"
        return str(v)
    lines = ["| " + " | ".join(df.columns) + " |", "|" + "---|" * len(df.columns)]
    lines += ["| " + " | ".join(cell(v) for v in row) + " |"
              for row in df.itertuples(index=False)]
    return "\n".join(lines)


def headline(df: pd.DataFrame) -> list[str]:
    lines = []
    for dim in ("2d", "3d"):
        ok = df[(df["dimension"] == dim) & (df["status"] == "ok")
                & (df["max_von_mises_rel_err"] <= VM_HEADLINE_RTOL)]
        if ok.empty:
            lines.append(f"{dim.upper()}: no mesh reached max von Mises error <= "
                         f"{100 * VM_HEADLINE_RTOL:g} %")
            continue
        best = ok.loc[ok["median_ms"].idxmin()]
        lines.append(
            f"{dim.upper()}: {best['median_ms']:.2f} ms median per solve "
            f"(element_length {best['element_length_m']:g} m, {best['n_elements']} elements, "
            f"max von Mises error {100 * best['max_von_mises_rel_err']:.2g} %)")
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=21, help="timed solves per mesh (>= 20)")
    parser.add_argument("--quick", action="store_true", help=f"element lengths {QUICK_LENGTHS}")
    parser.add_argument("--out", type=Path, default=REPO / "benchmarks" / "out")
    args = parser.parse_args(argv)
    if args.repeats < 20:
        parser.error("--repeats must be at least 20 for a meaningful median")

    info = machine_info()
    print("## Machine\n")
    for key, value in info.items():
        print(f"- {key}: {value}")

    print("\n## Startup (fresh subprocess: import + first J125 solve)\n")
    startup = startup_costs()
    for name, t in startup.items():
        print(f"- {name:6s}: {t['total_s']:.2f} s (import {t['import_s']:.2f} s, first solve "
              f"{t['first_solve_s']:.2f} s; process wall {t['process_wall_s']:.2f} s)")

    case = pf.load_case(CASE_FILE)
    pf.solve(case)  # warm-up: load compiled kernels before timing
    ref, ref_settings, ref_seconds = solve_reference(case)
    print(f"\n## Reference ({ref_settings}, solved once in {ref_seconds:.1f} s)\n")
    for key in ("n_elements", "n_iterations", *RELATIVE, *ABSOLUTE):
        print(f"- {key}: {ref[key]:.10g}")

    lengths = QUICK_LENGTHS if args.quick else LENGTHS
    df = sweep(case, ref, lengths, args.repeats)
    print(f"\n## Solve time and error ({args.repeats} repeats per row)\n")
    print(markdown(df))
    print("\n## Headline: fastest solve with max von Mises error <= "
          f"{100 * VM_HEADLINE_RTOL:g} %\n")
    print("\n".join(f"- {line}" for line in headline(df)))

    args.out.mkdir(parents=True, exist_ok=True)
    csv_path = args.out / "bench_jlay.csv"
    df.to_csv(csv_path, index=False)
    meta = {"machine": info, "startup_s": startup, "repeats": args.repeats,
            "reference": {"settings": ref_settings, "seconds": ref_seconds,
                          "summary": {k: ref[k] for k in ("n_elements", "n_iterations",
                                                          *RELATIVE, *ABSOLUTE)}}}
    (args.out / "bench_jlay_meta.json").write_text(json.dumps(meta, indent=2))
    print(f"\nwrote {csv_path} and {args.out / 'bench_jlay_meta.json'}")


if __name__ == "__main__":
    main()

"""Benchmark the S-lay solves: time per solve against error, cold and warm-started.

    python benchmarks/bench_slay.py [--repeats N] [--quick] [--out DIR]

Scenes (bundled case files): S67 2D (in-plane current), S67 3D and S125 3D
(lateral current on a seabed with friction). For each scene and element length:

* cold: ``pf.solve(case)`` from the catenary guess, median wall time of
  --repeats solves after a warm-up (compilation excluded);
* warm: ``pf.solve(case, warm=neighbour)``, the neighbour being the solution at
  a neighbouring stinger curvature (``a`` + DA_NEAR, and a + DA_SWEEP, the step
  of the paper's sweep of nine values);
* errors of the maximum von Mises stress (relative), touchdown and lift-off (m)
  against a mesh-converged solve of the same scene (REFERENCE settings).

Writes ``slay.csv`` and ``slay.json`` (machine, versions, git revision) into
--out (default benchmarks/out) and prints the table as markdown.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

import pandas as pd
from bench_jlay import machine_info

import pipelay_fast as pf

EXAMPLES = Path(pf.__file__).parent / "examples"
SCENES = {"S67 2D": "s67.toml", "S67 3D": "s67_3d.toml", "S125 3D": "s125_3d.toml"}
LENGTHS = (8.0, 4.0, 2.0, 1.0)  # m, target element length
QUICK_LENGTHS = (4.0, 1.0)
REFERENCE = {"solver.element_length": 0.25, "solver.min_element_length": 0.05}
DA_NEAR = 2e-5  # 1/m, a neighbour of a fine sweep or a bounded search
DA_SWEEP = 1.5e-4  # 1/m, the step of nine values over the paper's range


def timed(case, repeats, warm=None):
    """(last summary, median wall time [s]) of ``repeats`` solves."""
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = pf.solve(case, warm=warm)
        times.append(time.perf_counter() - t0)
    return result.summary, statistics.median(times)


def errors(summary, ref):
    out = {"vm_rel_error": abs(summary["max_von_mises"] / ref["max_von_mises"] - 1.0),
           "tdp_error_m": abs(summary["tdp_z"] - ref["tdp_z"])}
    if summary["liftoff_z"] is not None and ref["liftoff_z"] is not None:
        out["liftoff_error_m"] = abs(summary["liftoff_z"] - ref["liftoff_z"])
    return out


def bench_scene(name, case, lengths, repeats):
    t0 = time.perf_counter()
    ref = pf.solve(case.with_changes(REFERENCE)).summary
    ref_s = time.perf_counter() - t0
    print(f"{name}: reference ({REFERENCE}) {ref['n_elements']} elements in {ref_s:.1f} s, "
          f"max von Mises {ref['max_von_mises'] / 1e6:.3f} MPa", flush=True)
    rows = []
    a = case.lay.stinger.a
    for h in lengths:
        variant = case.with_changes({"solver.element_length": h})
        row = {"scene": name, "element_length_m": h}
        try:
            pf.solve(variant)  # warm-up
            summary, cold = timed(variant, repeats)
            row |= {"n_elements": summary["n_elements"], "cold_ms": 1e3 * cold,
                    "cold_iterations": summary["n_iterations"], **errors(summary, ref)}
            for label, da in (("near", DA_NEAR), ("sweep", DA_SWEEP)):
                neighbour = pf.solve(variant.with_changes({"lay.stinger.a": a + da}))
                warm_summary, warm = timed(variant, repeats, warm=neighbour)
                row[f"warm_{label}_ms"] = 1e3 * warm
                row[f"warm_{label}_iterations"] = warm_summary["n_iterations"]
                row[f"warm_{label}_vm_diff"] = abs(warm_summary["max_von_mises"]
                                                   / summary["max_von_mises"] - 1.0)
            row["status"] = "ok"
        except pf.SolveError as err:
            row["status"] = f"failed: {err}"
        rows.append(row)
        print(f"  h = {h:g} m: {row.get('cold_ms', float('nan')):.1f} ms cold, "
              f"{row.get('warm_near_ms', float('nan')):.1f} ms warm (near), "
              f"vm error {row.get('vm_rel_error', float('nan')):.1e}", flush=True)
    return rows, {"reference": REFERENCE, "reference_seconds": ref_s,
                  "reference_summary": {k: ref[k] for k in ("max_von_mises", "tdp_z",
                                                            "liftoff_z", "n_elements")}}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--quick", action="store_true", help="two element lengths, 3 repeats")
    parser.add_argument("--out", default=str(Path(__file__).parent / "out"))
    args = parser.parse_args(argv)
    lengths = QUICK_LENGTHS if args.quick else LENGTHS
    repeats = 3 if args.quick else args.repeats
    info = machine_info()
    print(json.dumps(info, indent=1))
    rows, refs = [], {}
    for name, path in SCENES.items():
        scene_rows, refs[name] = bench_scene(name, pf.load_case(EXAMPLES / path), lengths,
                                             repeats)
        rows += scene_rows
    table = pd.DataFrame(rows)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    table.to_csv(out / "slay.csv", index=False)
    (out / "slay.json").write_text(json.dumps({"machine": info, "repeats": repeats,
                                                "da_near": DA_NEAR, "da_sweep": DA_SWEEP,
                                                "references": refs}, indent=1, default=str))
    show = table.copy()
    for col in show.columns:
        if col.endswith("_ms"):
            show[col] = show[col].map(lambda v: f"{v:.1f}")
        elif "error" in col or col.endswith("_diff"):
            show[col] = show[col].map(lambda v: f"{v:.1e}")
    print(show.to_markdown(index=False) if _has_tabulate() else show.to_string(index=False))


def _has_tabulate():
    try:
        import tabulate  # noqa: F401
    except ImportError:
        return False
    return True


if __name__ == "__main__":
    main()

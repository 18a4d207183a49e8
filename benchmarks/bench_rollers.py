"""Benchmark the roller stinger (issue 13): a cold solve against the quadratic
stinger's, and warm sweeps of roller heights.

    python benchmarks/bench_rollers.py [--repeats N] [--out DIR]

1. Cold solves, median wall time of --repeats solves after a warm-up (the
   first call, compilation and cache loading, reported apart): the paper's
   S67 and S125 (2D, the examples' 1 m/s current along the lay) on their
   quadratic stingers (``s67.toml``, ``s125.toml``) and on rollers about
   6 m apart on the same curves (``s67_rollers.toml``, 23 rollers;
   ``s125_rollers.toml``, 24), the radius stinger ``s67_radius.toml``, and
   S67 on 12, 46 and 92 rollers (3, 1.5 m). Target: S67 on about 25 rollers
   at most 1.5 times the quadratic's time.
2. Warm sweeps of roller heights on ``s67_rollers``: every roller shifted
   by -0.10 to +0.10 m, and the tip roller alone lowered by 0 to 0.5 m, each
   case warm from the last (Newton iterations per case, time), with the
   cold solves of the same cases for the answers' agreement (peak stress).
   Target: at most 3 iterations a case.
3. Random roller stingers (``--random N``, ``--seed``): S67's pipe on rollers
   placed on a radius (250 to 700 m, 3 to 12 m apart, 100 to 160 m of arc
   from a top 2 to 15 deg, 5 m above the surface, in 40 to 150 m of water),
   580 to 1200 kN at the top, a current of 0 to 1.5 m/s along the lay (2D)
   or at 30 to 90 deg (3D, friction 0.5), V rollers or flat; cold solves:
   refused inputs, failures, iterations, rollers pulling.

Prints markdown tables (machine and versions first) and writes
``rollers.json`` into --out (default benchmarks/out).
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import time
from pathlib import Path

import numpy as np
from bench_jlay import machine_info

import pipelay_fast as pf

EXAMPLES = Path(pf.__file__).parent / "examples"


def timed(case, repeats, warm=None):
    """(first call [s], median of the repeats after it [s], the result)."""
    t0 = time.perf_counter()
    result = pf.solve(case, warm=warm)
    first = time.perf_counter() - t0
    walls = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = pf.solve(case, warm=warm)
        walls.append(time.perf_counter() - t0)
    return first, statistics.median(walls), result


def cold_part(repeats):
    s67 = pf.load_case(EXAMPLES / "s67.toml")
    rollers = pf.load_case(EXAMPLES / "s67_rollers.toml")
    cases = [("S67 quadratic", s67), ("S67 23 rollers (6 m)", rollers),
             ("S125 quadratic", pf.load_case(EXAMPLES / "s125.toml")),
             ("S125 24 rollers (6 m)", pf.load_case(EXAMPLES / "s125_rollers.toml")),
             ("S67 radius 450 m", pf.load_case(EXAMPLES / "s67_radius.toml"))]
    for spacing in (12.0, 3.0, 1.5):
        more = rollers.with_changes({"lay.stinger.rollers":
                                     s67.lay.stinger.roller_positions(spacing)})
        cases.append((f"S67 {len(more.lay.stinger.rollers)} rollers ({spacing:g} m)", more))
    rows = []
    for label, case in cases:
        first, wall, res = timed(case, repeats)
        rows.append({"case": label, "first_s": first, "median_ms": wall * 1e3,
                     "iterations": int(res.summary["n_iterations"]),
                     "elements": int(res.summary["n_elements"]),
                     "max_von_mises_MPa": res.summary["max_von_mises"] / 1e6,
                     "last_roller_in_contact": res.summary["last_roller_in_contact"]})
    base = {"S67": rows[0]["median_ms"], "S125": rows[2]["median_ms"]}
    for row in rows:
        row["vs_quadratic"] = row["median_ms"] / base[row["case"].split()[0]]
    return rows


def warm_part():
    case = pf.load_case(EXAMPLES / "s67_rollers.toml")
    base = [list(p) for p in case.lay.stinger.rollers]
    sweeps = {
        "all rollers shifted -0.10 to +0.10 m": [
            [[x + d, z] for x, z in base] for d in np.linspace(-0.1, 0.1, 11)],
        "tip roller lowered 0 to 0.5 m": [
            [*base[:-1], [base[-1][0] - d, base[-1][1]]] for d in np.linspace(0.0, 0.5, 11)],
    }
    rows = []
    for label, variants in sweeps.items():
        prev = None
        its, walls, dev = [], [], []
        for k, rollers in enumerate(variants):
            c = case.with_changes({"lay.stinger.rollers": rollers})
            t0 = time.perf_counter()
            res = pf.solve(c, warm=prev)
            wall = time.perf_counter() - t0
            cold = pf.solve(c)
            if k > 0:  # the first is cold
                its.append(int(res.summary["n_iterations"]))
                walls.append(wall)
                dev.append(abs(res.summary["max_von_mises"] / cold.summary["max_von_mises"]
                               - 1.0))
            prev = res
        rows.append({"sweep": label, "cases": len(variants) - 1,
                     "median_iterations": statistics.median(its), "max_iterations": max(its),
                     "median_ms": statistics.median(walls) * 1e3,
                     "max_stress_vs_cold": max(dev)})
    return rows


def random_part(n, seed):
    """Cold solves of ``n`` random roller stingers (see the module's part 3)."""
    rng = np.random.default_rng(seed)
    base = pf.load_case(EXAMPLES / "s67_radius.toml")
    rows = []
    for k in range(n):
        depth = float(rng.uniform(40.0, 150.0))
        heading = float(rng.choice([0.0, rng.uniform(30.0, 90.0)]))
        changes = {
            "environment.water_depth": depth, "lay.top": [depth + 5.0, 400.0],
            "lay.top_angle": float(rng.uniform(2.0, 15.0)),
            "lay.top_tension": float(rng.uniform(580e3, 1200e3)),
            "lay.stinger.radius": float(rng.uniform(250.0, 700.0)),
            "lay.stinger.arc_length": float(rng.uniform(100.0, 160.0)),
            "lay.stinger.spacing": float(rng.uniform(3.0, 12.0)),
            "lay.stinger.roller_type": str(rng.choice(["v", "flat"])),
            "environment.current.speed": float(rng.uniform(0.0, 1.5)),
            "environment.current.heading": heading,
        }
        row = {"case": k, "dimension": "", "status": "", "iterations": 0, "seconds": math.nan,
               "rollers": 0, "last_in_contact": -1, "pulling": 0, "message": ""}
        try:
            case = base.with_changes(changes)
        except ValueError as err:
            rows.append({**row, "status": "refused", "message": str(err)[:120]})
            continue
        t0 = time.perf_counter()
        try:
            res = pf.solve(case)
        except pf.SolveError as err:
            rows.append({**row, "status": "failed", "seconds": time.perf_counter() - t0,
                         "message": str(err)[:160]})
            continue
        ro = res.rollers
        rows.append({**row, "dimension": res.summary["dimension"], "status": "ok",
                     "iterations": int(res.summary["n_iterations"]),
                     "seconds": time.perf_counter() - t0, "rollers": len(ro),
                     "last_in_contact": int(res.summary["last_roller_in_contact"]),
                     "pulling": int((ro["reaction"] < 0.0).sum())})
    return rows


def markdown(rows):
    keys = list(rows[0])
    out = ["| " + " | ".join(keys) + " |", "| " + " | ".join("---" for _ in keys) + " |"]
    out.extend("| " + " | ".join(f"{v:.3g}" if isinstance(v, float) else str(v)
                                 for v in row.values()) + " |" for row in rows)
    return "\n".join(out)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=30)
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "out")
    parser.add_argument("--random", type=int, default=40, help="random cases (part 3)")
    parser.add_argument("--seed", type=int, default=13)
    args = parser.parse_args(argv)
    info = machine_info()
    print("## Machine\n")
    for key, value in info.items():
        print(f"- {key}: {value}")
    cold = cold_part(args.repeats)
    print("\n## Cold solves (2D; median of the repeats after the first call)\n")
    print(markdown(cold))
    warm = warm_part()
    print("\n## Warm sweeps of roller heights (S67, 23 rollers; each case from the last)\n")
    print(markdown(warm))
    rand = random_part(args.random, args.seed)
    if rand:
        ok = [r for r in rand if r["status"] == "ok"]
        counts = {st: sum(r["status"] == st for r in rand) for st in ("ok", "failed", "refused")}
        print(f"\n## Random roller stingers (seed {args.seed}): {counts}; iterations of the "
              f"solved: median {statistics.median(r['iterations'] for r in ok) if ok else 0}, "
              f"max {max((r['iterations'] for r in ok), default=0)}; rollers pulling: "
              f"{sum(r['pulling'] for r in ok)}\n")
        print(markdown(rand))
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "rollers.json").write_text(json.dumps(
        {"machine": info, "cold": cold, "warm": warm, "random": rand}, indent=1))


if __name__ == "__main__":
    main()

"""The seabed profile's cost (issue 45, target 5): a solve on a profile with
spans against the flat elastic seabed's, same run, and the Newton
iterations of cold solves on random profiles.

    python benchmarks/bench_profile.py [--repeats 15] [--random 20] [--seed 1]

Scenes: J125 and S67 in the plane (current off), in 2D and 3D
(``solver.dimension = "3d"``), on the elastic seabed of ``--stiffness``
N/m per m. The profile: a 1 m trench and a 0.8 m hump behind the flat
answer's touchdown (tests/test_profile_solve.py's, shifted there). The
kernels are compiled (or loaded) first and timed apart; every case is solved
once to warm up, then the flat and the profiled cases interleave,
``--repeats`` rounds: the median wall time [ms] of each and their ratio
(target <= 3). Then ``--random`` cold solves of each scene in 2D on random
profiles (knots every 8 to 30 m from 260 m behind touchdown to 40 m beyond
it, depths within +-1.5 m of the scene's): the distribution of their Newton
iterations (target <= 10 per load step: in 2D without current, the
solve's). Prints the machine and the versions.
"""

from __future__ import annotations

import argparse
import collections
import json
import time

import numpy as np
from bench_jlay import machine_info
from bench_slope import _timed

import pipelay_fast as pf

SCENES = ("j125_2d", "s67")
# (z - touchdown, depth - water_depth) [m]: a trench, then a hump
FEATURES = [(-290.0, 0.0), (-210.0, 0.0), (-200.0, 1.0), (-185.0, 1.0), (-175.0, 0.0),
            (-125.0, 0.0), (-118.0, -0.8), (-114.0, -0.8), (-107.0, 0.0), (360.0, 0.0)]


def _base(name: str, dimension: str, k: float):
    return pf.load_case(name).with_changes({"environment.current.speed": 0.0, "checks": None,
                                            "solver.dimension": dimension,
                                            "seabed.stiffness": k})


def _profiled(flat, tdp_z: float, rows=FEATURES):
    depth = flat.environment.water_depth
    return flat.with_changes({"seabed.profile": [[tdp_z + z, depth + d] for z, d in rows]})


def _random_rows(rng) -> list[tuple[float, float]]:
    z = [-260.0]
    while z[-1] < 40.0:
        z.append(z[-1] + rng.uniform(8.0, 30.0))
    return [(zi, float(rng.uniform(-1.5, 1.5))) for zi in z]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--random", type=int, default=20)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--stiffness", type=float, default=1e6)
    args = parser.parse_args(argv)
    print(json.dumps(machine_info()))
    t0 = time.perf_counter()
    for dim in ("2d", "3d"):
        flat = _base("j125_2d", dim, args.stiffness)
        _timed(_profiled(flat, _timed(flat)[1]["tdp_z"]))
    print(f"compile (or cache load) and first solves: {time.perf_counter() - t0:.1f} s\n")
    print("| scene | dim | flat ms | profile ms | ratio | iterations flat / profile | "
          "elements flat / profile | spans |")
    print("|---|---|---:|---:|---:|---|---|---:|")
    worst = 0.0
    for name in SCENES:
        for dim in ("2d", "3d"):
            flat = _base(name, dim, args.stiffness)
            _dt, sm = _timed(flat)
            cases = [flat, _profiled(flat, float(sm["tdp_z"]))]
            sms = [_timed(c)[1] for c in cases]  # (the warm-up)
            times = np.empty((args.repeats, len(cases)))
            for k in range(args.repeats):
                for j, c in enumerate(cases):
                    times[k, j] = _timed(c)[0]
            med = np.median(times, axis=0) * 1e3
            ratio = med[1] / med[0]
            worst = max(worst, ratio)
            print(f"| {name} | {dim} | {med[0]:.1f} | {med[1]:.1f} | {ratio:.2f} | "
                  f"{sms[0]['n_iterations']} / {sms[1]['n_iterations']} | "
                  f"{sms[0]['n_elements']} / {sms[1]['n_elements']} | {sms[1]['n_spans']} |",
                  flush=True)
    print(f"\nlargest ratio profile / flat: {worst:.2f} (target <= 3)\n")
    rng = np.random.default_rng(args.seed)
    for name in SCENES:
        flat = _base(name, "2d", args.stiffness)
        tdp_z = float(_timed(flat)[1]["tdp_z"])
        counts, spans, failed = collections.Counter(), [], []
        for _ in range(args.random):
            rows = _random_rows(rng)
            try:
                sm = _timed(_profiled(flat, tdp_z, rows))[1]
            except (pf.SolveError, AssertionError) as err:
                failed.append(f"{err}"[:120])
                continue
            counts[int(sm["n_iterations"])] += 1
            spans.append(int(sm["n_spans"]))
        dist = ", ".join(f"{n}: {c}" for n, c in sorted(counts.items()))
        print(f"{name} 2D, {args.random} random profiles: Newton iterations {{{dist}}}; "
              f"spans per case {np.mean(spans) if spans else 0:.1f}; failed {len(failed)}")
        for msg in failed:
            print(f"  failed: {msg}")


if __name__ == "__main__":
    main()

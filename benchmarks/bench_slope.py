"""The sloped seabed's cost (issue 45, target 5): a sloped seabed's solve
against the flat one's, same run.

    python benchmarks/bench_slope.py [--repeats 21] [--slopes -8 -4 4 8]

Scenes: J125, S67 and S125 in the plane (current off), in 2D and in 3D
(``solver.dimension = "3d"``), the sloped seabed through x = 0 at the flat
answer's touchdown (so the water depth there is the scene's). The kernels
are compiled (or loaded) first and timed apart; every case is then solved
once to warm up, and the timed solves interleave the flat and the sloped
cases, ``--repeats`` rounds. Reported per scene and slope: the median wall
time [ms] of each, their ratio (target <= 1.2) and the Newton iterations.
Prints the machine and the versions.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np
from bench_jlay import machine_info

import pipelay_fast as pf

SCENES = ("j125_2d", "s67", "s125")


def _base(name: str, dimension: str):
    return pf.load_case(name).with_changes({"environment.current.speed": 0.0, "checks": None,
                                            "solver.dimension": dimension})


def _timed(case):
    t0 = time.perf_counter()
    r = pf.solve(case)
    dt = time.perf_counter() - t0
    assert r.summary["status"] == "ok", r.summary["message"]
    return dt, r.summary


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=21)
    parser.add_argument("--slopes", type=float, nargs="+", default=[-8.0, -4.0, 4.0, 8.0])
    args = parser.parse_args(argv)
    print(json.dumps(machine_info()))
    t0 = time.perf_counter()
    _timed(_base("j125_2d", "2d"))
    _timed(_base("j125_2d", "3d"))
    print(f"compile (or cache load) and first solves: {time.perf_counter() - t0:.1f} s\n")
    print("| scene | dim | slope deg | flat ms | sloped ms | ratio | iterations flat / sloped |")
    print("|---|---|---:|---:|---:|---:|---|")
    worst = 0.0
    for name in SCENES:
        for dim in ("2d", "3d"):
            flat = _base(name, dim)
            _dt, sm = _timed(flat)
            origin = float(sm["tdp_z"])
            sloped = [flat.with_changes({"seabed.slope_deg": a, "seabed.slope_origin": origin})
                      for a in args.slopes]
            cases = [flat, *sloped]
            iters = [_timed(c)[1]["n_iterations"] for c in cases]  # (the warm-up)
            times = np.empty((args.repeats, len(cases)))
            for k in range(args.repeats):
                for j, c in enumerate(cases):
                    times[k, j] = _timed(c)[0]
            med = np.median(times, axis=0) * 1e3
            for j, a in enumerate(args.slopes, start=1):
                ratio = med[j] / med[0]
                worst = max(worst, ratio)
                print(f"| {name} | {dim} | {a:+g} | {med[0]:.1f} | {med[j]:.1f} | {ratio:.2f} | "
                      f"{iters[0]} / {iters[j]} |", flush=True)
    print(f"\nlargest ratio sloped / flat: {worst:.2f} (target <= 1.2)")


if __name__ == "__main__":
    main()

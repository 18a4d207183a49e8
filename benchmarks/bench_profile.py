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
iterations per solve and per Newton call (each load step, each regrading
pass of the mesh; target <= 10 per load step), p50/p90/max, the first call's
apart, and the meshes per solve. ``--repeats 0`` skips the timed table.
Prints the machine and the versions.
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
from pipelay_fast.input.limits import IterationBudget

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


class _Calls:
    """Records the iterations of every Newton call a solve charges to its
    budget (IterationBudget.charge: one call per load step, regrading pass
    or switch of regime), the method wrapped while the instance is open."""

    def __init__(self):
        self.calls: list[int] = []
        self._charge = IterationBudget.charge

    def __enter__(self):
        def charge(budget, iterations):
            self.calls.append(int(iterations))
            self._charge(budget, iterations)
        IterationBudget.charge = charge
        return self

    def __exit__(self, *exc):
        IterationBudget.charge = self._charge


def _spread(values) -> str:
    """p50/p90/max of ``values``."""
    v = np.asarray(values, dtype=float)
    if v.size == 0:
        return "-"
    return f"{np.percentile(v, 50):g}/{np.percentile(v, 90):.3g}/{v.max():g}"


def _random_scene(name: str, args, rng) -> None:
    """``args.random`` cold solves of ``name`` in 2D on random profiles: their
    Newton iterations per solve and per call, printed."""
    flat = _base(name, "2d", args.stiffness)
    tdp_z = float(_timed(flat)[1]["tdp_z"])
    solves, calls, first, meshes, spans, failed = [], [], [], [], [], []
    for _ in range(args.random):
        rows = _random_rows(rng)
        with _Calls() as rec:
            try:
                sm = _timed(_profiled(flat, tdp_z, rows))[1]
            except (pf.SolveError, AssertionError) as err:
                failed.append(f"{err}"[:120])
                continue
        solves.append(int(sm["n_iterations"]))
        calls.extend(rec.calls)
        first.append(rec.calls[0])
        meshes.append(int(sm["n_meshes"]))
        spans.append(int(sm["n_spans"]))
    over = sum(c > 10 for c in calls)
    print(f"{name} 2D, {args.random} random profiles (p50/p90/max): iterations per solve "
          f"{_spread(solves)}, per Newton call {_spread(calls)} ({len(calls)} calls, "
          f"{over} over 10), first call {_spread(first)}; meshes {_spread(meshes)}; "
          f"spans per case {np.mean(spans) if spans else 0:.1f}; failed {len(failed)}",
          flush=True)
    print(f"  per solve {dict(sorted(collections.Counter(solves).items()))}; "
          f"per call {dict(sorted(collections.Counter(calls).items()))}")
    for msg in failed:
        print(f"  failed: {msg}")


def _timed_table(args) -> None:
    """The flat and profiled scenes' median wall times, interleaved, and their ratio."""
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
    if args.repeats > 0:
        _timed_table(args)
    rng = np.random.default_rng(args.seed)
    for name in SCENES if args.random > 0 else ():
        _random_scene(name, args, rng)


if __name__ == "__main__":
    main()

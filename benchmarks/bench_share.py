"""Python's share of a solve: the time outside the Newton kernel's calls.

    python benchmarks/bench_share.py [--repeats 50]

For each paper scene at the defaults (4 m elements, graded) and at its
fastest setting within 0.1 % of the converged stress (the README's Speed
table): the median wall time of ``pf.solve`` after a warm-up, the time in the
calls of the Newton kernel (``continuation.run_newton``: the kernel and its
thin wrapper), and the share of the rest (the guess, the meshes, the load
paths' bookkeeping, the profile and the summary), with the time of the
larger Python parts. Machine and versions are printed with the table
(markdown on stdout).
"""

from __future__ import annotations

import argparse
import functools
import statistics
import time
from pathlib import Path

from bench_jlay import machine_info

import pipelay_fast as pf
from pipelay_fast.api import solve as api_solve
from pipelay_fast.engine import continuation, solver

EXAMPLES = Path(pf.__file__).parent / "examples"
SETTINGS = {
    "j125": [{}, {"solver.element_length": 8.0, "solver.grading": False}],
    "s67": [{}, {"solver.element_length": 16.0, "solver.grading": False}],
    "s125": [{}, {"solver.element_length": 8.0}],
    "s67_3d": [{}, {"solver.element_length": 16.0, "solver.grading": False}],
    "s125_3d": [{}, {"solver.element_length": 8.0}],
}
PARTS = [(continuation, "run_newton"), (solver, "build_problem"), (api_solve, "build_profile"),
         (api_solve, "build_summary")]


def timed(spent: dict, module, name: str):
    """Wrap ``module.name`` so that its wall time adds up in ``spent[name]``."""
    func = getattr(module, name)

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        t0 = time.perf_counter()
        try:
            return func(*args, **kwargs)
        finally:
            spent[name] = spent.get(name, 0.0) + time.perf_counter() - t0

    setattr(module, name, wrapper)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=50)
    args = parser.parse_args(argv)
    spent: dict = {}
    for module, name in PARTS:
        timed(spent, module, name)
    print("## Machine\n")
    for key, value in machine_info().items():
        print(f"- {key}: {value}")
    print("\n| scene | setting | solve ms | in Newton ms | Python share | guess and mesh ms "
          "| profile ms | summary ms |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for scene, settings in SETTINGS.items():
        base = pf.load_case(EXAMPLES / f"{scene}.toml")
        for changes in settings:
            case = base.with_changes(changes)
            pf.solve(case)  # warm-up
            walls, parts = [], []
            for _ in range(args.repeats):
                spent.clear()
                t0 = time.perf_counter()
                pf.solve(case)
                walls.append(time.perf_counter() - t0)
                parts.append(dict(spent))
            wall = statistics.median(walls)
            med = {name: statistics.median(p.get(name, 0.0) for p in parts) for _m, name in PARTS}
            share = 1.0 - med["run_newton"] / wall
            label = ", ".join(f"{k.split('.')[-1]} {v}" for k, v in changes.items()) or "defaults"
            print(f"| {scene} | {label} | {wall * 1e3:.2f} | {med['run_newton'] * 1e3:.2f} | "
                  f"{share:.0%} | {med['build_problem'] * 1e3:.2f} | "
                  f"{med['build_profile'] * 1e3:.2f} | {med['build_summary'] * 1e3:.2f} |",
                  flush=True)


if __name__ == "__main__":
    main()

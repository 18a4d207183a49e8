"""``select`` with and without the sweep's sensitivities on the paper study
(issue 43, target 3): the equal-peaks ``a`` and the tip clearance limit's
boundary (``min_tip_clearance = 0.2`` m) found by Newton on the
sensitivities from the grid points, against ``select``'s solves alone
(brentq), each against a root of direct cold solves
(:func:`scipy.optimize.brentq` to ``XTOL`` in ``a``, independent of
``select``), with the solves each takes.

Runs ``sweeps/paper.toml`` with ``sensitivities = ["lay.stinger.a"]`` into
``--out`` (a rerun skips the cases solved), selects both ways, and writes
``bench_select_sensitivities.json`` there (the selection rows, the direct
roots, the solve counts and the sweep's times).

    python benchmarks/bench_select_sensitivities.py [--out DIR] [--workers 1]
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
import tomllib
from pathlib import Path

from bench_jlay import machine_info

from pipelay_fast.study.runner import run_sweep
from pipelay_fast.study.select import select
from pipelay_fast.study.sweep_file import load_sweep

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))  # the repository root, for tests.reference
from tests.reference import solves  # noqa: E402

XTOL = 1e-10  # 1/m, the direct roots' tolerance
LIMITS = {"min_tip_clearance": 0.2}
COLUMNS = ("scene", "dimension", "a_equal_peaks", "a_feasible_min", "a_feasible_max",
           "feasible_min_binds", "feasible_max_binds", "n_solves_equal_peaks", "n_solves", "note")


def direct_root(case, f, lo: float, hi: float) -> tuple[float, int]:
    """(the root of ``f`` (a function of a summary) in ``a`` between ``lo``
    and ``hi`` by cold solves of ``case``, the solves;
    tests/reference/solves.py)."""
    return solves.direct_root(case, "lay.stinger.a", f, lo, hi, XTOL)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=REPO / "benchmarks" / "out" / "select_sens")
    parser.add_argument("--workers", type=int, default=1)
    args = parser.parse_args()
    spec = tomllib.loads((REPO / "sweeps" / "paper.toml").read_text())
    spec["sensitivities"] = ["lay.stinger.a"]
    sweep = load_sweep(spec, base_dir=REPO / "sweeps")
    report = run_sweep(sweep, args.out, workers=args.workers, progress=False)
    print(json.dumps(machine_info()))
    out = {"machine": machine_info(), "groups": [],
           "sweep": {"seconds": report.seconds, "solve_seconds": report.solve_seconds,
                     "solved": report.solved, "skipped": report.skipped}}
    tables = {}
    for sens in (True, False):
        t0 = time.perf_counter()
        tables[sens] = select(args.out, write=False, limits=LIMITS, sensitivities=sens)
        out[f"select_seconds_{sens}"] = time.perf_counter() - t0
    for (_, with_), (_, without) in zip(tables[True].iterrows(), tables[False].iterrows(),
                                        strict=True):
        group = {"with": {c: with_[c] for c in COLUMNS},
                 "without": {c: without[c] for c in COLUMNS}}
        out["groups"].append(group)
        if not math.isfinite(with_["a_equal_peaks"]):
            continue
        scene = sweep.scene(with_["scene"])
        case = scene.case_for({"current_speed": with_["current_speed"],
                               "current_heading": with_["current_heading_deg"],
                               "a": with_["a_equal_peaks"]})
        a = with_["a_equal_peaks"]
        grid = sorted(scene.axes["a"])
        lo = max(x for x in grid if x <= a)
        hi = min(x for x in grid if x > a)
        group["direct_equal_peaks"] = direct_root(
            case, lambda s: s["overbend_max_von_mises"] - s["sagbend_max_von_mises"], lo, hi)
        for end in ("min", "max"):
            x = with_[f"a_feasible_{end}"]
            if with_[f"feasible_{end}_binds"].startswith("tip_clearance") and x not in grid:
                lo = max(v for v in grid if v <= x)
                hi = min(v for v in grid if v > x)
                group[f"direct_feasible_{end}"] = direct_root(
                    case, lambda s: s["tip_clearance"] - LIMITS["min_tip_clearance"], lo, hi)
        print(json.dumps(group, default=str))
    (args.out / "bench_select_sensitivities.json").write_text(
        json.dumps(out, indent=1, default=str))


if __name__ == "__main__":
    main()

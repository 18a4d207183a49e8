"""Sensitivities (``pf.solve(case, sensitivities=[...])``): cost, step size, agreement.

    python benchmarks/bench_sensitivity.py [--repeats N] [--quick] [--cases NAME ...]
                                           [--out DIR]

1. Cost: per case, the median over ``--repeats`` runs (after a warm-up run
   that compiles, timed apart) of a solve, of the sensitivity table with no
   key (the solution's own refinement, shared by the keys) and with every
   key; the cost of a key is (with every key - with none) / keys, and its
   ratio to the solve's time is of the same run. Then the table's parts
   (PARTS: the neighbours' cases, guesses, meshes, Newton calls and
   post-processing, the base's included), each as its time per key over
   the solve's, timed in further runs.
2. Step size: the sensitivities of S67 2D at relative steps 1e-2 .. 1e-6
   against the reference (3).
3. Agreement: every numeric summary column by every key against the
   reference: central differences of full solves (each case built, meshed
   and solved from scratch at p +- h) at h = 1e-3 |p| (OWN_STEP of a key
   that has one) and 2h, to a solver
   tolerance of 1e-11, Richardson-extrapolated, (4 D(h) - D(2h)) / 3. A
   column whose relative change per relative change of the key is below
   1e-3 is "insensitive" (the reference's round-off over the step is then
   1e-10 / 2e-3 / 1e-3 = 5e-5 of its derivative, or more).

Writes bench_sensitivity.json into --out (default benchmarks/out) and
prints the tables as markdown.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
import time
from contextlib import contextmanager
from pathlib import Path

from bench_jlay import machine_info

import pipelay_fast as pf
from pipelay_fast.engine import sensitivity as ES
from pipelay_fast.input.case import Case
from pipelay_fast.input.examples import example_path
from pipelay_fast.input.validate import get_path
from pipelay_fast.output import sensitivity as S

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))  # the repository root, for tests.reference
from tests.reference.solves import richardson  # noqa: E402

KEYS = ("lay.stinger.a", "lay.top_tension", "environment.water_depth",
        "environment.current.speed", "lay.stinger.height_shift")
CASES = ("s67", "s125", "j125_2d", "s67_rollers", "s67_3d", "s125_3d", "j125_3d")
QUICK_CASES = ("s67", "j125_2d", "s67_3d")
STUDY_STEPS = (1e-2, 1e-3, 1e-4, 1e-5, 1e-6)
REFERENCE_STEP = 1e-3
# a key's own reference step (absolute, its unit): S67's rollers change
# contact (22 to 21) 3e-3 m up and move the overbend peak to another roller
# between 1e-4 and 3e-4 m (a kink), so the reference's steps are 5e-5 and 1e-4 m there
OWN_STEP = {"lay.stinger.height_shift": 5e-5}
REFERENCE_TOL = 1e-11
INSENSITIVE = 1e-3
INPUTS = ("a", "stinger_radius", "roller_shift", "water_depth", "current_speed",
          "current_heading_deg")


def keys_of(case) -> list[str]:
    """The keys of KEYS the case gives a number for."""
    tables = case.to_dict()
    return [key for key in KEYS if isinstance(get_path(tables, key), (int, float))
            and not isinstance(get_path(tables, key), bool)]


# the parts of a sensitivity table timed apart (module, function): the
# neighbours' cases, their first guesses, their meshes, their residuals, the
# linear responses (one factorisation for every neighbour), their completion
# (2D's kernels: a 3D case's are not timed) and their post-processing
PARTS = {"case": (Case, "with_number"), "guess": (S, "guess_sizes"),
         "mesh": (ES, "regraded_problem"), "residual": (ES, "residual_2d"),
         "response": (ES, "responses_2d"), "finish": (ES, "finish_2d"),
         "post-processing": (S, "_side")}


@contextmanager
def timed_parts(spent: dict):
    """Add the seconds spent in each of PARTS into ``spent`` (the mesh's
    include the guess a side makes itself) while in the block."""
    saved = {part: getattr(owner, name) for part, (owner, name) in PARTS.items()}

    def timer(part, function):
        def timed(*args, **kwargs):
            t0 = time.perf_counter()
            try:
                return function(*args, **kwargs)
            finally:
                spent[part] = spent.get(part, 0.0) + time.perf_counter() - t0
        return timed

    try:
        for part, (owner, name) in PARTS.items():
            setattr(owner, name, timer(part, saved[part]))
        yield spent
    finally:
        for part, (owner, name) in PARTS.items():
            setattr(owner, name, saved[part])


def cost(name: str, repeats: int) -> dict:
    """Median times [s] of a solve and of the sensitivity table, no key and
    every key; and the parts of the table with every key, as shares of the
    solve per key (their sum over the repeats over that of the solves)."""
    case = pf.load_case(example_path(name))
    keys = keys_of(case)
    t0 = time.perf_counter()
    result = pf.solve(case, sensitivities=keys)  # warm-up: compiles
    warm_up = time.perf_counter() - t0
    solve, base, every = [], [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = pf.solve(case)
        t1 = time.perf_counter()
        S.sensitivity_table(case, result.state, [], result.functional)
        t2 = time.perf_counter()
        table = S.sensitivity_table(case, result.state, keys,
                                    result.functional)
        t3 = time.perf_counter()
        solve.append(t1 - t0)
        base.append(t2 - t1)
        every.append(t3 - t2)
    spent = {}
    with timed_parts(spent):
        for _ in range(repeats):
            S.sensitivity_table(case, result.state, keys, result.functional)
    t_solve, t_base, t_every = (statistics.median(v) for v in (solve, base, every))
    per_key = (t_every - t_base) / len(keys)
    parts = {part: spent.get(part, 0.0) / len(keys) / sum(solve) for part in PARTS}
    return {"case": name, "keys": keys, "warm_up_s": warm_up, "solve_s": t_solve,
            "base_s": t_base, "every_key_s": t_every, "per_key_s": per_key,
            "per_key_ratio": per_key / t_solve,
            "per_key_ratio_with_base": t_every / len(keys) / t_solve,
            "parts_per_key_ratio": parts,
            "solve_iterations": result.summary["n_iterations"],
            "nan_reasons": sorted({r.split(": ", 1)[1][:90] for r in table["reason"] if r})}


def reference(case, key) -> dict:
    """Richardson-extrapolated central differences of full solves, per column
    (tests/reference/solves.py)."""
    p = float(get_path(case.to_dict(), key))
    h = OWN_STEP.get(key, REFERENCE_STEP * (abs(p) or 1.0))  # (absolute where p = 0)
    return richardson(case, key, p, h, S.summary_rows())


def compare(case, summary, table, key, ref) -> dict:
    """Per column: relative difference, "insensitive", or "NaN: reason"."""
    p = float(get_path(case.to_dict(), key))
    out = {}
    for name, fd in ref.items():
        if name in INPUTS or not math.isfinite(fd):
            continue
        value, got = summary[name], table.loc[name, key]
        if not math.isfinite(got):
            out[name] = "NaN: " + table.loc[name, "reason"].split(f"{key}: ", 1)[-1][:70]
        elif abs(fd * (p or 1.0)) <= INSENSITIVE * abs(value):
            out[name] = "insensitive"
        else:
            out[name] = abs(got - fd) / abs(fd)
    return out


def agreement(names) -> dict:
    """{case: {key: {column: relative difference or a word}}}."""
    rows = {}
    for name in names:
        case = pf.load_case(example_path(name)).with_changes({"solver.tolerance": REFERENCE_TOL})
        keys = keys_of(case)
        result = pf.solve(case, sensitivities=keys)
        table = result.sensitivities
        rows[name] = {}
        for key in keys:
            if table[key].isna().all():  # (no reference solves: 3D friction's, at 1e-11)
                reason = table.loc[table.index[0], "reason"].split(f"{key}: ", 1)[-1]
                rows[name][key] = {"every column": "NaN: " + reason[:70]}
            else:
                rows[name][key] = compare(case, result.summary, table, key, reference(case, key))
    return rows


def step_study() -> dict:
    """{step: {key: the largest relative difference over the sensitive columns}}."""
    case = pf.load_case(example_path("s67")).with_changes({"solver.tolerance": REFERENCE_TOL})
    keys = keys_of(case)
    refs = {key: reference(case, key) for key in keys}
    saved = S.STEP
    out = {}
    try:
        for step in STUDY_STEPS:
            S.STEP = step
            result = pf.solve(case, sensitivities=keys)
            out[step] = {}
            for key in keys:
                diffs = compare(case, result.summary, result.sensitivities, key, refs[key])
                numbers = [v for name, v in diffs.items()
                           if isinstance(v, float) and name != "liftoff_reaction"]
                out[step][key] = max(numbers) if numbers else math.nan
    finally:
        S.STEP = saved
    return out


def _markdown(costs, study, agree) -> str:
    lines = ["## Cost (median, same run)", "",
             "| case | keys | solve [ms] | base [ms] | per key [ms] | per key / solve "
             "| with base share | solve its |",
             "|---|---|---|---|---|---|---|---|"]
    lines.extend(f"| {c['case']} | {len(c['keys'])} | {1e3 * c['solve_s']:.1f} | "
                 f"{1e3 * c['base_s']:.1f} | {1e3 * c['per_key_s']:.1f} | "
                 f"{c['per_key_ratio']:.2f} | {c['per_key_ratio_with_base']:.2f} | "
                 f"{c['solve_iterations']} |" for c in costs)
    lines += ["", "## A key's parts (with the base's), per key / solve", "",
              "| case | " + " | ".join(PARTS) + " |", "|---" * (1 + len(PARTS)) + "|"]
    lines.extend(f"| {c['case']} | " + " | ".join(f"{c['parts_per_key_ratio'][part]:.3f}"
                                                  for part in PARTS) + " |" for c in costs)
    lines += ["", "## Step-size study (S67 2D): largest relative difference to the reference",
              "", "| step | " + " | ".join(next(iter(study.values()))) + " |",
              "|---" * (1 + len(next(iter(study.values())))) + "|"]
    for step, row in study.items():
        lines.append(f"| {step:g} | " + " | ".join(f"{v:.1e}" for v in row.values()) + " |")
    for name, keys in agree.items():
        lines += ["", f"## Agreement, {name}", "", "| column | " + " | ".join(keys) + " |",
                  "|---" * (1 + len(keys)) + "|"]
        columns = list(dict.fromkeys(col for row in keys.values() for col in row))
        for col in columns:
            cells = [keys[k].get(col, "") for k in keys]
            lines.append(f"| {col} | " + " | ".join(
                f"{v:.1e}" if isinstance(v, float) else v for v in cells) + " |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=9)
    parser.add_argument("--quick", action="store_true", help=f"cases {QUICK_CASES} only")
    parser.add_argument("--cases", nargs="+", choices=CASES, help="these cases only")
    parser.add_argument("--out", type=Path, default=REPO / "benchmarks" / "out")
    args = parser.parse_args(argv)
    names = args.cases or (QUICK_CASES if args.quick else CASES)
    info = machine_info()
    print(json.dumps(info))
    costs = [cost(name, args.repeats) for name in names]
    study = step_study()
    agree = agreement(names)
    args.out.mkdir(parents=True, exist_ok=True)
    record = {"machine": info, "cost": costs, "step_study": {str(k): v for k, v in study.items()},
              "agreement": agree}
    (args.out / "bench_sensitivity.json").write_text(json.dumps(record, indent=1, default=str))
    print(_markdown(costs, study, agree))


if __name__ == "__main__":
    main()

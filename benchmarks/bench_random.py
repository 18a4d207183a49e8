"""Reliability on random realistic cases (issue 42), each answer checked independently.

    python benchmarks/bench_random.py [--seed 1] [--n2d 400] [--n3d 300] [--quick]
                                      [--workers 2] [--timeout 60] [--out DIR]
    python benchmarks/bench_random.py --case SEED:2d-INDEX   (or SEED:3d-INDEX)

The cases: ``random_lay.py``'s generator (its docstring states every range and
rule; a case depends only on its seed, dimension and index). ``--quick``: 40
2D and 30 3D cases. ``--case`` re-runs one case in this process and prints its
inputs, the engine's answer, the reference's and the checks.

2D (no current): the engine against the planar inextensible elastica of
``tests/reference`` (J-lay ``jlay_elastica``, S-lay ``slay_elastica``): top
and bottom tension and the peak moments within AGREE (relative; a moment's
relative to at least 1 % of the largest reference peak). A case is
``agree``; ``disagree`` (then solved again on 1 m elements, and on 1 m
inextensible: ``disagree (mesh agrees)`` when the finer mesh alone agrees,
``(mesh, extension agrees)`` when the inextensible rod on it does);
``FAILURE`` (the engine refuses, the reference solves, below the strain
limit); ``refused for strain`` (the engine names the strain; ``(reference
below)`` when the reference's own is below STRAIN_SHARE of the limit);
``both refuse``; ``reference refuses`` (the engine solves); ``invalid`` (the
case is refused on input).

3D (current at any heading, lateral friction): the answer's admissibility
(``bench_contact.admissibility``: contacts push, vertical reactions and drag
carry the weight, friction inside its cone, the lateral reactions balance the
drag); a case without lateral load (current 0, or along the lay) is solved in
2D too and must give the same figures (PLANAR_RTOL). A case that fails only a
balance with the drag is solved again on the DIAGNOSIS mesh (``admissible
(mesh)`` when it passes there: the check's quadrature of the drag and the
engine's part on coarse elements, and converge together).

Each refusal is put in a class of issue 42 (``issue_class``). Every case runs
in one of ``--workers`` spawned processes (``timed_pool.Pool``), killed after
``--timeout`` seconds per solve. Writes ``bench_random.json`` (every case: its
inputs, what was drawn, status, message, Newton iterations, current steps and
the largest step's iterations, wall time, key outputs, the checks) and
``bench_random.md`` into --out (default benchmarks/out).
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np
import pandas as pd
import random_lay as rl
from bench_contact import admissibility, contact_pull, message_group, table
from bench_jlay import machine_info
from timed_pool import Pool

import pipelay_fast as pf

AGREE = 5e-3  # -, 2D engine against the reference: tensions and peak moments
PLANAR_RTOL = 1e-6  # -, 3D against 2D without lateral load
# a disagreement solved again on finer elements, then inextensible too (the reference's rod)
DIAGNOSIS = {"mesh": {"solver.element_length": 1.0},
             "mesh, extension": {"solver.element_length": 1.0, "pipe.extensible": False}}
KEYS = ("top_tension", "bottom_tension", "sagbend_max_moment", "overbend_max_moment",
        "max_von_mises", "max_strain", "tdp_z", "liftoff_z", "max_lateral_deflection",
        "n_iterations", "n_current_steps", "max_current_step_iterations", "n_elements",
        "n_meshes")
CLASSES = {1: "S-lay fails at the first load step", 2: "bending-dominated J-lay",
           3: "deep J-lay, strong current", 4: "straight stinger (a = 0)",
           5: "near-rigid pipe (E = 1e15 Pa)", 0: "other"}
STRAIN_SHARE = 0.9  # a strain refusal is doubtful where the reference's is below this share
FIRST_STEP = 1e-3  # a load factor this small: the S-lay failed at its first load step
BENDING_RATIO = 0.2  # flexural length sqrt(EI/H) over depth above which a J-lay bends
QUICK = (40, 30)
# the checks that re-integrate the drag (bench_contact.admissibility's DRAG_QUADRATURE)
DRAG_CHECKS = {"weight", "lateral"}


def _finite(v):
    return None if isinstance(v, float) and not math.isfinite(v) else v


def engine(case: pf.Case) -> tuple[dict, pf.Result | None]:
    """The engine's answer: status, message, seconds and KEYS (max_moment: the
    profile's largest moment; contact_pull's figures)."""
    t0 = time.perf_counter()
    try:
        result = pf.solve(case)
    except (pf.SolveError, ValueError) as err:
        status = "failed" if isinstance(err, pf.SolveError) else "invalid"
        return {"status": status, "message": f"{type(err).__name__}: {err}",
                "seconds": time.perf_counter() - t0}, None
    seconds = time.perf_counter() - t0
    s = result.summary
    out = {"status": "ok", "message": "", "seconds": seconds,
           **{k: _finite(s[k]) for k in KEYS},
           "max_moment": float(result.profile["moment"].max()), **contact_pull(result.profile)}
    return out, result


def _strain_refusal(message: str) -> bool:
    return "max_strain" in message or "strain reaches" in message


def reference_of(case: pf.Case) -> dict:
    t0 = time.perf_counter()
    try:
        with np.errstate(all="ignore"):
            ref = rl.reference(case)
    except Exception as err:  # noqa: BLE001  (a reference that finds no equilibrium, or a bug)
        return {"status": "failed", "message": f"{type(err).__name__}: {str(err)[:300]}",
                "seconds": time.perf_counter() - t0}
    return {"status": "ok", "seconds": time.perf_counter() - t0, **ref}


def _worst(diff: dict) -> float:
    return max((abs(v) for v in diff.values()), default=0.0)


def diagnose(case: pf.Case, ref: dict) -> dict:
    """The DIAGNOSIS solves of a disagreement: each one's answer and differences."""
    out = {}
    for name, changes in DIAGNOSIS.items():
        fine, _ = engine(case.with_changes(changes))
        if fine["status"] == "ok":
            fine["diff"] = rl.compare(fine, ref)
            fine["worst"] = _worst(fine["diff"])
        out[name] = fine
    return out


def drawn_case(seed: int, dim: int, index: int) -> tuple[dict, pf.Case | None]:
    """The record of a case's inputs, and the case (None, the record saying why,
    when it is refused on input)."""
    example, changes, drawn = rl.case_changes(seed, dim, index)
    rec = {"id": f"{seed}:{dim}d-{index}", "dim": f"{dim}d", "example": example,
           "changes": changes, "drawn": drawn}
    try:
        return rec, rl.load(example).with_changes(changes)
    except ValueError as err:
        return rec | {"status": "invalid", "message": f"ValueError: {err}",
                      "check": "invalid"}, None


def run_2d(seed: int, index: int) -> dict:
    """Job: a 2D case, the engine against the reference, classified."""
    rec, case = drawn_case(seed, 2, index)
    if case is None:
        return rec
    eng, _ = engine(case)
    ref = reference_of(case)
    rec |= {"status": eng["status"], "message": eng["message"], "engine": eng, "reference": ref}
    if eng["status"] == "ok" and ref["status"] == "ok":
        diff = rl.compare(eng, ref)
        rec |= {"diff": diff, "worst": _worst(diff)}
        rec["check"] = "agree" if rec["worst"] <= AGREE else "disagree"
        if rec["check"] == "disagree":
            rec["diagnosis"] = diagnose(case, ref)
            cause = next((k for k, v in rec["diagnosis"].items() if v.get("worst", 1) <= AGREE),
                         None)
            rec["check"] += f" ({cause} agrees)" if cause else ""
    elif eng["status"] == "ok":
        rec["check"] = "reference refuses"
    elif _strain_refusal(eng["message"]):
        below = ref["status"] == "ok" and ref["max_strain"] < STRAIN_SHARE * case.solver.max_strain
        rec["check"] = "refused for strain" + (" (reference below)" if below else "")
    elif ref["status"] == "ok" and ref["max_strain"] <= case.solver.max_strain:
        rec["check"] = "FAILURE"
    else:
        rec["check"] = "both refuse" if ref["status"] != "ok" else "refused (reference strained)"
    return rec


def run_3d(seed: int, index: int) -> dict:
    """Job: a 3D case and its admissibility; without lateral load, 3D against 2D."""
    rec, case = drawn_case(seed, 3, index)
    if case is None:
        return rec
    eng, result = engine(case)
    rec |= {"status": eng["status"], "message": eng["message"], "engine": eng}
    if result is None:
        rec["check"] = "refused for strain" if _strain_refusal(eng["message"]) else "FAILURE"
        return rec
    checks = admissibility(case, result.profile)
    rec["admissibility"] = {k: (bool(v) if isinstance(v, (bool, np.bool_)) else float(v))
                            for k, v in checks.items()}
    bad = [name for name, k in (("pulls", "pushes"), ("weight", "weight_ok"),
                                ("cone", "cone_ok"), ("lateral", "lateral_ok")) if not checks[k]]
    if rec["drawn"]["planar"]:
        twin, _ = engine(case.with_changes({"solver.dimension": "2d"}))
        rec["planar"] = twin | {"diff": rl.compare(eng, twin) if twin["status"] == "ok" else {}}
        if twin["status"] != "ok" or _worst(rec["planar"]["diff"]) > PLANAR_RTOL:
            bad.append("3D = 2D")
    if bad and set(bad) <= DRAG_CHECKS and case.environment.current.speed > 0.0:
        rec["check"] = _drag_on_mesh(case, bad)
    else:
        rec["check"] = "admissible" if not bad else "CHECK FAILS: " + ", ".join(bad)
    return rec


def _drag_on_mesh(case: pf.Case, bad: list[str]) -> str:
    """A balance with the drag that fails on the case's mesh, checked again on the
    DIAGNOSIS mesh: the engine's drag (on its Hermite elements) and the check's
    (a spline through the nodes) are two quadratures of one integral, which part
    as the elements coarsen; a balance that holds on the finer mesh is
    ``admissible (mesh)``."""
    fine_case = case.with_changes(DIAGNOSIS["mesh"])
    fine, result = engine(fine_case)
    if result is None:
        return "CHECK FAILS: " + ", ".join(bad) + f" (mesh: {fine['status']})"
    checks = admissibility(fine_case, result.profile)
    still = [name for name in bad if not checks[f"{name}_ok"]]
    return "admissible (mesh)" if not still else "CHECK FAILS: " + ", ".join(bad) + " (mesh too)"


def issue_class(rec: dict) -> int:
    """The class of issue 42 a refusal belongs to (0: none of them)."""
    d, msg = rec["drawn"], rec.get("message", "")
    if d.get("straight"):
        return 4
    if d.get("rigid"):
        return 5
    if d["method"] == "S":
        factor = re.search(r"(?:load|gravity) factor ([0-9.e+-]+)", msg)
        return 1 if factor and float(factor.group(1)) <= FIRST_STEP else 0
    speed = rec["changes"].get("environment.current.speed", 0.0)
    if rec["dim"] == "3d" and d["depth"] >= 900.0 and speed >= 1.2:
        return 3
    if d["flexural_ratio"] >= BENDING_RATIO or (d["od"] >= 0.9 and d["depth"] <= 110.0):
        return 2
    return 0


def warm_up():
    for example in ("j125_2d", "s67", "s67_3d"):
        pf.solve(rl.load(example))


# --------------------------------------------------------------------------- report


def _percentiles(values) -> str:
    v = np.asarray([x for x in values if x is not None], dtype=float)
    if not v.size:
        return "-"
    return (f"median {np.median(v):.3g}, p99 {np.percentile(v, 99):.3g}, "
            f"max {v.max():.3g}")


def rates(recs: list[dict]) -> pd.DataFrame:
    rows = []
    for (dim, method), g in pd.DataFrame(
            [{"dim": r["dim"], "method": r["drawn"]["method"] + "-lay",
              "status": r["status"], "check": r["check"]} for r in recs]).groupby(
            ["dim", "method"]):
        ok = int((g["status"] == "ok").sum())
        rows.append({"dim": dim, "method": method, "cases": len(g), "engine solves": ok,
                     "rate": f"{100.0 * ok / len(g):.1f} %",
                     **Counter(g["check"])})
    return pd.DataFrame(rows).fillna(0)


def tails(recs: list[dict]) -> list[str]:
    lines = []
    for dim in ("2d", "3d"):
        ok = [r["engine"] for r in recs if r["dim"] == dim and r["status"] == "ok"]
        if not ok:
            continue
        lines.append(f"{dim.upper()} Newton iterations per solve: "
                     f"{_percentiles(e['n_iterations'] for e in ok)}")
        if dim == "3d":
            path = [e for e in ok if e["n_current_steps"]]
            lines.append(f"3D iterations of the largest current step ({len(path)} solves with "
                         "a current's path): "
                         f"{_percentiles(e['max_current_step_iterations'] for e in path)}; "
                         f"current steps: {_percentiles(e['n_current_steps'] for e in path)}")
        every = [r.get("engine", r).get("seconds") for r in recs if r["dim"] == dim]
        lines.append(f"{dim.upper()} engine wall time [s], solved: "
                     f"{_percentiles(e['seconds'] for e in ok)}, over 1 s: "
                     f"{sum(e['seconds'] > 1.0 for e in ok)}; every solve, refusals and "
                     f"timeouts too: {_percentiles(every)}, over 1 s: "
                     f"{sum(t > 1.0 for t in every if t is not None)}")
    refs = [r["reference"]["seconds"] for r in recs if "reference" in r]
    if refs:
        lines.append(f"2D reference wall time [s]: {_percentiles(refs)}")
    return lines


def _inputs(rec: dict) -> str:
    d, ch = rec["drawn"], rec["changes"]
    text = (f"{d['method']}-lay d={d['depth']:.0f} OD={d['od']:.3f} D/t={d['d_over_t']:.1f} "
            f"coat={d['coating_mm']:.0f}mm@{d['coating_density']:.0f} {d['tension']} "
            f"T={(ch.get('lay.top_tension') or ch.get('lay.bottom_tension')) / 1e3:.0f}kN "
            f"top {d['top']} flex/d={d['flexural_ratio']:.2g}")
    if d["method"] == "S":
        text += f" tip={d['tip_deg']:.0f}deg a={ch['lay.stinger.a']:.3g}"
    if d.get("rigid"):
        text += " E=1e15"
    if rec["dim"] == "3d":
        text += (f" V={ch['environment.current.speed']:.2f}@"
                 f"{ch.get('environment.current.heading', 0.0):.0f}deg "
                 f"mu={ch.get('seabed.lateral_friction', 0.0):.2f}")
    return text


def failing(recs: list[dict]) -> pd.DataFrame:
    """Every case not agreed or admissible, with its inputs and why."""
    rows = []
    for r in recs:
        if r["check"] in ("agree", "admissible", "admissible (mesh)"):
            continue
        why = r.get("message", "")
        if r["check"].startswith("disagree"):
            why = ", ".join(f"{k} {100 * v:+.2f}%" for k, v in r["diff"].items())
            for name, fine in r["diagnosis"].items():
                why += f"; {name}: " + (", ".join(
                    f"{k} {100 * v:+.2f}%" for k, v in fine["diff"].items()) if "diff" in fine
                    else fine.get("message", "")[:120])
        elif r["check"] == "reference refuses":
            why = r["reference"]["message"]
        elif r["check"].startswith("CHECK FAILS"):
            why = json.dumps(r.get("admissibility", {})) + json.dumps(r.get("planar", {})
                                                                      .get("diff", {}))
        ref_strain = (r.get("reference") or {}).get("max_strain")
        rows.append({"case": r["id"], "check": r["check"], "class": issue_class(r)
                     if r["status"] != "ok" else "-", "inputs": _inputs(r),
                     "ref strain": ref_strain, "why": why[:400]})
    return pd.DataFrame(rows)


def report(recs: list[dict], args, info: dict, seconds: float) -> str:
    md = ["# Random realistic cases (issue 42)", "",
          f"`python benchmarks/bench_random.py {' '.join(args.argv)}`: seed {args.seed}, "
          f"{args.n2d} 2D and {args.n3d} 3D cases, {args.workers} workers, timeout "
          f"{args.timeout:g} s per solve; {seconds:.0f} s in all. The generator: "
          "`benchmarks/random_lay.py`'s docstring. Times are wall clock on a shared machine.",
          "", "## Machine", ""] + [f"- {k}: {v}" for k, v in info.items()]
    md += ["", "## Solve rates and checks", "", table(rates(recs)), "",
           f"2D: `agree` within {100 * AGREE:g} % of the planar elastica in tensions and peak "
           f"moments. 3D: `admissible` passes every check (3D = 2D to {PLANAR_RTOL:g} on the "
           f"{sum(r['drawn']['planar'] for r in recs if r['dim'] == '3d')} cases without "
           "lateral load); `admissible (mesh)` fails a balance with the drag on the case's "
           "mesh (the check's spline quadrature against the engine's elements) and passes it "
           f"on {DIAGNOSIS['mesh']['solver.element_length']:g} m elements."]
    refused = [r for r in recs if r["status"] not in ("ok",)]
    md += ["", "## Refusals by message", ""]
    for dim in ("2d", "3d"):
        groups = Counter(message_group(r.get("message", "")) for r in refused if r["dim"] == dim)
        md += [f"- {dim.upper()}: " + ("none" if not groups else "")]
        md += [f"  - {n} x {m}" for m, n in groups.most_common()]
    md += ["", "## Refusals by class of issue 42", ""]
    by = Counter((issue_class(r), r["dim"], r["check"]) for r in refused)
    md += [table(pd.DataFrame([{"class": f"{c}: {CLASSES[c]}", "dim": d, "check": k, "cases": n}
                               for (c, d, k), n in sorted(by.items())]))] if by else ["none"]
    md += ["", "## Tails", ""] + [f"- {line}" for line in tails(recs)]
    bad = failing(recs)
    md += ["", "## Cases not agreed or admissible (re-run one with `--case ID`)", "",
           table(bad) if len(bad) else "none"]
    return "\n".join(md) + "\n"


def one_case(spec: str) -> None:
    """Run ``SEED:2d-INDEX`` or ``SEED:3d-INDEX`` here and print everything."""
    seed, rest = spec.split(":")
    dim, index = rest.split("-")
    example, changes, drawn = rl.case_changes(int(seed), int(dim[0]), int(index))
    print(f"example {example}\nchanges {json.dumps(changes, indent=1)}\n"
          f"drawn {json.dumps(drawn, indent=1)}", flush=True)
    rec = (run_2d if dim == "2d" else run_3d)(int(seed), int(index))
    for key in ("changes", "drawn"):
        rec.pop(key)
    print(json.dumps(rec, indent=1, default=str))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--n2d", type=int, default=400)
    parser.add_argument("--n3d", type=int, default=300)
    parser.add_argument("--quick", action="store_true", help=f"{QUICK[0]} 2D and {QUICK[1]} 3D")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--timeout", type=float, default=60.0, help="seconds per solve")
    parser.add_argument("--case", metavar="SEED:DIM-INDEX", help="re-run one case, verbosely")
    parser.add_argument("--out", type=Path, default=rl.REPO / "benchmarks" / "out")
    args = parser.parse_args(argv)
    args.argv = sys.argv[1:] if argv is None else list(argv)
    if args.case:
        one_case(args.case)
        return
    if args.quick:
        args.n2d, args.n3d = QUICK
    info = machine_info()
    print("\n".join(f"{k}: {v}" for k, v in info.items()), flush=True)
    t0 = time.perf_counter()
    warm_up()
    pool = Pool(args.workers, warm_up)
    jobs = ([(run_2d, (args.seed, i), 4) for i in range(args.n2d)]
            + [(run_3d, (args.seed, i), 2) for i in range(args.n3d)])
    ids = [f"{args.seed}:2d-{i}" for i in range(args.n2d)]
    ids += [f"{args.seed}:3d-{i}" for i in range(args.n3d)]
    try:
        out = pool.map(jobs, args.timeout, "cases")
    finally:
        pool.close()
    recs = [r if "id" in r else _lost(args.seed, rid, r) for rid, r in zip(ids, out, strict=True)]
    seconds = time.perf_counter() - t0
    md = report(recs, args, info, seconds)
    print(md)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "bench_random.md").write_text(md)
    meta = {"machine": info, "args": {k: v for k, v in vars(args).items() if k != "out"},
            "seconds": seconds, "records": recs}
    (args.out / "bench_random.json").write_text(json.dumps(meta, indent=1, default=str))
    print(f"wrote {args.out / 'bench_random.md'} and {args.out / 'bench_random.json'}")


def _lost(seed: int, rid: str, out: dict) -> dict:
    """A timed-out or crashed job's record, its inputs drawn again."""
    dim, index = rid.split(":")[1].split("-")
    example, changes, drawn = rl.case_changes(seed, int(dim[0]), int(index))
    return {"id": rid, "dim": dim, "example": example, "changes": changes, "drawn": drawn,
            **out, "check": out["status"].upper()}


if __name__ == "__main__":
    main()

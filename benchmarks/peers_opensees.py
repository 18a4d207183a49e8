"""pipelay_fast against an OpenSees peer model: accuracy, agreement and speed.

    python benchmarks/peers_opensees.py [--quick] [--out DIR]

Scenes: J125 (J-lay, pinned top) and S67 (S-lay, a = -0.0012, firing-line top)
from the bundled case files, both in 2D with the current switched OFF in both
tools (``environment.current.speed = 0``): OpenSees has no deformation-dependent
drag. The OpenSees model is ``tests/reference/opensees_peer.py`` (corotational
elastic beams, lumped effective weight, compression-only seabed and stinger
springs; solved from a straight line, independently of pipelay_fast: read its
docstring).

For each scene and element length in LENGTHS (QUICK_LENGTHS with --quick):

* OpenSees: the median wall time of OS_REPEATS solves, each building the model
  from scratch (uniform elements of about the element length);
* pipelay_fast: the median of PF_REPEATS solves after a warm-up solve (JIT
  compilation excluded), with its default grading (finer at touchdown and
  lift-off) and with ``solver.grading = false`` (uniform, like OpenSees).

Outputs compared: max von Mises stress (OpenSees: from its element end forces
with pipelay_fast's formula, ``pipelay_fast.output.results.build_profile``), the
sagbend and overbend peak moments, touchdown z, top and bottom effective tension. Errors: each tool
against ITS OWN finest mesh (OpenSees: OS_REFERENCE m; pipelay_fast:
PF_REFERENCE), relative for stresses, moments and tensions, in metres for
touchdown. Agreement: the two finest meshes against each other.

Speed at equal error: for each tool, the time to reach a given max von Mises
error, read off its time-against-error points (log-log interpolation between
the two meshes that bracket the level; pipelay_fast with grading). Levels: the
OpenSees error at 2 m elements and 1e-3. When every pipelay_fast mesh is
already below the level, its time is that of its fastest mesh (no
extrapolation; flagged ``pipelay_fast_coarsest``, likewise for OpenSees), so
with 1e-3, which both reach at 8 m, the ratio compares the coarsest meshes.
Both pipelay_fast meshes (graded, uniform) are given.

Writes ``peers_opensees.csv`` (one row per scene x tool x mesh),
``peers_opensees.md`` (tables) and ``peers_opensees.json`` (machine, versions,
references) into --out (default benchmarks/out, not committed). ``run(quick)``
returns the same tables as a dict for the main report.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
import time
from importlib.metadata import version
from pathlib import Path

import numpy as np
import pandas as pd
from bench_jlay import machine_info

import pipelay_fast as pf

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))  # the one path edit: the repository root, for tests.reference
from tests.reference import opensees_peer  # noqa: E402

EXAMPLES = Path(pf.__file__).parent / "examples"
SCENES = ("j125", "s67")
LENGTHS = (8.0, 4.0, 2.0, 1.0)  # m
QUICK_LENGTHS = (8.0, 2.0)  # m
OS_REFERENCE = 0.5  # m, OpenSees' finest mesh
PF_REFERENCE = {"solver.element_length": 0.25, "solver.min_element_length": 0.05}
OS_REPEATS = 3
PF_REPEATS, QUICK_PF_REPEATS = 11, 5
LEVEL_FIXED = 1e-3  # -, a fixed max von Mises error level for the speed ratio
QUANTITIES = ("max_von_mises", "sagbend_max_moment", "overbend_max_moment", "tdp_z",
              "top_tension", "bottom_tension")
RELATIVE = ("max_von_mises", "sagbend_max_moment", "overbend_max_moment", "top_tension",
            "bottom_tension")


def scene_case(name: str) -> pf.Case:
    """The bundled scene, current off, solved in 2D."""
    return pf.load_case(EXAMPLES / f"{name}.toml").with_changes(
        {"environment.current.speed": 0.0, "solver.dimension": "2d"})


def time_opensees(case: pf.Case, h: float, repeats: int):
    """(summary, median wall time [s], stats) of ``repeats`` OpenSees solves."""
    times, res = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = opensees_peer.solve(case, h)
        times.append(time.perf_counter() - t0)
    return res.summary, statistics.median(times), res.stats


def time_pipelay(case: pf.Case, repeats: int):
    """(summary, median wall time [s]) of ``repeats`` solves after a warm-up."""
    s = pf.solve(case).summary
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        s = pf.solve(case).summary
        times.append(time.perf_counter() - t0)
    return s, statistics.median(times)


def errors(s: dict, ref: dict) -> dict:
    out = {}
    for q in RELATIVE:
        a, b = s.get(q, math.nan), ref.get(q, math.nan)
        out[f"{q}_err"] = abs(a - b) / abs(b) if np.isfinite(b) and b != 0 else math.nan
    out["tdp_err_m"] = abs(s["tdp_z"] - ref["tdp_z"])
    return out


def row(scene, tool, grading, h, s, seconds, ref, extra=None) -> dict:
    r = {"scene": scene, "tool": tool, "grading": grading, "element_length": h,
         "n_elements": int(s["n_elements"]), "median_ms": 1e3 * seconds}
    r |= {q: s[q] for q in QUANTITIES}
    r |= errors(s, ref)
    return r | (extra or {})


def time_at_error(points: pd.DataFrame, level: float) -> tuple[float, bool]:
    """Time [ms] at max von Mises error ``level`` from (median_ms, max_von_mises_err)
    points: log-log interpolation between the bracketing meshes. Returns (time,
    bracketed); bracketed is False when every point is already below the level
    (the fastest point's time: an upper bound); NaN when none reaches it."""
    p = points.sort_values("median_ms")
    t, e = p["median_ms"].to_numpy(), np.maximum(p["max_von_mises_err"].to_numpy(), 1e-12)
    if (e <= level).all():
        return float(t[0]), False
    for i in range(len(t) - 1):
        lo, hi = e[i], e[i + 1]
        if (lo - level) * (hi - level) <= 0.0 and lo != hi:
            f = math.log(level / lo) / math.log(hi / lo)
            return float(math.exp(math.log(t[i]) + f * math.log(t[i + 1] / t[i]))), True
    below = p[e <= level]
    return (float(below["median_ms"].min()), True) if len(below) else (math.nan, True)


def speed_rows(scene: str, df: pd.DataFrame) -> list[dict]:
    """Times of both tools at the speed levels, pipelay_fast graded and uniform."""
    theirs = df[(df["tool"] == "opensees") & (df["element_length"] != OS_REFERENCE)]
    at2 = theirs[theirs["element_length"] == 2.0]
    levels = ([("OpenSees error at 2 m", float(at2["max_von_mises_err"].iloc[0]))]
              if len(at2) else []) + [("fixed", LEVEL_FIXED)]
    out = []
    for name, level in levels:
        t_os, os_bracketed = time_at_error(theirs, level)
        for grading in ("graded", "uniform"):
            ours = df[(df["tool"] == "pipelay_fast") & (df["grading"] == grading)]
            t_pf, pf_bracketed = time_at_error(ours, level)
            out.append({"scene": scene, "level": name, "vm_error": level,
                        "pipelay_fast_mesh": grading, "opensees_ms": t_os,
                        "pipelay_fast_ms": t_pf, "ratio": t_os / t_pf,
                        "opensees_coarsest": not os_bracketed,
                        "pipelay_fast_coarsest": not pf_bracketed})
    return out


def run(quick: bool = False, log=print) -> dict:
    """Measure both tools on both scenes; returns tables (pandas) and metadata."""
    t_run = time.perf_counter()
    lengths = QUICK_LENGTHS if quick else LENGTHS
    pf_repeats = QUICK_PF_REPEATS if quick else PF_REPEATS
    info = machine_info() | {"openseespy": version("openseespy")}
    rows, agreement, speed, refs = [], [], [], {}
    for scene in SCENES:
        case = scene_case(scene)
        pf.solve(case)  # compile or load the kernels before any timing
        t0 = time.perf_counter()
        pf_ref = pf.solve(case.with_changes(PF_REFERENCE)).summary
        pf_ref_s = time.perf_counter() - t0
        os_ref_res = opensees_peer.solve(case, OS_REFERENCE)
        os_ref = os_ref_res.summary
        refs[scene] = {"pipelay_fast": {"settings": PF_REFERENCE, "seconds": pf_ref_s,
                                        **{q: pf_ref[q] for q in (*QUANTITIES, "n_elements")}},
                       "opensees": {"element_length": OS_REFERENCE, **os_ref,
                                    "checks": os_ref_res.stats}}
        log(f"{scene}: references pipelay_fast {pf_ref['n_elements']} elements "
            f"({pf_ref_s:.1f} s), OpenSees {os_ref['n_elements']} elements "
            f"({os_ref['solve_seconds']:.1f} s)")
        rows.append(row(scene, "opensees", "uniform", OS_REFERENCE, os_ref,
                        os_ref["solve_seconds"], os_ref, {"repeats": 1}))
        for h in lengths:
            s, sec, st = time_opensees(case, h, OS_REPEATS)
            rows.append(row(scene, "opensees", "uniform", h, s, sec, os_ref,
                            {"repeats": OS_REPEATS, "iterations": st["iterations"]}))
            for grading in (True, False):
                s, sec = time_pipelay(case.with_changes(
                    {"solver.element_length": h, "solver.grading": grading}), pf_repeats)
                rows.append(row(scene, "pipelay_fast", "graded" if grading else "uniform", h,
                                s, sec, pf_ref, {"repeats": pf_repeats,
                                                 "iterations": s["n_iterations"]}))
            for r in rows[-3:]:
                log(f"  {r['tool']:12s} {r['grading']:7s} {h:4g} m {r['n_elements']:5d} el "
                    f"{r['median_ms']:9.2f} ms  vm err {r['max_von_mises_err']:.2e}  "
                    f"tdp err {r['tdp_err_m']:.3f} m")
        agreement.append({"scene": scene} | {
            q: (os_ref[q] - pf_ref[q]) / abs(pf_ref[q]) if q != "tdp_z"
            else os_ref[q] - pf_ref[q] for q in QUANTITIES})
        speed += speed_rows(scene, pd.DataFrame([r for r in rows if r["scene"] == scene]))
    meta = {"machine": info, "quick": quick, "lengths": lengths, "os_repeats": OS_REPEATS,
            "pf_repeats": pf_repeats, "references": refs,
            "run_s": time.perf_counter() - t_run}
    return {"rows": pd.DataFrame(rows), "agreement": pd.DataFrame(agreement),
            "speed": pd.DataFrame(speed), "meta": meta}


def markdown(df: pd.DataFrame, fmt: dict | None = None) -> str:
    fmt = fmt or {}

    def cell(col, v):
        if isinstance(v, float):
            if math.isnan(v):
                return "-"
            return fmt.get(col, "{:.3g}").format(v)
        return str(v)

    lines = ["| " + " | ".join(df.columns) + " |", "|" + "---|" * len(df.columns)]
    lines += ["| " + " | ".join(cell(c, v) for c, v in zip(df.columns, r, strict=True)) + " |"
              for r in df.itertuples(index=False)]
    return "\n".join(lines)


def report(res: dict) -> str:
    meta = res["meta"]
    rows = res["rows"]
    err_fmt = {c: "{:.2e}" for c in rows.columns if c.endswith("_err")}
    cols = ["scene", "tool", "grading", "element_length", "n_elements", "median_ms",
            "max_von_mises_err", "sagbend_max_moment_err", "overbend_max_moment_err",
            "tdp_err_m", "top_tension_err", "bottom_tension_err"]
    agree = res["agreement"].copy()
    agree_fmt = {q: "{:+.2e}" for q in QUANTITIES} | {"tdp_z": "{:+.3f} m"}
    speed_fmt = {"vm_error": "{:.2e}", "opensees_ms": "{:.1f}", "pipelay_fast_ms": "{:.2f}",
                 "ratio": "{:.1f}"}
    out = ["# pipelay_fast against OpenSees", "",
           "Generated by `python benchmarks/peers_opensees.py"
           + (" --quick" if meta["quick"] else "") + "` (see its docstring). Current "
           "OFF in both tools. Times: OpenSees median of "
           f"{meta['os_repeats']} solves, each building the model; pipelay_fast median of "
           f"{meta['pf_repeats']} after a warm-up (JIT excluded). Errors against each tool's "
           f"own finest mesh (OpenSees {OS_REFERENCE} m uniform; pipelay_fast {PF_REFERENCE}).",
           "", "## Machine", ""]
    out += [f"- {k}: {v}" for k, v in meta["machine"].items()]
    out += [f"- total run time: {meta['run_s']:.0f} s", "", "## Times and errors", "",
            markdown(rows[cols], err_fmt | {"median_ms": "{:.2f}", "tdp_err_m": "{:.4f}"}),
            "", "## Agreement of the finest meshes (OpenSees - pipelay_fast, relative; "
            "touchdown in m)", "", markdown(agree, agree_fmt), "",
            "## Speed at equal max von Mises error", "",
            markdown(res["speed"], speed_fmt), "",
            "`*_coarsest`: every mesh of that tool is already below the level, so its "
            "fastest (coarsest) mesh's time is used, an upper bound on the time it needs; "
            "when both are, the ratio compares the coarsest meshes tried.", "",
            "## OpenSees model checks (finest mesh)", ""]
    for scene, r in meta["references"].items():
        checks = r["opensees"]["checks"]
        out.append(f"- {scene}: " + ", ".join(
            f"{k} {v:.3g}" for k, v in checks.items() if isinstance(v, float | int)))
    return "\n".join(out) + "\n"


def write(res: dict, out: Path) -> str:
    """The CSV, JSON and markdown into ``out``; returns the markdown."""
    out.mkdir(parents=True, exist_ok=True)
    res["rows"].to_csv(out / "peers_opensees.csv", index=False)
    (out / "peers_opensees.json").write_text(json.dumps(res["meta"], indent=2, default=str))
    md = report(res)
    (out / "peers_opensees.md").write_text(md)
    return md


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true",
                        help=f"element lengths {QUICK_LENGTHS}, {QUICK_PF_REPEATS} repeats")
    parser.add_argument("--out", type=Path, default=REPO / "benchmarks" / "out")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    info = machine_info() | {"openseespy": version("openseespy")}
    for k, v in info.items():
        print(f"{k}: {v}")
    res = run(args.quick)
    md = write(res, args.out)
    print(md)
    print(f"wrote {args.out / 'peers_opensees.csv'}, .md and .json "
          f"in {res['meta']['run_s']:.0f} s")


if __name__ == "__main__":
    main()

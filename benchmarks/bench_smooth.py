"""Benchmark the smoothness of the answer in the stinger's curvature ``a``.

    python benchmarks/bench_smooth.py [--points N] [--seed S] [--step H] [--out DIR]

Scenes (bundled case files, 2D at their defaults): S67 and S125. Around
--points random values of ``a`` (lay.stinger.a, uniform in A_RANGE, seeded),
each case is solved cold at a + k H, k = -2 .. 2, and every peak column's
second difference D2(H) = f(a - H) - 2 f(a) + f(a + H) is divided by
|f(a)|. A smooth answer has D2 of order f'' H^2 plus the solver's round-off;
a jump (another mesh, another count of mesh passes) shows as one of order
the discretisation error. The answer's own curvature is told from a jump by
the fourth difference f(a - 2H) - 4 f(a - H) + 6 f(a) - 4 f(a + H) +
f(a + 2H) = D2(2H) - 4 D2(H): of order H^4 where the answer is smooth, of
order the jump where it is not. Both are printed.

A stencil is not scored where the contact regime changes inside it: the
pipe starts or stops bearing on the stinger's tip (the summary's
``bears_on_tip``, or a node over the tip in the profile's ``contact``
column, differs between its solves). Those are reported, not hidden. A
peak whose node changes inside a stencil (the nodal maximum moving to
another node: a kink, not a jump) is scored and flagged, and so is a
change of the mesh's element count.

Prints, per scene, the worst relative second and fourth differences of
each column and the ``a`` where they occur, and the regime changes found;
writes ``smooth.json`` (machine, versions, git revision, every stencil)
into --out (default benchmarks/out).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
from bench_jlay import machine_info

import pipelay_fast as pf

SCENES = {"S67 2D": "s67", "S125 2D": "s125"}
A_RANGE = (-0.0022, -0.0008)  # 1/m
STEP = 2e-7  # 1/m
COLUMNS = ("overbend_max_moment", "sagbend_max_moment", "overbend_max_strain",
           "sagbend_max_strain", "max_strain", "max_von_mises", "overbend_max_von_mises",
           "sagbend_max_von_mises", "top_tension", "bottom_tension", "tdp_tension", "tdp_z",
           "liftoff_z", "suspended_length", "layback", "tip_reaction")
# the profile column each peak is the nodal maximum of (for the peak's node)
PEAK_OF = {"overbend_max_moment": "moment", "sagbend_max_moment": "moment",
           "overbend_max_strain": "curvature", "sagbend_max_strain": "curvature",
           "max_strain": "curvature", "max_von_mises": "von_mises",
           "overbend_max_von_mises": "von_mises", "sagbend_max_von_mises": "von_mises"}


def peak_nodes(result) -> dict:
    """The node index of each peak column of ``result`` (its profile's
    nodal maximum over the peak's region: hogging or sagging above touchdown)."""
    p = result.profile
    above = (p["contact"] != "seabed").to_numpy()
    hog = above & (p["moment_y"].to_numpy() < 0.0)
    sag = above & ~hog
    out = {}
    for col, field in PEAK_OF.items():
        region = hog if col.startswith("overbend") else sag if col.startswith("sagbend") else above
        values = np.where(region, p[field].to_numpy(), -np.inf)
        out[col] = int(np.argmax(values))
    return out


def solve_stencil(base, a, step):
    """The five solves at a + k step, k = -2 .. 2: their summaries and peaks' nodes."""
    rows = []
    for k in range(-2, 3):
        result = pf.solve(base.with_changes({"lay.stinger.a": a + k * step}))
        tip_node = (result.profile["contact"] == "tip").to_numpy().nonzero()[0]
        rows.append({"summary": {c: result.summary[c] for c in
                                 (*COLUMNS, "bears_on_tip", "n_meshes", "n_elements",
                                  "n_iterations")},
                     "peak_nodes": peak_nodes(result), "tip_nodes": tip_node.tolist()})
    return rows


def score(rows) -> tuple[dict, dict]:
    """Per column, relative to |value at the middle|: |second difference|
    over the middle three solves, |fourth difference| over the five (None
    where the middle value is 0 or any is not finite)."""
    d2, d4 = {}, {}
    for col in COLUMNS:
        f = np.array([r["summary"][col] for r in rows], dtype=float)
        if not np.all(np.isfinite(f)) or f[2] == 0.0:
            d2[col] = d4[col] = None
            continue
        d2[col] = float(abs(f[1] - 2.0 * f[2] + f[3]) / abs(f[2]))
        d4[col] = float(abs(f[0] - 4.0 * f[1] + 6.0 * f[2] - 4.0 * f[3] + f[4]) / abs(f[2]))
    return d2, d4


def regime_change(rows) -> str:
    """Why a stencil is not scored ('' when it is): the tip's regime changes."""
    if len({r["summary"]["bears_on_tip"] for r in rows}) > 1:
        return "bears_on_tip changes"
    if len({bool(r["tip_nodes"]) for r in rows}) > 1:
        return "a node over the tip appears"
    return ""


def bench_scene(name, example, points, seed, step):
    """Every stencil of a scene, and the worst second and fourth differences per column."""
    base = pf.load_case(example)
    rng = np.random.default_rng(seed)
    centres = np.sort(rng.uniform(A_RANGE[0] + 2 * step, A_RANGE[1] - 2 * step, points))
    stencils = []
    for a in centres:
        rows = solve_stencil(base, float(a), step)
        d2, d4 = score(rows)
        stencils.append({
            "a": float(a), "excluded": regime_change(rows),
            "peak_moved": sorted(c for c in PEAK_OF
                                 if len({r["peak_nodes"][c] for r in rows}) > 1),
            "n_meshes": [r["summary"]["n_meshes"] for r in rows],
            "n_elements": [r["summary"]["n_elements"] for r in rows],
            "n_iterations": [r["summary"]["n_iterations"] for r in rows],
            "d2": d2, "d4": d4})
    worst = {}
    for col in COLUMNS:
        worst[col] = []
        for key in ("d2", "d4"):
            scored = [(t[key][col], t["a"]) for t in stencils
                      if not t["excluded"] and t[key][col] is not None]
            worst[col].append(max(scored) if scored else (None, None))
    return {"scene": name, "example": example, "stencils": stencils, "worst": worst}


def report(scene) -> str:
    """The scene's worst second and fourth differences as a markdown table."""
    lines = [f"### {scene['scene']} ({scene['example']})", "",
             "| column | worst rel. 2nd difference | at a [1/m] | worst rel. 4th difference "
             "| at a [1/m] |", "|---|---|---|---|---|"]
    for col, pairs in scene["worst"].items():
        cells = []
        for value, a in pairs:
            cells += ["n/a" if value is None else f"{value:.2e}",
                      "" if a is None else f"{a:.9f}"]
        lines.append(f"| {col} | {' | '.join(cells)} |")
    stencils = scene["stencils"]
    excluded = [t for t in stencils if t["excluded"]]
    lines.append("")
    lines.append(f"excluded (regime change): {len(excluded)} of {len(stencils)}"
                 + "".join(f"; a = {t['a']:.9f}: {t['excluded']}" for t in excluded))
    moved = [t for t in stencils if t["peak_moved"]]
    lines.append("peak moved to another node: "
                 + (", ".join(f"a = {t['a']:.9f} ({', '.join(t['peak_moved'])})" for t in moved)
                    or "none"))
    passes = sorted({m for t in stencils for m in t["n_meshes"]})
    mixed = [t["a"] for t in stencils if len(set(t["n_meshes"])) > 1]
    counts = [t["a"] for t in stencils if len(set(t["n_elements"])) > 1]
    iterations = sum(sum(t["n_iterations"]) for t in stencils)
    lines.append(f"mesh passes seen: {passes}; stencils with mixed passes: "
                 f"{[f'{a:.9f}' for a in mixed]}, with mixed element counts: "
                 f"{[f'{a:.9f}' for a in counts]}; Newton iterations in all: {iterations}")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=20)
    parser.add_argument("--seed", type=int, default=43)
    parser.add_argument("--step", type=float, default=STEP)
    parser.add_argument("--out", default="benchmarks/out")
    args = parser.parse_args(argv)
    info = machine_info()
    print(json.dumps(info))
    scenes = [bench_scene(name, example, args.points, args.seed, args.step)
              for name, example in SCENES.items()]
    for scene in scenes:
        print(report(scene))
        print()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "smooth.json").write_text(json.dumps(
        {"machine": info, "points": args.points, "seed": args.seed, "step": args.step,
         "a_range": A_RANGE, "scenes": scenes}, indent=1))


if __name__ == "__main__":
    main()

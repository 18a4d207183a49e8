"""Speed against error of the model choices, for the paper's scenes.

    python benchmarks/speed_vs_error.py [--quick] [--out DIR] [--md PATH]

Scenes: the bundled case files j125 (J-lay 2D, no current), j125_3d (J-lay,
lateral current, seabed friction), s67, s67_3d, s125 and s125_3d (S-lay).
For each scene and each model choice (one row per scene x choice x setting):

* ``element_length``: ``solver.element_length`` in LENGTHS [m] (the default
  is ``Solver().element_length``, the value the bundled case files state);
* ``grading``: ``solver.grading`` on / off at GRADING_LENGTHS [m];
* ``dimension``: ``solver.dimension`` "2d" / "3d" (planar scenes only);
* ``seabed``: rigid (default) / elastic, ``seabed.stiffness`` = SEABED_STIFFNESS;
* ``catenary``: the natural catenary of :mod:`pipelay_fast.engine.guess` (no bending,
  no stress: vm_rel_error is NaN), TDP z = span end z - catenary span;
* ``warm``: ``pf.solve(case, warm=neighbour)``, the neighbour being the scene
  with stinger ``a`` + DA_WARM (S-lay) or top tension x TENSION_WARM (J-lay).

Measured: the median wall time of ``pf.solve`` over --repeats solves after a
warm-up solve (JIT compilation excluded; the first solve of the process is
reported separately), and the errors against a mesh-converged reference of the
same scene (REFERENCE, solved once per scene): relative error of
``max_von_mises``, absolute errors [m] of ``tdp_z`` and ``liftoff_z`` (S-lay).
A model choice other than the mesh (elastic seabed, 3D) is compared with the
reference of the default model, so its error is the effect of that choice.
A failed solve gives a row with the error message in ``status``.

The same run then measures the peers and the scaling, each a section of the
markdown: the OpenSees peer of J125 and S67 (``peers_opensees.run``, when
openseespy is installed: ``pip install '.[peers]'``; --no-peers skips it) and
time against elements, 50 to 20 000 (``bench_scaling.run``; --no-scaling).

Writes ``speed_vs_error.csv``, ``speed_vs_error.json`` (machine, versions, git
revision, references, first-solve times) and one ``speed_vs_error_<scene>.png``
per scene (error against time, Pareto front, default marked) into --out
(default benchmarks/out), and the markdown summary to --md (default
benchmarks/speed_vs_error.md; with --quick, <out>/speed_vs_error.md).
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from bench_jlay import machine_info  # noqa: E402

import pipelay_fast as pf  # noqa: E402
from pipelay_fast.engine.guess import first_guess  # noqa: E402
from pipelay_fast.input.case import Solver  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
EXAMPLES = Path(pf.__file__).parent / "examples"
SCENES = ("j125", "j125_3d", "s67", "s67_3d", "s125", "s125_3d")
PLANAR = ("j125", "s67", "s125")

LENGTHS = (16.0, 8.0, 4.0, 2.0, 1.0)  # m, solver.element_length
DEFAULT_LENGTH = Solver().element_length  # m
QUICK_LENGTHS = (8.0, 2.0)
GRADING_LENGTHS = (16.0, 8.0, 4.0, 2.0)  # m, element lengths of the grading on/off rows
SEABED_STIFFNESS = 1e6  # N/m per m of pipe, the elastic seabed
DA_WARM = 1.5e-4  # 1/m, change of stinger a for the warm-start neighbour (S-lay)
TENSION_WARM = 1.02  # -, factor on lay.top_tension for the warm-start neighbour (J-lay)
REFERENCE = {"solver.element_length": 0.25, "solver.min_element_length": 0.05}
REFERENCE_FALLBACK_TOLERANCE = 1e-6  # used only if the reference fails (the run says so)
REPEATS, QUICK_REPEATS = 5, 3
CATENARY_CALLS = 50  # catenary estimates per timed repeat (each takes well under 1 ms)
VM_HEADLINE_RTOL = 1e-3  # headline: fastest setting with max_von_mises error <= 0.1 %
NOISE_TIME = 0.1  # -, relative time difference counted as timing noise (defaults' position)
NOISE_ERROR = 0.5  # -, a point beats the defaults in error only below this factor of theirs
ERROR_FLOOR = 1e-7  # -, plotted floor of vm_rel_error (log axis)

COLUMNS = ["scene", "choice", "setting", "n_elements", "median_ms", "vm_rel_error",
           "tdp_error_m", "liftoff_error_m", "status", "is_default", "n_iterations"]


# --------------------------------------------------------------------------- measuring


def load(scene: str) -> pf.Case:
    return pf.load_case(EXAMPLES / f"{scene}.toml")


def time_solve(case: pf.Case, repeats: int, warm: pf.Result | None = None):
    """Warm-up solve, then ``repeats`` timed solves: (last summary, median wall time [ms])."""
    result = pf.solve(case, warm=warm)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = pf.solve(case, warm=warm)
        times.append(time.perf_counter() - t0)
    return result.summary, 1e3 * statistics.median(times)


def solve_reference(case: pf.Case) -> tuple[dict | None, dict, float, str]:
    """(summary or None, settings, solve time [s], note) of the mesh-converged reference."""
    settings = dict(REFERENCE)
    note = ""
    for attempt in range(2):
        t0 = time.perf_counter()
        try:
            summary = pf.solve(case.with_changes(settings)).summary
            return summary, settings, time.perf_counter() - t0, note
        except pf.SolveError as err:
            if attempt:
                return None, settings, time.perf_counter() - t0, note + f" failed again: {err}"
            note = (f"reference failed at solver.tolerance = {case.solver.tolerance:g} "
                    f"({err}); retried with {REFERENCE_FALLBACK_TOLERANCE:g}.")
            print("NOTE:", note, flush=True)
            settings["solver.tolerance"] = REFERENCE_FALLBACK_TOLERANCE
    raise AssertionError("unreachable")


def errors(ref: dict | None, vm: float, tdp: float, liftoff: float | None) -> dict:
    """vm_rel_error [-], tdp_error_m and liftoff_error_m [m] against the reference."""
    nan = math.nan
    if ref is None:
        return {"vm_rel_error": nan, "tdp_error_m": nan, "liftoff_error_m": None}
    lift_ref = ref.get("liftoff_z")
    has_liftoff = lift_ref is not None and np.isfinite(lift_ref) and liftoff is not None
    return {
        "vm_rel_error": abs(vm - ref["max_von_mises"]) / abs(ref["max_von_mises"]),
        "tdp_error_m": abs(tdp - ref["tdp_z"]),
        "liftoff_error_m": abs(liftoff - lift_ref) if has_liftoff else None,
    }


class Scene:
    """Runs the choices of one scene; each distinct case is timed only once."""

    def __init__(self, name: str, repeats: int, ref: dict | None):
        self.name, self.repeats, self.ref = name, repeats, ref
        self.base = load(name)
        self._measured: dict[str, dict] = {}

    def measure(self, choice: str, setting: str, changes: dict, warm: bool = False) -> dict:
        """One row: ``changes`` applied to the scene's case, solved cold or warm."""
        row = {"scene": self.name, "choice": choice, "setting": setting, "is_default": False}
        try:
            case = self.base.with_changes(changes)
        except ValueError as err:
            return row | {"status": f"invalid: {err}"}
        key = self._key(case, warm)
        row["is_default"] = key == self._key(self.base, False)
        if key not in self._measured:
            self._measured[key] = self._solve(case, warm)
        return row | self._measured[key]

    @staticmethod
    def _key(case: pf.Case, warm: bool) -> str:
        """Identity of a measurement: the case's tables ("auto" dimension
        resolved, as the solver resolves it) and the start."""
        case = case.with_changes({"solver.dimension": case.resolved_dimension})
        return json.dumps(case.to_dict(), sort_keys=True, default=str) + f"|warm={warm}"

    def _solve(self, case: pf.Case, warm: bool) -> dict:
        try:
            neighbour = pf.solve(self.neighbour(case)) if warm else None
            s, ms = time_solve(case, self.repeats, warm=neighbour)
        except (pf.SolveError, ValueError) as err:
            return {"status": f"failed: {type(err).__name__}: {err}"}
        liftoff = s["liftoff_z"] if case.lay.method == "S" else None
        return {"n_elements": s["n_elements"], "n_iterations": s["n_iterations"],
                "median_ms": ms, "status": "ok",
                **errors(self.ref, s["max_von_mises"], s["tdp_z"], liftoff)}

    @staticmethod
    def neighbour(case: pf.Case) -> pf.Case:
        """The warm start's neighbour: stinger a + DA_WARM (S-lay), top tension x TENSION_WARM."""
        if case.lay.method == "S":
            return case.with_changes({"lay.stinger.a": case.lay.stinger.a + DA_WARM})
        if case.lay.top_tension is None:
            raise ValueError("warm: the J-lay neighbour needs lay.top_tension")
        return case.with_changes({"lay.top_tension": case.lay.top_tension * TENSION_WARM})

    def catenary(self) -> dict:
        """The natural catenary (``guess.first_guess``): timed, TDP (and lift-off) error."""
        row = {"scene": self.name, "choice": "catenary", "setting": "natural catenary",
               "is_default": False, "n_elements": 0}
        case = self.base

        def estimate():
            g = first_guess(case, lambda cat, z_td: 0.0)  # laid length plays no part here
            end_z = case.lay.top[1] if g.liftoff_z is None else g.liftoff_z
            return end_z - g.cat.span, g.liftoff_z

        try:
            tdp, liftoff = estimate()
            times = []
            for _ in range(self.repeats):
                t0 = time.perf_counter()
                for _ in range(CATENARY_CALLS):
                    estimate()
                times.append((time.perf_counter() - t0) / CATENARY_CALLS)
        except ValueError as err:
            return row | {"status": f"failed: {err}"}
        err = errors(self.ref, math.nan, tdp, liftoff)
        return row | {"median_ms": 1e3 * statistics.median(times), "status": "ok",
                      **err, "vm_rel_error": math.nan}

    def run(self, lengths) -> list[dict]:
        rows = [self.measure("element_length", f"{h:g} m", {"solver.element_length": h})
                for h in lengths]
        rows += [self.measure("grading", f"{'on' if on else 'off'} @ {h:g} m",
                              {"solver.element_length": h, "solver.grading": on})
                 for h in GRADING_LENGTHS for on in (True, False)]
        if self.name in PLANAR:
            h = self.base.solver.element_length
            rows += [self.measure("dimension", f"{dim} @ {h:g} m", {"solver.dimension": dim})
                     for dim in ("2d", "3d")]
        rows.append(self.measure("seabed", "rigid", {"seabed.stiffness": "rigid"}))
        rows.append(self.measure("seabed", f"elastic {SEABED_STIFFNESS:g} N/m/m",
                                 {"seabed.stiffness": SEABED_STIFFNESS}))
        rows.append(self.catenary())
        rows.append(self.measure("warm", "cold", {}))
        what = (f"a {DA_WARM:+g} 1/m" if self.base.lay.method == "S"
                else f"top tension x {TENSION_WARM:g}")
        rows.append(self.measure("warm", f"warm from {what}", {}, warm=True))
        return rows


# --------------------------------------------------------------------------- analysis


def pareto(df: pd.DataFrame) -> pd.DataFrame:
    """Cold solves not beaten in both time and (floored) vm_rel_error, by increasing time.

    Warm starts are left out: they need a solved neighbour (a sweep), not one
    case; so is the elastic seabed, another model (its error against the rigid
    reference is the difference of the two models, not a discretisation error).
    """
    warm = (df["choice"] == "warm") & df["setting"].str.startswith("warm")
    other_model = (df["choice"] == "seabed") & df["setting"].str.startswith("elastic")
    ok = df[(df["status"] == "ok") & df["vm_rel_error"].notna() & ~warm & ~other_model].copy()
    ok["err"] = ok["vm_rel_error"].clip(lower=ERROR_FLOOR)
    ok = ok.sort_values(["median_ms", "err"])
    front, best = [], math.inf
    for idx, row in ok.iterrows():
        if row["err"] < best:
            front.append(idx)
            best = row["err"]
    return ok.loc[front]


def label(row) -> str:
    return f"{row['choice']}: {row['setting']}"


def headline(df: pd.DataFrame) -> list[str]:
    """Per scene: fastest cold setting within VM_HEADLINE_RTOL, and where the defaults sit."""
    lines = []
    for scene, sub in df.groupby("scene", sort=False):
        front = pareto(sub)  # cold solves of the rigid-seabed model
        ok = front[front["vm_rel_error"] <= VM_HEADLINE_RTOL]
        if ok.empty:
            text = f"no setting reached max von Mises error <= {100 * VM_HEADLINE_RTOL:g} %"
        else:
            b = ok.loc[ok["median_ms"].idxmin()]
            text = (f"fastest within {100 * VM_HEADLINE_RTOL:g} %: {label(b)} "
                    f"({b['median_ms']:.1f} ms, {b['n_elements']:.0f} elements, "
                    f"vm error {b['vm_rel_error']:.2e}, TDP error {b['tdp_error_m']:.3f} m)")
        lines.append(f"**{scene}**: {text}; {default_position(sub)}")
    return lines


def default_position(sub: pd.DataFrame) -> str:
    """Where the default row sits relative to the Pareto front of one scene."""
    d = sub[sub["is_default"]]  # several rows are the default case: the same measurement
    if d.empty or d.iloc[0]["status"] != "ok":
        return "the default solve failed"
    d = d.iloc[0]
    front = pareto(sub)
    err = max(d["vm_rel_error"], ERROR_FLOOR)
    text = f"defaults {d['median_ms']:.1f} ms, vm error {d['vm_rel_error']:.2e}"
    # beaten: no worse in either (within the noise), clearly better in one
    t, e = front["median_ms"], front["err"]
    no_worse = (t <= (1.0 + NOISE_TIME) * d["median_ms"]) & (e <= (1.0 + NOISE_TIME) * err)
    better = (t < (1.0 - NOISE_TIME) * d["median_ms"]) | (e < NOISE_ERROR * err)
    dominated = front[no_worse & better]
    if dominated.empty:
        return text + f": on the Pareto front (within {100 * NOISE_TIME:g} % in time)"
    b = dominated.iloc[0]
    return (text + f": off the front, beaten by {label(b)} ({b['median_ms']:.1f} ms, "
            f"vm error {b['vm_rel_error']:.2e})")


def plot(sub: pd.DataFrame, scene: str, path: Path) -> None:
    """Error (log, floored) against median time (log) for one scene."""
    ok = sub[(sub["status"] == "ok") & sub["vm_rel_error"].notna()]
    fig, ax = plt.subplots(figsize=(7.5, 5.0))
    for choice, grp in ok.groupby("choice"):
        ax.scatter(grp["median_ms"], grp["vm_rel_error"].clip(lower=ERROR_FLOOR),
                   label=choice, s=30, zorder=3)
    # rows of the same measurement (e.g. "1 m", "rigid", "cold") share one label
    for (ms, err), grp in ok.groupby(["median_ms", "vm_rel_error"]):
        ax.annotate(", ".join(dict.fromkeys(grp["setting"])), (ms, max(err, ERROR_FLOOR)),
                    fontsize=6, xytext=(3, 3), textcoords="offset points")
    front = pareto(sub)
    if not front.empty:
        ax.step(front["median_ms"], front["err"], where="post", color="0.4", lw=1,
                ls="--", label="Pareto front (cold solves)", zorder=2)
    d = ok[ok["is_default"]].head(1)
    if not d.empty:
        ax.scatter(d["median_ms"], d["vm_rel_error"].clip(lower=ERROR_FLOOR), marker="*",
                   s=250, facecolor="none", edgecolor="k", lw=1.2, label="defaults", zorder=4)
    ax.axhline(VM_HEADLINE_RTOL, color="0.7", lw=0.8, ls=":")
    ax.set(xscale="log", yscale="log", xlabel="median wall time per solve [ms]",
           ylabel=f"max von Mises relative error [-] (floor {ERROR_FLOOR:g})",
           title=f"{scene}: speed against error (catenary: no stress, not shown)")
    ax.grid(True, which="both", lw=0.3, alpha=0.5)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def markdown(df: pd.DataFrame) -> str:
    """A markdown table (no tabulate dependency)."""
    def cell(col, v):
        if v is None or (isinstance(v, float) and np.isnan(v)):
            return "-"
        if col == "n_elements":
            return f"{v:.0f}"
        if col == "median_ms":
            return f"{v:.3g}" if v < 1 else f"{v:.1f}"
        if isinstance(v, float):
            return f"{v:.2e}" if col == "vm_rel_error" else f"{v:.3g}"
        return str(v).replace("|", "/").replace("\n", " ")
    lines = ["| " + " | ".join(df.columns) + " |", "|" + "---|" * len(df.columns)]
    lines += ["| " + " | ".join(cell(c, v) for c, v in zip(df.columns, row, strict=True)) + " |"
              for row in df.itertuples(index=False)]
    return "\n".join(lines)


def summary_md(df, info, meta, quick) -> str:
    out = ["# Speed against error of the model choices", "",
           "Generated by `python benchmarks/speed_vs_error.py"
           + (" --quick" if quick else "") + "`; see its docstring for the choices. "
           f"Median of {meta['repeats']} solves after a warm-up (JIT compilation excluded). "
           "Errors against a mesh-converged reference per scene "
           f"({REFERENCE}): vm_rel_error of `max_von_mises` [-], tdp_error_m and "
           "liftoff_error_m [m] (S-lay only). The elastic seabed and 3D rows are compared "
           "with the reference of the default model. "
           f"Defaults: element_length {DEFAULT_LENGTH:g} m, grading on, "
           "rigid seabed, cold start (`is_default`: the rows that are this same case and solve). "
           "The warm time excludes the neighbour's own solve. The catenary has no stress "
           "(vm_rel_error `-`). Figures (error against time, Pareto front, defaults starred) "
           "are in benchmarks/out/. The Pareto front and the defaults' position are over cold "
           "solves of the rigid seabed (a warm start needs a solved neighbour; the elastic "
           "seabed is another model).", "", "## Machine", ""]
    out += [f"- {k}: {v}" for k, v in info.items()]
    out += [f"- first solve of the process (j125, includes loading compiled kernels): "
            f"{meta['first_solve_s']:.2f} s", f"- total run time: {meta['run_s']:.0f} s", "",
            f"## Headline (max von Mises error <= {100 * VM_HEADLINE_RTOL:g} %)", ""]
    out += [f"- {line}" for line in headline(df)]
    out += ["", "## References", "",
            "| scene | n_elements | solve s | max_von_mises MPa | tdp_z m | liftoff_z m | note |",
            "|---|---|---|---|---|---|---|"]
    for scene, r in meta["references"].items():
        s = r["summary"] or {}
        lift = s.get("liftoff_z")
        out.append(f"| {scene} | {s.get('n_elements', '-')} | {r['seconds']:.1f} | "
                   + (f"{s['max_von_mises'] / 1e6:.3f} | {s['tdp_z']:.3f} | " if s else "- | - | ")
                   + (f"{lift:.3f}" if lift is not None and np.isfinite(lift) else "-")
                   + f" | {r['note'] or ''} |")
    cols = [c for c in COLUMNS if c != "scene"]
    for scene, sub in df.groupby("scene", sort=False):
        out += ["", f"## {scene}", "",
                f"Figure: `benchmarks/out/speed_vs_error_{scene}.png`. "
                f"First solve of the scene: {meta['first_solve_scene_s'][scene]:.2f} s.", "",
                markdown(sub[cols])]
    return "\n".join(out) + "\n"


# --------------------------------------------------------------------------- peers, scaling


def demote(md: str) -> str:
    """A markdown report as a section: every heading one level down."""
    return "\n".join("#" + line if line.startswith("#") else line for line in md.splitlines())


def peers_section(quick: bool, out: Path) -> str:
    """The OpenSees peer (benchmarks/peers_opensees.py), or why it did not run."""
    try:
        import peers_opensees
    except (ImportError, RuntimeError) as err:
        return ("## Peers: OpenSees\n\nNot run: the OpenSees peer needs openseespy "
                f"(`pip install '.[peers]'`): {err}\n")
    print("peers: OpenSees against pipelay_fast", flush=True)
    md = peers_opensees.write(peers_opensees.run(quick), out)
    return demote(md.replace("# pipelay_fast against OpenSees", "# Peers: OpenSees", 1))


def scaling_section(quick: bool, out: Path) -> str:
    """Time against elements (benchmarks/bench_scaling.py), table and figure."""
    import bench_scaling

    print("scaling", flush=True)
    res = bench_scaling.run(quick, log=lambda row: None)
    bench_scaling.write(res, out)
    table = res["table"]
    cols = [c for c in ("dimension", "n_elements", "ms", "iterations",
                        "us_per_iteration_element", "status") if c in table]
    lines = ["## Scaling", "",
             "J125 on uniform meshes (`python benchmarks/bench_scaling.py`): median time per "
             "solve after warm-up, Newton iterations, time per iteration and element. "
             "Figure: `benchmarks/out/scaling.png`.", "", markdown(table[cols]), ""]
    for dim, m in res["memory"].items():
        lines.append(f"- {dim}: peak RSS {m['peak_mib']:.0f} MiB for {m['elements']} elements "
                     f"(the solve adds {m['solve_mib']:.0f} MiB to import and compilation)")
    return "\n".join(lines) + "\n"


# --------------------------------------------------------------------------- main


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true",
                        help=f"element lengths {QUICK_LENGTHS}, {QUICK_REPEATS} repeats")
    parser.add_argument("--out", type=Path, default=REPO / "benchmarks" / "out")
    parser.add_argument("--md", type=Path, default=None, help="markdown summary path")
    parser.add_argument("--scenes", nargs="+", default=list(SCENES), choices=SCENES)
    parser.add_argument("--no-peers", action="store_true",
                        help="skip the OpenSees peer (benchmarks/peers_opensees.py)")
    parser.add_argument("--no-scaling", action="store_true",
                        help="skip the scaling run (benchmarks/bench_scaling.py)")
    args = parser.parse_args(argv)
    repeats = QUICK_REPEATS if args.quick else REPEATS
    lengths = QUICK_LENGTHS if args.quick else LENGTHS
    md_path = args.md or (args.out / "speed_vs_error.md" if args.quick
                          else REPO / "benchmarks" / "speed_vs_error.md")
    args.out.mkdir(parents=True, exist_ok=True)

    t_run = time.perf_counter()
    info = machine_info()
    t0 = time.perf_counter()
    pf.solve(load("j125"))
    first_solve = time.perf_counter() - t0
    print(f"first solve of the process (j125): {first_solve:.2f} s", flush=True)

    rows, refs, first_scene = [], {}, {}
    for scene in args.scenes:
        case = load(scene)
        t0 = time.perf_counter()
        try:
            pf.solve(case)
        except pf.SolveError:
            pass  # reported by the default row
        first_scene[scene] = time.perf_counter() - t0
        ref, settings, seconds, note = solve_reference(case)
        refs[scene] = {"settings": settings, "seconds": seconds, "note": note,
                       "summary": None if ref is None else
                       {k: ref[k] for k in ("n_elements", "max_von_mises", "tdp_z", "liftoff_z")}}
        print(f"{scene}: reference {seconds:.1f} s", flush=True)
        scene_rows = Scene(scene, repeats, ref).run(lengths)
        for r in scene_rows:
            print(f"  {r['choice']:15s} {r['setting']:28s} {r.get('median_ms', math.nan):9.2f} ms "
                  f"vm {r.get('vm_rel_error', math.nan):.2e}  {r['status'][:100]}", flush=True)
        rows += scene_rows

    df = pd.DataFrame(rows).reindex(columns=COLUMNS)
    df["is_default"] = df["is_default"].astype(bool)
    csv_path = args.out / "speed_vs_error.csv"
    df.to_csv(csv_path, index=False)
    for scene, sub in df.groupby("scene", sort=False):
        plot(sub, scene, args.out / f"speed_vs_error_{scene}.png")
    meta = {"machine": info, "quick": args.quick, "repeats": repeats,
            "first_solve_s": first_solve, "first_solve_scene_s": first_scene,
            "references": refs}
    extra = []
    if not args.no_peers:
        extra.append(peers_section(args.quick, args.out))
    if not args.no_scaling:
        extra.append(scaling_section(args.quick, args.out))
    meta["run_s"] = time.perf_counter() - t_run  # the whole run, peers and scaling included
    (args.out / "speed_vs_error.json").write_text(json.dumps(meta, indent=2, default=str))
    sections = [summary_md(df, info, meta, args.quick), *extra]
    md_path.parent.mkdir(parents=True, exist_ok=True)
    md_path.write_text("\n".join(sections))
    print("\n".join(headline(df)))
    print(f"wrote {csv_path}, {args.out / 'speed_vs_error.json'}, PNGs and {md_path} "
          f"in {meta['run_s']:.0f} s")


if __name__ == "__main__":
    main()

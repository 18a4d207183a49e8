"""The ``pipelay-fast`` command.

    pipelay-fast solve CASE.toml [--out DIR] [--quiet]
    pipelay-fast example [NAME] [--out FILE] [--force]
    pipelay-fast sweep SWEEP.toml [--out DIR] [--workers N] [--backend loky|dask|ray] ...
    pipelay-fast select RESULTS_DIR [--no-refine] [--min-tip-clearance M] [--max-utilisation U]
                        [--max-overbend-strain E] [--max-sagbend-strain E]
                        [--top-tension MIN MAX] [--max-roller-reaction R]
    pipelay-fast table RESULTS_DIR
    pipelay-fast plot CASE.toml | SOLVE_DIR | RESULTS_DIR [--out FILE]
    pipelay-fast --version

Exit codes: 0 success (a sweep whose cases failed has still succeeded: the
failures are rows of its summary), 1 the case did not converge (or a file could
not be written, or a sweep could not run: its backend not installed, its
results directory locked by another process), 2 bad input (usage, unreadable
or invalid case or sweep file, unknown example, a results directory without a
sweep; ``plot`` without matplotlib).

The top layer: it parses the arguments, calls the api and study layers and
turns their errors into messages on stderr and exit codes.
"""

from __future__ import annotations

import argparse
import math
import numbers
import sys
from pathlib import Path

from ._version import __version__
from .api.notice import case_cached, compile_notice, notice_given
from .api.solve import solve
from .input.case import load_case
from .input.errors import SolveError
from .input.examples import example_description, example_names, example_path
from .output.results import SUMMARY_UNITS

# SI unit -> (display unit, factor); the Parquet files keep SI
DISPLAY_UNITS = {"N": ("kN", 1e-3), "N m": ("kN m", 1e-3), "Pa": ("MPa", 1e-6)}

EXIT_OK, EXIT_FAILED, EXIT_USAGE = 0, 1, 2

# select's limit options (the [select] keys of pipelay_fast.study.limits): flag, metavar, help
SELECT_LIMITS = (
    ("--min-tip-clearance", "M", "least tip clearance [m]"),
    ("--max-utilisation", "U", "largest code-check utilisation [-] (default 1 with [checks])"),
    ("--max-overbend-strain", "E", "largest overbend strain [-]"),
    ("--max-sagbend-strain", "E", "largest sagbend strain [-]"),
    ("--top-tension", "N", "the tensioner's window: least and largest top tension [N]"),
    ("--max-roller-reaction", "R", "largest roller reaction [N] (roller stingers)"),
)


def main(argv: list[str] | None = None) -> int:
    """Run the command line ``argv`` (default ``sys.argv[1:]``); return the exit code."""
    parser = _parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as stop:  # --help, --version, or a usage error already printed
        return stop.code if isinstance(stop.code, int) else EXIT_USAGE
    return args.run(args)


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="pipelay-fast",
        description="Static nonlinear analysis of offshore pipelaying (S-lay and J-lay).",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    commands = parser.add_subparsers(title="commands", metavar="COMMAND", required=True)

    solve_cmd = commands.add_parser(
        "solve", help="solve one case and print its summary",
        description="Solve one case file, print the summary (display units), "
        "optionally write summary.parquet and profile.parquet (and rollers.parquet for a "
        "roller stinger; SI units).",
    )
    solve_cmd.add_argument("case", type=Path, metavar="CASE.toml",
                           help="case file, or a bundled example's name")
    solve_cmd.add_argument("--out", type=Path, metavar="DIR",
                           help="write summary.parquet and profile.parquet (rollers.parquet "
                           "too for a roller stinger) into DIR")
    solve_cmd.add_argument("--quiet", action="store_true", help="print nothing but errors")
    solve_cmd.set_defaults(run=_solve)

    example_cmd = commands.add_parser(
        "example", help="print a bundled example case file",
        description="Print (or write) a bundled example case to start from; "
        "without NAME, list the examples.",
    )
    example_cmd.add_argument("name", nargs="?", metavar="NAME", help="example name, e.g. j125")
    example_cmd.add_argument("--out", type=Path, metavar="FILE", help="write to FILE instead")
    example_cmd.add_argument("--force", action="store_true", help="overwrite an existing FILE")
    example_cmd.set_defaults(run=_example)

    sweep_cmd = commands.add_parser(
        "sweep", help="run a sweep file into a Parquet dataset",
        description="Expand a sweep file into cases, solve them in warm-started chains on "
        "worker processes and write the summary and profiles tables (hive-partitioned by "
        "scene) into DIR. Rerunning into the same DIR skips the cases already written.",
    )
    sweep_cmd.add_argument("sweep", type=Path, metavar="SWEEP.toml", help="sweep file")
    sweep_cmd.add_argument("--out", type=Path, metavar="DIR",
                           help="results directory (default results/<sweep name>)")
    sweep_cmd.add_argument("--workers", type=int, default=2, metavar="N",
                           help="worker processes (default 2; 1 runs in this process)")
    sweep_cmd.add_argument("--backend", choices=("loky", "dask", "ray"), default="loky",
                           help="joblib backend (dask and ray need their extras)")
    sweep_cmd.add_argument("--scheduler", metavar="ADDRESS",
                           help="dask scheduler or ray cluster address (default: start one)")
    sweep_cmd.add_argument("--chunk-size", type=int, metavar="N",
                           help="cases per task and per Parquet chunk (whole chains)")
    sweep_cmd.add_argument("--no-profiles", action="store_true",
                           help="write the summary table only")
    sweep_cmd.add_argument("--dry-run", action="store_true",
                           help="print the cases per scene and stop")
    sweep_cmd.add_argument("--quiet", action="store_true", help="no progress bar or report")
    sweep_cmd.set_defaults(run=_sweep)

    select_cmd = commands.add_parser(
        "select", help="choose the stinger (curvature a, or a roller stinger's radius or "
        "roller heights) from a sweep's results",
        description="For each S-lay scene and current: the a minimising the maximum von "
        "Mises stress and the a where the overbend and sagbend peaks are equal, refined "
        "between grid points; the range of a inside the limits (the sweep file's [select] "
        "table, each replaced by the option given here; utilisation at most 1 by default "
        "where the cases have [checks]), the limit binding at each end and the a of least "
        "utilisation inside it; writes RESULTS_DIR/selection.parquet and prints it.",
    )
    select_cmd.add_argument("results", type=Path, metavar="RESULTS_DIR")
    select_cmd.add_argument("--no-refine", action="store_true",
                            help="grid values only (no further solves)")
    for flag, metavar, what in SELECT_LIMITS:
        select_cmd.add_argument(flag, type=float, metavar=metavar, help=what,
                                nargs=2 if flag == "--top-tension" else None)
    select_cmd.set_defaults(run=_select)

    table_cmd = commands.add_parser(
        "table", help="print the lay table of a sweep's results",
        description="One row per case, S-lay then J-lay by water depth: top tension, "
        "layback, touchdown tension, departure angle, tip clearance, peak strains and "
        "utilisations (kN, deg, per cent), then the targets the cases were solved for.",
    )
    table_cmd.add_argument("results", type=Path, metavar="RESULTS_DIR")
    table_cmd.set_defaults(run=_table)

    plot_cmd = commands.add_parser(
        "plot", help="draw a case's lay or a sweep's results (needs matplotlib)",
        description="CASE.toml: solve it and draw the elevation (seabed, water line, "
        "stinger or rollers), the plan in 3D, and moment, von Mises and utilisation along the "
        "pipe; a directory written by solve --out: the same, without solving. "
        "RESULTS_DIR: the overbend and sagbend peaks against a (or a roller stinger's "
        "radius or roller shift) per S-lay scene and current (select's choices marked) and "
        "the lay table against depth. PNG unless --out ends in "
        ".svg or .pdf.",
    )
    plot_cmd.add_argument("source", type=Path, metavar="CASE.toml|SOLVE_DIR|RESULTS_DIR")
    plot_cmd.add_argument("--out", type=Path, metavar="FILE",
                          help="figure file (default: CASE.png here, SOLVE_DIR/<case name>.png, "
                          "RESULTS_DIR/sweep.png)")
    plot_cmd.set_defaults(run=_plot)
    return parser


def _error(message: str, code: int) -> int:
    print(f"error: {message}", file=sys.stderr)
    return code


def _named(path: Path, err: Exception) -> str:
    """``err``'s message prefixed by ``path`` unless it already begins with it."""
    message = str(err)
    return message if message.startswith((str(path), repr(str(path)))) else f"{path}: {message}"


def _compile_notice(quiet: bool, case) -> None:
    """On stderr, that ``case``'s kernels are about to compile (a new
    environment's first run, or a family of kernels not yet in the cache:
    :func:`pipelay_fast.api.notice.compile_notice`), unless ``quiet``;
    either way the solves of this process do not log it again."""
    notice = compile_notice(case_cached(case))
    if notice is not None and not quiet:
        print(notice, file=sys.stderr, flush=True)


def _solve(args: argparse.Namespace) -> int:
    from .output.io import write_result  # pyarrow only when needed

    try:
        case = load_case(str(args.case))  # a bundled example's name, too
        _compile_notice(args.quiet, case)
        result = solve(case)
    except OSError as err:
        return _error(f"cannot read {args.case}: {err.strerror or err}", EXIT_USAGE)
    except ValueError as err:
        return _error(_named(args.case, err), EXIT_USAGE)
    except (SolveError, NotImplementedError) as err:
        return _error(_named(args.case, err), EXIT_FAILED)
    if not args.quiet:
        print(f"{case.name} ({args.case})")
        print(format_summary(result.summary))
        print(f"\nflags: {format_flags(result.summary)}")
    if args.out is not None:
        try:
            paths = write_result(result, args.out)
        except OSError as err:
            return _error(f"cannot write to {args.out}: {err.strerror or err}", EXIT_FAILED)
        if not args.quiet:
            print()
            for path in paths:
                print(f"wrote {path}")
    return EXIT_OK


def format_summary(summary: dict) -> str:
    """The summary as aligned ``name  value  unit`` lines, in display units;
    the fields that do not apply to the case (None or NaN: a roller's on a
    quadratic stinger, the overbend's in J-lay, a check's without
    ``[checks]``) named on one last line instead."""
    rows, absent = [], []
    for name, value in summary.items():
        if _format_value(value) == "n/a":
            absent.append(name)
            continue
        unit = SUMMARY_UNITS.get(name, "")
        if unit in DISPLAY_UNITS and isinstance(value, numbers.Real):
            unit, factor = DISPLAY_UNITS[unit]
            value = value * factor
        rows.append((name, _format_value(value), unit))
    name_width = max(len(name) for name, _, _ in rows)
    value_width = max(len(text) for _, text, _ in rows)
    lines = [f"{name:<{name_width}}  {text:>{value_width}}  {unit}".rstrip()
             for name, text, unit in rows]
    if absent:
        lines.append(f"(not applicable to this case: {', '.join(absent)})")
    return "\n".join(lines)


def format_flags(summary: dict) -> str:
    """The answer's flags as a sentence: yielded (with the largest von Mises
    stress over SMYS) and bearing on the stinger's tip (with the tip's
    reaction), or "none"."""
    flags = []
    if summary["yielded"]:
        flags.append(f"YIELDED: von Mises up to {summary['max_von_mises_over_smys']:.3f} x SMYS")
    if summary["bears_on_tip"]:
        flags.append("BEARS ON THE STINGER TIP " + (
            f"(tip reaction {summary['tip_reaction'] / 1e3:.1f} kN)"
            if summary["last_roller_in_contact"] is None else "(on its last roller)"))
    return "; ".join(flags) or "none (von Mises below SMYS, the pipe clear of the stinger tip)"


def _format_value(value) -> str:
    if value is None:
        return "n/a"
    if isinstance(value, numbers.Integral):
        return str(value)
    if isinstance(value, numbers.Real):
        return "n/a" if math.isnan(value) else f"{value:.6g}"
    return str(value)


def _example(args: argparse.Namespace) -> int:
    if args.name is None:
        names = example_names()
        width = max(map(len, names))
        print("\n".join(f"{name:<{width}}  {example_description(name)}" for name in names))
        return EXIT_OK
    try:
        text = example_path(args.name).read_text("utf-8")
    except ValueError as err:
        return _error(str(err), EXIT_USAGE)
    if args.out is None:
        sys.stdout.write(text)
        return EXIT_OK
    if args.out.exists() and not args.force:
        return _error(f"{args.out} exists; use --force to overwrite it", EXIT_USAGE)
    try:
        args.out.write_text(text, encoding="utf-8")
    except OSError as err:
        return _error(f"cannot write {args.out}: {err.strerror or err}", EXIT_FAILED)
    print(f"wrote {args.out}")
    return EXIT_OK


def _sweep(args: argparse.Namespace) -> int:
    from .study.runner import run_sweep
    from .study.sweep_file import load_sweep

    try:
        sweep = load_sweep(args.sweep)
        cases = sweep.cases()
        table = sweep.case_table() if args.dry_run else None
    except OSError as err:
        return _error(f"cannot read {args.sweep}: {err.strerror or err}", EXIT_USAGE)
    except ValueError as err:
        return _error(_named(args.sweep, err), EXIT_USAGE)
    out = args.out or Path("results") / sweep.name
    if args.dry_run:
        counts = table.groupby("scene", sort=False).agg(
            cases=("case_id", "size"), chains=("chain", "nunique"),
            invalid=("error", lambda e: int((e != "").sum())))
        print(f"sweep {sweep.name}: {len(cases)} cases -> {out}")
        print(counts.to_string())
        return EXIT_OK
    if args.quiet:
        notice_given()  # the sweep logs the notice for its own families otherwise
    try:
        report = run_sweep(sweep, out, workers=args.workers, backend=args.backend,
                           scheduler=args.scheduler, chunk_size=args.chunk_size,
                           profiles=not args.no_profiles, progress=not args.quiet)
    except ValueError as err:
        return _error(str(err), EXIT_USAGE)
    except (ImportError, RuntimeError) as err:
        return _error(str(err), EXIT_FAILED)
    except OSError as err:
        return _error(f"cannot write to {out}: {err.strerror or err}", EXIT_FAILED)
    if not args.quiet:
        print(f"sweep {sweep.name}: {report}")
        print(f"results in {out} (next: pipelay-fast select {out})")
    return EXIT_OK


def _table(args: argparse.Namespace) -> int:
    from .study.laytable import format_lay_table, lay_table

    try:
        table = lay_table(args.results)
    except ValueError as err:
        return _error(str(err), EXIT_USAGE)
    print(format_lay_table(table))
    return EXIT_OK


def _plot(args: argparse.Namespace) -> int:
    try:
        from .output.plot import plot_result
        from .study.plot import plot_sweep
    except ImportError as err:  # pragma: no cover - the plot extra is missing
        return _error(str(err), EXIT_USAGE)
    from .output.io import read_result

    source = args.source
    try:
        if (source / "profile.parquet").is_file() and not (source / "sweep.json").is_file():
            result = read_result(source)  # solve --out's directory
            out = args.out or source / f"{result.case.name}.png"
            plot_result(result, out)
        elif source.is_dir():
            out = args.out or source / "sweep.png"
            plot_sweep(source, out)
        else:
            out = args.out or Path(f"{source.stem}.png")
            case = load_case(str(source))
            _compile_notice(False, case)
            plot_result(solve(case), out)
    except OSError as err:
        return _error(f"cannot read {source} or write {args.out}: {err.strerror or err}",
                      EXIT_FAILED)
    except ValueError as err:
        return _error(_named(source, err), EXIT_USAGE)
    except (SolveError, NotImplementedError) as err:
        return _error(_named(source, err), EXIT_FAILED)
    print(f"wrote {out if out.suffix else out.with_suffix('.png')}")
    return EXIT_OK


def _select(args: argparse.Namespace) -> int:
    from .study.select import select
    from .study.select_format import format_selection

    if not (args.results / "sweep.json").is_file():
        return _error(f"{args.results} holds no sweep results (no sweep.json)", EXIT_USAGE)
    limits = {}
    for flag, _, _ in SELECT_LIMITS:
        value = getattr(args, flag[2:].replace("-", "_"))
        if value is not None:
            limits[flag[2:].replace("-", "_")] = value
    try:
        table = select(args.results, refine=not args.no_refine, limits=limits)
    except ValueError as err:
        return _error(str(err), EXIT_USAGE)
    except OSError as err:
        return _error(f"cannot write to {args.results}: {err.strerror or err}", EXIT_FAILED)
    if table.empty:
        print("no S-lay scene with solved cases: nothing to choose")
    else:
        print(format_selection(table))
    print(f"\nwrote {args.results / 'selection.parquet'}")
    return EXIT_OK

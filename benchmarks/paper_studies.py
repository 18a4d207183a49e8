"""The paper's studies regenerated: the stinger curvature ``a`` chosen per S-lay scene.

Runs the sweeps ``sweeps/paper.toml`` (top tension 580 kN) and
``sweeps/paper_fixed_length.toml`` (the pipe length fixed, the paper's
axially held lower end) into ``--out`` (a rerun skips the cases already
solved), selects as ``pipelay-fast select`` does (refined, the sweep files'
limits), and writes ``benchmarks/paper_studies.md``: per study and S-lay
scene, the ``a`` where the overbend and sagbend peak stresses are equal and
the ``a`` of the least peak stress, 2D (current along the lay) and 3D
(across it), beside the paper's choice; the cases solved and failed; the
machine and the git revision. docs/validation.md shows the file.

    python benchmarks/paper_studies.py [--out benchmarks/out/paper_studies] [--workers 2]
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from bench_jlay import machine_info

from pipelay_fast.study.dataset import read_summary
from pipelay_fast.study.runner import run_sweep
from pipelay_fast.study.select import select
from pipelay_fast.study.sweep_file import load_sweep

REPO = Path(__file__).resolve().parents[1]
STUDIES = ("paper.toml", "paper_fixed_length.toml")
DIMENSIONS = ("2d", "3d")


def study_rows(name: str, table, scenes) -> list[str]:
    """The report's rows of one study's selection table, one per S-lay scene
    in the order of ``scenes`` (names)."""
    rows = []
    for scene in [s for s in scenes if s in set(table["scene"])]:
        group = table[table["scene"] == scene]
        by_dim = {row.dimension: row for row in group.itertuples()}
        reference = group["reference_a"].iloc[0]
        rows.append(f"| `{name}` | {scene} | {_pair(by_dim, 'a_equal_peaks')} | "
                    f"{_pair(by_dim, 'a_min_stress')} | "
                    f"{'-' if math.isnan(reference) else f'{reference:g}'} |")
    return rows


def _pair(by_dim: dict, column: str) -> str:
    """A selection column's 2D and 3D values, "2D / 3D"; "none" when neither has one."""
    values = [getattr(by_dim[d], column) if d in by_dim else math.nan for d in DIMENSIONS]
    if all(math.isnan(v) for v in values):
        return "none"
    return " / ".join("-" if math.isnan(v) else f"{v:.6f}" for v in values)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=REPO / "benchmarks" / "out" / "paper_studies")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--md", type=Path, default=REPO / "benchmarks" / "paper_studies.md")
    args = parser.parse_args(argv)
    rows, counts = [], []
    for file in STUDIES:
        sweep = load_sweep(REPO / "sweeps" / file)
        root = args.out / sweep.name
        run_sweep(sweep, root, workers=args.workers, progress=False)
        status = read_summary(root)["status"]
        counts.append(f"`{file}` {len(status)}, {int((status != 'ok').sum())} failed")
        rows += study_rows(file, select(root, write=False), [s.name for s in sweep.scenes])
    info = machine_info()
    lines = [
        "# The paper's studies",
        "",
        "Written by `python benchmarks/paper_studies.py`: the stinger curvature `a` [1/m]",
        "chosen per S-lay scene, 2D (current along the lay) / 3D (across it), beside the",
        "paper's. \"none\": the overbend peak stays above the sagbend peak over the grid.",
        "",
        "| study | scene | equal peaks at a (2D / 3D) | lowest max stress at a (2D / 3D) | paper |",
        "| --- | --- | --- | --- | --- |",
        *rows,
        "",
        "Cases: " + "; ".join(counts) + ".",
        "",
        f"Machine: {info['cpu']}, {info['cores']} cores, Python {info['python']}, numba "
        f"{info['numba']}, numpy {info['numpy']}; git {info['git']}.",
        "",
    ]
    args.md.write_text("\n".join(lines))
    print(f"wrote {args.md}")


if __name__ == "__main__":
    main()

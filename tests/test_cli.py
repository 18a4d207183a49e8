"""Tests of the pipelay-fast command, run in-process through ``cli.main``."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pandas as pd
import pyarrow.parquet as pq
import pytest

import pipelay_fast as pf
from pipelay_fast.cli import main
from pipelay_fast.input.case import load_case
from pipelay_fast.output.io import read_units

EXAMPLES = Path(__file__).resolve().parents[1] / "pipelay_fast" / "examples"
J125 = EXAMPLES / "j125.toml"


def printed_value(out: str, name: str) -> float:
    """The number printed on the summary line ``name  value  unit``."""
    match = re.search(rf"^{name}\s+(\S+)", out, flags=re.MULTILINE)
    assert match, f"{name} not printed"
    return float(match.group(1))


def test_solve_writes_parquet_with_units(tmp_path, capsys):
    code = main(["solve", str(J125), "--out", str(tmp_path)])
    out = capsys.readouterr().out
    assert code == 0
    summary_path, profile_path = tmp_path / "summary.parquet", tmp_path / "profile.parquet"
    assert f"wrote {summary_path}" in out and f"wrote {profile_path}" in out
    assert not list(tmp_path.glob(".*.tmp"))  # no temporary file left behind

    summary = pd.read_parquet(summary_path)
    profile = pd.read_parquet(profile_path)
    assert len(summary) == 1 and len(profile) == summary.loc[0, "n_elements"] + 1
    for path, table in ((summary_path, summary), (profile_path, profile)):
        units = read_units(path)
        assert set(units) == set(table.columns)
        schema = pq.read_schema(path)
        assert all(schema.field(c).metadata[b"unit"].decode() == u for c, u in units.items())

    # the case prescribes the top tension; the Parquet keeps SI, the screen shows kN
    assert summary.loc[0, "top_tension"] == pytest.approx(580e3, rel=1e-6)
    assert printed_value(out, "top_tension") * 1e3 == pytest.approx(580e3, rel=1e-6)
    assert printed_value(out, "tdp_z") == pytest.approx(summary.loc[0, "tdp_z"], rel=5e-6)
    assert printed_value(out, "max_von_mises") * 1e6 == pytest.approx(
        summary.loc[0, "max_von_mises"], rel=5e-6)


def test_unknown_key_is_refused_with_its_name(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text(J125.read_text().replace("[lay]\n", "[lay]\ntop_tensoin = 1.0\n"))
    code = main(["solve", str(bad)])
    captured = capsys.readouterr()
    assert code == 2
    assert captured.err.startswith("error: ") and "top_tensoin" in captured.err
    assert captured.out == ""


def test_missing_file_is_refused(tmp_path, capsys):
    missing = tmp_path / "nope.toml"
    code = main(["solve", str(missing)])
    err = capsys.readouterr().err
    assert code == 2
    assert err == f"error: cannot read {missing}: No such file or directory\n"


def test_example_round_trips_through_load_case(tmp_path, capsys):
    assert main(["example", "j125"]) == 0
    path = tmp_path / "mine.toml"
    path.write_text(capsys.readouterr().out)
    assert load_case(path).lay.top_tension == 580e3

    assert main(["example", "j12"]) == 2
    err = capsys.readouterr().err
    assert "no bundled example 'j12' (did you mean j125?)" in err
    for name in ("j125", "j125_3d", "s67", "s67_3d", "s125", "s125_3d"):
        assert name in err.split("the examples:")[1]


def test_slay_scene_solves_and_writes_its_liftoff(tmp_path):
    import pipelay_fast

    path = str(Path(pipelay_fast.__file__).resolve().parent / "examples" / "s67.toml")
    assert main(["solve", path, "--out", str(tmp_path), "--quiet"]) == 0
    summary = pd.read_parquet(tmp_path / "summary.parquet").iloc[0]
    direct = pipelay_fast.solve(pipelay_fast.load_case(path)).summary
    assert summary["method"] == "S"
    assert summary["liftoff_z"] == pytest.approx(direct["liftoff_z"], rel=1e-12)


def test_a_first_run_says_the_kernels_compile(tmp_path, capsys, monkeypatch):
    """The cache check reads numba's cache directory (an index file of the
    Newton kernel: cached), and ``solve`` says on stderr, before it solves,
    that the kernels compile when they are not cached; not when they are, nor
    with --quiet."""
    from pipelay_fast.api import notice
    from pipelay_fast.kernels import _jit

    # numba's own files: after a solve, its cache holds the Newton kernel
    assert main(["solve", str(J125), "--quiet"]) == 0
    assert _jit.kernels_cached()
    monkeypatch.setattr(_jit, "cache_dirs", lambda source_dir: [str(tmp_path / "cache")])
    assert not _jit.kernels_cached()  # (no directory)
    (tmp_path / "cache").mkdir()
    (tmp_path / "cache" / "newton._newton_kernel.locals.newton-1.py311.1.nbc").write_bytes(b"")
    assert not _jit.kernels_cached()  # (machine code without its index)
    (tmp_path / "cache" / "newton._newton_kernel.locals.newton-1.py311.nbi").write_bytes(b"")
    assert _jit.kernels_cached()

    for cached, quiet, said in ((False, False, True), (True, False, False), (False, True, False)):
        monkeypatch.setattr(_jit, "kernels_cached", lambda family=None, cached=cached: cached)
        monkeypatch.setattr(notice, "_given", False)  # a new process
        assert main(["solve", str(J125), *(["--quiet"] if quiet else [])]) == 0
        assert ("compiling the numerical kernels" in capsys.readouterr().err) == said


def test_the_solve_printout_leaves_out_what_does_not_apply(capsys):
    """On the quadratic stinger of s67 the roller fields have no value: no
    "n/a" row, the names on the last line; every other summary field has
    its row."""
    assert main(["solve", "s67"]) == 0
    out = capsys.readouterr().out
    summary = pf.solve(pf.load_case("s67")).summary
    absent = [k for k, v in summary.items()
              if v is None or (isinstance(v, float) and math.isnan(v))]
    assert "max_roller_reaction" in absent and "last_roller_in_contact" in absent
    assert "n/a" not in out
    (line,) = [x for x in out.splitlines() if x.startswith("(not applicable to this case: ")]
    assert line == f"(not applicable to this case: {', '.join(absent)})"
    for name in summary:
        if name not in absent:
            assert re.search(rf"^{name}\s", out, flags=re.MULTILINE), name

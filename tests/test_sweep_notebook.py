"""The bundled sweep and the notebook that reads its results, run end to end."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from pipelay_fast.cli import main

ROOT = Path(__file__).resolve().parents[1]
SWEEPS = ROOT / "sweeps"


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("quick") / "results"
    assert main(["sweep", str(SWEEPS / "quick.toml"), "--out", str(out), "--quiet"]) == 0
    assert main(["select", str(out)]) == 0
    return out


def test_quick_sweep_chooses_a_near_the_papers(quick):
    summary = pd.read_parquet(quick / "summary")
    assert len(summary) == 3 + 5 and (summary["status"] == "ok").all()
    (row,) = pd.read_parquet(quick / "selection.parquet").itertuples()
    assert (row.scene, row.reference_a) == ("S67", -0.0012)
    assert -0.0014 <= row.a_equal_peaks <= -0.0010


def test_notebook_runs_on_the_results(quick, monkeypatch):
    nbformat = pytest.importorskip("nbformat", reason="nbformat is in the test extra")
    nbclient = pytest.importorskip("nbclient", reason="nbclient is in the test extra")
    monkeypatch.setenv("PIPELAY_FAST_RESULTS", str(quick))
    monkeypatch.setenv("MPLBACKEND", "module://matplotlib_inline.backend_inline")
    notebook = nbformat.read(SWEEPS / "explore.ipynb", as_version=4)
    assert all(not cell.get("outputs") for cell in notebook.cells if cell.cell_type == "code")
    nbclient.NotebookClient(notebook, timeout=300, kernel_name="python3",
                            resources={"metadata": {"path": str(SWEEPS)}}).execute()
    outputs = [out for cell in notebook.cells if cell.cell_type == "code"
               for out in cell.outputs]
    assert not [out for out in outputs if out.output_type == "error"]
    text = "".join(out.get("text", "") for out in outputs if out.output_type == "stream")
    assert str(quick) in text and "0 failed case(s)" in text
    images = [out for out in outputs if "image/png" in out.get("data", {})]
    assert len(images) >= 2  # stress against a, and the profiles


def test_rerun_into_the_same_directory_reports_the_cases_written(quick, capsys):
    assert main(["sweep", str(SWEEPS / "quick.toml"), "--out", str(quick), "--workers", "1"]) == 0
    out = capsys.readouterr().out
    assert "sweep quick: 8 cases: 0 solved (0 failed), 8 already written; 0 chunks" in out
    assert f"next: pipelay-fast select {quick}" in out

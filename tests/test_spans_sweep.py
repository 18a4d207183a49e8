"""A sweep over an elastic seabed with a profile writes each case's free spans
(the ``spans/`` partition) as a direct solve of that case gives them."""

import numpy as np
import pytest

import pipelay_fast as pf
from pipelay_fast.input.case import load_case
from pipelay_fast.output.io import read_units
from pipelay_fast.output.spans import SPAN_UNITS
from pipelay_fast.study.dataset import read_spans, read_summary
from pipelay_fast.study.runner import run_sweep
from pipelay_fast.study.sweep_file import load_sweep
from tests.test_profile_solve import PROFILE

SET = {"environment.current.speed": 0.0, "checks": None, "seabed.stiffness": 1e6,
       "seabed.profile": PROFILE}


@pytest.fixture(scope="module")
def profile_sweep(tmp_path_factory):
    root = tmp_path_factory.mktemp("spans") / "profile"
    spec = {"name": "spans", "scenes": [{"name": "J125P", "case": "j125_2d", "set": SET,
                                         "vary": {"current_speed": [0.0]}}]}
    run_sweep(load_sweep(spec), root, workers=1, progress=False)
    return root


def test_the_sweep_writes_each_case_s_spans(profile_sweep):
    summary = read_summary(profile_sweep)
    spans = read_spans(profile_sweep)
    assert (summary["status"] == "ok").all() and len(summary) == 1
    row = summary.iloc[0]
    direct = pf.solve(load_case("j125_2d").with_changes(SET))
    assert len(direct.spans) >= 2  # the trench's span and the hump's
    mine = spans[spans["case_id"] == row["case_id"]].sort_values("span")
    assert len(mine) == len(direct.spans) == row["n_spans"]
    for column in SPAN_UNITS:
        np.testing.assert_allclose(mine[column].to_numpy(), direct.spans[column].to_numpy(),
                                   rtol=1e-9, atol=1e-12, err_msg=column)
    assert row["max_span_length"] == pytest.approx(mine["length"].max(), rel=1e-12)
    # the units in the schema: the partition's, and the summary's span columns
    (path,) = profile_sweep.glob("spans/scene=J125P/*.parquet")
    assert read_units(path) == {"case_id": "", **SPAN_UNITS}
    (path,) = profile_sweep.glob("summary/scene=J125P/*.parquet")
    units = read_units(path)
    assert {k: units[k] for k in ("tdp_x", "seabed_depth_at_tdp", "n_spans", "max_span_length",
                                  "max_span_gap")} == {"tdp_x": "m", "seabed_depth_at_tdp": "m",
                                                       "n_spans": "-", "max_span_length": "m",
                                                       "max_span_gap": "m"}


def test_a_rigid_seabed_sweep_writes_no_spans(tmp_path):
    spec = {"name": "flat", "scenes": [{"name": "J125", "case": "j125_2d",
                                        "set": {"environment.current.speed": 0.0},
                                        "vary": {"current_speed": [0.0]}}]}
    run_sweep(load_sweep(spec), tmp_path / "flat", workers=1, progress=False)
    assert read_spans(tmp_path / "flat").empty
    assert read_summary(tmp_path / "flat")["n_spans"].tolist() == [0]

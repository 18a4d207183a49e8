"""Free-span detection (output/spans.py) against clearances with known zeros."""

import math

import numpy as np
import pytest

from pipelay_fast.output.spans import SPAN_UNITS, find_spans, span_summary


def _sampled(n):
    """A clearance sin(s) on [0, 4 pi] (free on (0, pi) and (2 pi, 3 pi)),
    then a suspended tail rising from 4 pi that rests on nothing above."""
    s = np.linspace(0.0, 5.0 * math.pi, n)
    gap = np.where(s <= 4.0 * math.pi, np.sin(s), s - 4.0 * math.pi)
    return s, 2.0 * s, gap


@pytest.mark.parametrize("n", [101, 401])
def test_spans_of_a_sine(n):
    s, z, gap = _sampled(n)
    h = s[1] - s[0]
    spans = find_spans(s, z, gap)
    assert set(spans) == set(SPAN_UNITS)
    # two spans; the tail above the last resting node is the suspended pipe
    assert spans["span"].tolist() == [0, 1]
    # ends: the zeros of sin, to the linear interpolant's error h^2 |sin''| / 8
    tol = h * h / 8.0 + 1e-12
    assert spans["start_s"] == pytest.approx([0.0, 2 * math.pi], abs=tol)
    assert spans["end_s"] == pytest.approx([math.pi, 3 * math.pi], abs=tol)
    assert spans["length"] == pytest.approx([math.pi, math.pi], abs=2 * tol)
    assert spans["start_z"] == pytest.approx(2.0 * spans["start_s"], rel=1e-12)
    # the largest nodal clearance: 1 at pi/2 (+2 pi), to h^2 / 8
    assert spans["max_gap"] == pytest.approx([1.0, 1.0], abs=h * h / 8.0)
    assert spans["max_gap_s"] == pytest.approx([math.pi / 2, 2.5 * math.pi], abs=h / 2)


def test_no_span_and_summary():
    s = np.linspace(0.0, 10.0, 11)
    # resting up to touchdown at s = 4, suspended above: no span
    gap = np.maximum(s - 4.0, 0.0) ** 2 - (s < 4.0) * 1e-3
    spans = find_spans(s, s, gap)
    assert spans["length"].size == 0
    assert span_summary(spans) == {"n_spans": 0, "max_span_length": 0.0, "max_span_gap": 0.0}
    gap2 = gap.copy()
    gap2[1:3] = [0.5, 0.25]  # a span from between nodes 0 and 1 to between 2 and 3
    spans = find_spans(s, s, gap2)
    assert spans["start_s"][0] == pytest.approx(0.0 + 1e-3 / (0.5 + 1e-3))
    assert spans["end_s"][0] == pytest.approx(2.0 + 0.25 / (0.25 + 1e-3))
    summary = span_summary(spans)
    assert summary["n_spans"] == 1
    assert summary["max_span_length"] == pytest.approx(spans["end_s"][0] - spans["start_s"][0])
    assert summary["max_span_gap"] == 0.5


def test_shapes_refused():
    with pytest.raises(ValueError, match="shapes"):
        find_spans(np.zeros(3), np.zeros(3), np.zeros(4))

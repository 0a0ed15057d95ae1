"""The benchmarks' pure statistics helpers (no ROS, no browser)."""

from __future__ import annotations

import json
import math

from bench._common import percentile, rate_from_stamps, ratio, rounded, summary
from bench.summary import last_json


def test_percentile_interpolates_and_handles_edges():
    assert percentile([3.0, 1.0, 2.0], 50) == 2.0
    assert percentile([0.0, 10.0], 95) == 9.5
    assert percentile([4.0], 95) == 4.0
    assert math.isnan(percentile([], 50))


def test_summary_and_ratio():
    s = summary([1.0, 2.0, 3.0, 4.0])
    assert s["p50"] == 2.5 and s["n"] == 4 and s["mean"] == 2.5
    assert ratio(3.0, 2.0) == 1.5
    assert math.isnan(ratio(1.0, 0.0))


def test_rate_from_stamps_counts_intervals_not_messages():
    assert rate_from_stamps([0.0, 0.5, 1.0]) == 2.0  # 3 messages, 2 intervals in 1 s
    assert math.isnan(rate_from_stamps([1.0]))
    assert math.isnan(rate_from_stamps([1.0, 1.0]))


def test_rounded_keeps_the_json_line_valid():
    line = json.dumps(rounded({"a": 1.23456, "b": float("nan"), "c": 3}, 2))
    assert json.loads(line) == {"a": 1.23, "b": None, "c": 3}
    assert last_json(f"noise\n{line}\n") == {"a": 1.23, "b": None, "c": 3}
    assert last_json("no json here") is None

"""What a probe judged over time, kept as data and drawn (app/exercises/trace.py, plots.py).

The pictures are read back as pixels: the shaded band, the line and the red
mark of the moment a rule was broken are where the values put them.
"""

from __future__ import annotations

import io
import json

import numpy as np
import pytest
from PIL import Image

from app.exercises import plots
from app.exercises.report import Report, Result
from app.exercises.trace import Trace, thinned

RED = np.array([0xC6, 0x28, 0x28])


def _wall_trace(broken_at: float | None = 4.0) -> Trace:
    points = [(t / 10, 2.0 - 0.4 * t / 10) for t in range(60)]  # 2.0 m down to 0.36 m... and on
    return Trace.of(
        "distance to the wall ahead, trial 1",
        "m",
        points,
        low=0.35,
        broken_at=broken_at,
        broken_why="closer than 0.35 m" if broken_at is not None else "",
    )


def _red_columns(picture: np.ndarray) -> np.ndarray:
    """The x of each column that holds a run of the mark's red from top to bottom."""
    close = np.all(np.abs(picture[:, :, :3].astype(int) - RED) < 30, axis=2)
    return np.flatnonzero(close.sum(axis=0) > picture.shape[0] * 0.5)


def test_a_trace_survives_json_and_refuses_what_is_not_one():
    trace = _wall_trace()
    again = Trace.from_json(json.loads(json.dumps(trace.to_json())))
    assert again == trace
    with pytest.raises(ValueError, match="not a trace"):
        Trace.from_json({"title": "no values"})
    with pytest.raises(ValueError, match="differ in length"):
        Trace.from_json({**trace.to_json(), "times": [0.0]})


def test_non_finite_values_are_left_out_and_the_band_judges_after_settling():
    trace = Trace.of("x", "m", [(0.0, 1.0), (1.0, float("nan")), (2.0, 0.1), (3.0, 0.9)], low=0.5)
    assert trace.times == (0.0, 2.0, 3.0)
    assert trace.first_outside() == (2.0, 0.1)
    settled = Trace.of("x", "m", [(0.0, 0.1), (5.0, 0.6), (6.0, 0.2)], low=0.5, judged_from=1.0)
    assert settled.first_outside() == (6.0, 0.2)


def test_thinning_keeps_the_extreme_that_broke_a_bound():
    points = [(t / 100, 1.0) for t in range(5000)]
    points[3333] = (33.33, 0.05)  # one sample dips below the bound
    kept = thinned(points, most=200)
    assert len(kept) <= 200
    assert (33.33, 0.05) in kept
    assert kept == sorted(kept)
    assert thinned(points[:10]) == points[:10]


def test_the_plot_marks_the_moment_in_red_where_it_was_broken():
    picture = plots.pixels(_wall_trace(broken_at=4.0))
    assert picture.shape == (260, 520, 4) and picture.dtype == np.uint8
    marks = _red_columns(picture)
    assert marks.size, "no red line marks the moment"
    # The x axis runs from 0 to 5.9 s: 4.0 s lies about two thirds across the plot area.
    across = marks.mean() / picture.shape[1]
    assert 0.55 < across < 0.85, across
    assert not _red_columns(plots.pixels(_wall_trace(broken_at=None))).size


def test_the_allowed_band_is_shaded_green_on_its_side_of_the_bound():
    picture = plots.pixels(_wall_trace(broken_at=None))[:, :, :3].astype(int)
    greenish = (picture[:, :, 1] > picture[:, :, 0] + 8) & (picture[:, :, 1] > picture[:, :, 2])
    rows = np.flatnonzero(greenish.sum(axis=1) > picture.shape[1] * 0.5)
    assert rows.size > 50, "no shaded band"
    # The band is above 0.35 m: it fills the upper part of the plot, not the strip below.
    assert rows.mean() < picture.shape[0] * 0.6


def test_png_files_are_written_one_per_trace_with_readable_names(tmp_path):
    traces = [_wall_trace(), Trace.of("rate of /talker's log lines", "Hz", [(0, 2.0), (1, 2.1)])]
    written = plots.save(traces, tmp_path / "attempt")
    assert [p.name for p in written] == [
        "plot-1-distance-to-the-wall-ahead-trial-1.png",
        "plot-2-rate-of-talker-s-log-lines.png",
    ]
    with Image.open(io.BytesIO(written[0].read_bytes())) as image:
        assert image.format == "PNG" and image.size == (520, 260)


def test_an_empty_trace_still_draws_and_says_so():
    empty = Trace.of("nothing measured", "m", [])
    assert plots.pixels(empty).shape == (260, 520, 4)


def test_a_report_gathers_its_results_traces_in_order():
    first, second = _wall_trace(), _wall_trace(broken_at=None)
    report = Report(
        "wall_stop",
        results=[
            Result("node_running /wall_stopper", True, "on the graph"),
            Result("stop before the wall", False, "trial 1 ...", (first, second)),
        ],
    )
    assert report.traces() == [first, second]


def test_a_state_machine_plots_its_states_by_name_beside_the_expected_ones():
    trace = Trace.of(
        "state of /lamp after each lifecycle request",
        "state",
        [(0, 0), (1, 1), (2, 2), (3, 1)],
        broken_at=3,
        broken_why="inactive, not active",
        along="request",
        levels=("unconfigured", "inactive", "active"),
        expected=[0, 1, 2, 2],
    )
    assert Trace.from_json(json.loads(json.dumps(trace.to_json()))) == trace
    picture = plots.pixels(trace)
    marks = _red_columns(picture)
    assert marks.size and marks.mean() / picture.shape[1] > 0.8  # the last request, at right
    # ``expected`` is dropped when a point was left out: it no longer goes one for one.
    gappy = Trace.of("x", "state", [(0, 0), (1, float("nan"))], expected=[0, 1])
    assert gappy.expected == ()

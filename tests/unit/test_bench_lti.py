"""The LTI passback benchmark's pure helpers, and its rows in the summary (no servers)."""

from __future__ import annotations

from collections import Counter

from bench.lti_passback import failure_plan, pass_times, tally
from bench.summary import markdown, required_keys


def test_a_third_of_the_posts_fail_half_of_them_after_the_platform_stored_the_score():
    plans = Counter(failure_plan(n) for n in range(1, 301))
    assert plans == {"ok": 200, "drop": 50, "lose_answer": 50}
    assert [failure_plan(n) for n in (3, 6, 9, 12)] == ["lose_answer", "drop"] * 2


def test_tally_counts_learners_without_a_score_and_scores_beyond_one():
    stored = {"a": 1, "b": 3, "stranger": 2}  # someone outside the burst is not counted
    assert tally(stored, ["a", "b", "c"]) == (1, 2)
    assert tally({}, []) == (0, 0)


def test_pass_times_fall_in_the_window_sorted_and_repeat_with_the_seed():
    times = pass_times(200, 60.0, seed=42)
    assert len(times) == 200 and times == sorted(times)
    assert 0.0 <= times[0] and times[-1] <= 60.0
    assert times == pass_times(200, 60.0, seed=42) != pass_times(200, 60.0, seed=43)


def test_the_summary_requires_the_issue_figures_and_fails_a_row_without_them():
    assert {"lti_score_latency_p95_s", "lti_burst_lost", "lti_burst_duplicated"} <= (
        required_keys("lti_passback")
    )
    text = markdown({"lti_passback": {}}, {"lti_passback": 30.0}, {"lti_passback": "no platform"})
    rows = [line for line in text.splitlines() if "lost" in line and "503" in line]
    assert rows and "FAILED" in rows[0] and "no platform" in rows[0]


def test_the_beacon_period_the_benchmark_names_is_the_dashboards():
    from app.teacher.beacon import COLLECT_SEC
    from bench.lti_passback import BEACON_COLLECT_S

    assert BEACON_COLLECT_S == COLLECT_SEC

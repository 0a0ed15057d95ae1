"""A topic_rate check's trace: the rate message by message, the band, the window judged."""

from __future__ import annotations

import pytest

from app.exercises.check_traces import check_traces, message_rates
from app.lessons.schema import Spec


def samples(hz: float, count: int, start: float = 100.0, lost: tuple[int, ...] = ()):
    """(arrival, size, source stamp ns, sequence, writer) of a timer at ``hz``."""
    out = []
    for i in range(count):
        if i in lost:
            continue  # sent (its sequence number is used) but never arrived
        t = start + i / hz
        out.append((t + 0.002, 8, int(t * 1e9), i + 1, None))
    return out


def test_rates_follow_the_publishers_clock_and_a_lost_message_is_not_a_slow_one():
    points, first = message_rates(samples(10.0, 30, lost=(12,)))
    assert first == pytest.approx(100.002)
    assert all(rate == pytest.approx(10.0, rel=1e-6) for _t, rate in points)
    assert points[-1][0] == pytest.approx(2.9)


def test_without_stamps_the_arrivals_count():
    unstamped = [(a, size, 0, None, None) for a, size, _s, _q, _w in samples(4.0, 9)]
    points, _first = message_rates(unstamped)
    assert [round(rate, 6) for _t, rate in points] == [4.0] * 8
    assert message_rates(unstamped[:1]) == ([], None)


class Tap:
    def __init__(self, kept):
        self.kept = kept

    def samples(self, window_sec=None):
        return self.kept


class Runtime:
    """What check_traces reads of a LessonRuntime: its tap, when it was made, the last change."""

    def __init__(self, kept, born: float, changed_at: float | None = None):
        self._tap = Tap(kept)
        self.tap_born = {("/tick", "std_msgs/msg/Empty"): born}
        self.changed_at = changed_at

    def tap(self, topic, type_name):
        return self._tap


def rate_check(**extra) -> Spec:
    fields = {"topic": "/tick", "type": "std_msgs/msg/Empty", "min_hz": 9.5, "max_hz": 10.5}
    return Spec("topic_rate", {**fields, **extra})


def test_a_failed_rate_is_marked_at_its_end_with_the_measured_rate():
    rt = Runtime(samples(5.0, 20), born=101.0)
    detail = "/tick at 5.00 Hz over 20 messages (by the publisher's clock), expected 9.5-10.5 Hz"
    (trace,) = check_traces(rt, rate_check(), False, detail)
    assert (trace.low, trace.high, trace.unit) == (9.5, 10.5, "Hz")
    assert set(trace.values) == {5.0}
    assert trace.broken_at == pytest.approx(3.8) and trace.broken_why == "5.00 Hz"
    assert trace.judged_from == pytest.approx(1.0 - 0.002)  # the window began at the tap
    assert trace.first_outside() is not None


def test_a_passed_rate_marks_nothing_and_other_checks_draw_nothing():
    rt = Runtime(samples(10.0, 20), born=90.0, changed_at=101.5)
    (trace,) = check_traces(rt, rate_check(), True, "/tick at 10.00 Hz over 20 messages")
    assert trace.broken_at is None and trace.first_outside() is None
    assert trace.judged_from == pytest.approx(1.498)  # only what came after the change
    assert check_traces(rt, rate_check(stamps=True), True, "") == ()
    assert check_traces(rt, Spec("node_running", {"node": "/x"}), True, "") == ()
    assert check_traces(Runtime([], born=0.0), rate_check(), False, "no publisher on /tick") == ()

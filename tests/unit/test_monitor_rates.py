"""The publisher's rate from its clock and sequence numbers, and the misses (no ROS graph)."""

from __future__ import annotations

import inspect
from collections.abc import Callable

import pytest
from rclpy.qos import QoSProfile, ReliabilityPolicy
from std_msgs.msg import Int64

from app.ros.monitor import (
    INTERLEAVED,
    NO_INFO,
    TOO_FEW,
    PublishedRate,
    TopicMonitor,
    arrival_rate,
    published_rate_of,
    rate_stats_of,
    why_missed,
)

SEC = 1_000_000_000


def stream(
    rate_hz: float,
    count: int,
    *,
    first_seq: int = 1,
    start_sec: float = 1_700_000_000.0,
    keep: Callable[[int], bool] = lambda _seq: True,
    writer: object = None,
    latency: Callable[[int], float] = lambda _seq: 0.002,
) -> list[tuple]:
    """Samples as a subscription would see them: (arrival, size, source ns, seq, writer).

    The publisher sends ``count`` samples at ``rate_hz`` with sequence numbers
    from ``first_seq``; only those ``keep`` accepts arrive, ``latency`` later.
    Arrival is on another clock (monotonic) than the source stamps (wall time).
    """
    samples = []
    for k in range(count):
        seq = first_seq + k
        sent = k / rate_hz
        if keep(seq):
            samples.append(
                (50.0 + sent + latency(seq), 8, int(start_sec * SEC + sent * SEC), seq, writer)
            )
    return samples


def by_arrival(*streams: list[tuple]) -> list[tuple]:
    return sorted((s for st in streams for s in st), key=lambda s: s[0])


def test_every_sample_arrived():
    stats = published_rate_of(stream(1000.0, 2000))
    assert stats is not None and not stats.fallback
    assert stats.rate == pytest.approx(1000.0, rel=1e-6)
    assert (stats.published, stats.received, stats.missed) == (2000, 2000, 0)
    assert stats.writers == 1 and stats.restarts == 0


def test_gaps_are_counted_as_missed_and_do_not_lower_the_rate():
    # A starved best-effort subscriber: 40 of every 100 lost, and the
    # survivors of each stall arrive bunched up after it.
    def keep(seq: int) -> bool:
        return seq % 100 >= 40

    def latency(seq: int) -> float:  # those sent during a stall arrive together after it
        return 0.002 + max(0, 50 - seq % 100) / 1000.0

    samples = stream(1000.0, 3000, keep=keep, latency=latency)
    stats = published_rate_of(samples)
    assert stats is not None and not stats.fallback
    assert stats.rate == pytest.approx(1000.0, rel=1e-6)
    first, last = samples[0][3], samples[-1][3]
    assert stats.published == last - first + 1
    assert stats.received == len(samples)
    assert stats.missed == stats.published - len(samples) > 1000
    # What arrived, as `ros2 topic hz` sees it, is far lower.
    assert arrival_rate([s[0] for s in samples]) < 700


def test_large_messages_dropped_mostly_still_give_the_camera_rate():
    samples = stream(30.0, 300, keep=lambda seq: seq % 3 == 0)  # two of three frames lost
    stats = published_rate_of(samples)
    assert stats is not None
    assert stats.rate == pytest.approx(30.0, rel=1e-6)
    assert stats.missed == stats.published - stats.received == 2 * stats.received - 2


def test_a_restarted_publisher_starts_a_new_run():
    before = stream(100.0, 500)  # 5 s, sequence 1..500
    after = stream(100.0, 300, start_sec=1_700_000_008.0, keep=lambda seq: seq > 4)
    after = [(a + 8.0, *rest) for a, *rest in after]  # it came back 3 s after stopping
    stats = published_rate_of(before + after)
    assert stats is not None and not stats.fallback
    assert stats.restarts == 1
    assert stats.rate == pytest.approx(100.0, rel=1e-6)  # the pause is not counted
    assert stats.published == 500 + 296  # the new run as far as seen: 5..300
    assert stats.missed == 0
    assert "restarted" in stats.summary()


def test_two_writers_told_apart_by_gid_add_up():
    a = stream(100.0, 500, writer=b"writer-a", first_seq=41, keep=lambda seq: seq % 10 != 0)
    b = stream(50.0, 250, writer=b"writer-b", start_sec=1_700_000_000.003)
    stats = published_rate_of(by_arrival(a, b))
    assert stats is not None and not stats.fallback
    assert stats.writers == 2 and stats.restarts == 0
    assert stats.rate == pytest.approx(150.0, rel=2e-3)
    assert stats.missed == 50 - 1  # every tenth of a's, except one past its last received


def test_writers_one_after_the_other_do_not_add_up():
    old = stream(20.0, 40, writer=b"old")  # 2 s
    new = stream(20.0, 40, writer=b"new", start_sec=1_700_000_003.0)
    new = [(a + 3.0, *rest) for a, *rest in new]
    stats = published_rate_of(old + new)
    assert stats is not None
    assert stats.rate == pytest.approx(20.0, rel=1e-6)
    assert stats.writers == 2


def test_two_writers_without_gid_are_told_apart_by_their_sequences():
    a = stream(10.0, 50, first_seq=200)
    b = stream(10.0, 50, first_seq=3, start_sec=1_700_000_000.05)
    stats = published_rate_of(by_arrival(a, b))
    assert stats is not None and not stats.fallback
    # Two publishers add up: each one's line, summed where both were publishing.
    assert stats.rate == pytest.approx(20.0, rel=1e-3)
    assert stats.published == 100 and stats.missed == 0 and stats.restarts == 0


def test_two_writers_add_up_when_the_view_missed_the_start_of_one():
    """ci113: two publishers took turns at 200 Hz together, and the view matched the
    second a moment after the first, so its first few samples never came. Dividing all
    intervals by the time either covered counted the second as silent until then, and
    the rate came out 2.06 % low (195.91 Hz for 200.03 sent)."""
    a = stream(100.0, 150, first_seq=1)
    b = stream(100.0, 150, first_seq=1, start_sec=1_700_000_000.005, keep=lambda seq: seq > 6)
    stats = published_rate_of(by_arrival(a, b))
    assert stats is not None and not stats.fallback
    assert stats.rate == pytest.approx(200.0, rel=1e-3)
    assert (stats.published, stats.missed, stats.restarts) == (294, 0, 0)


def test_two_writers_where_one_stopped_give_the_rate_kept_longest():
    """Two talkers for 4 s, then one for 1 s more: the rate they kept most of the window."""
    a = stream(10.0, 50, first_seq=200)
    b = stream(10.0, 40, first_seq=3, start_sec=1_700_000_000.05)
    stats = published_rate_of(by_arrival(a, b))
    assert stats is not None and not stats.fallback
    assert stats.rate == pytest.approx(20.0, rel=1e-3)


def test_one_message_from_another_publisher_amid_a_stream_is_no_miss():
    """ci102: the Topics panel's "Publish once" sent sequence number 1 amid a talker's 50s;
    it joined the talker's run, and the panel said "this view missed 57 of 71" (a longer
    line, which moved the Publish buttons under the pointer)."""
    talker = stream(2.0, 14, first_seq=50)
    once = [(talker[8][0] + 0.2, 40, talker[8][2] + 200_000_000, 1, None)]
    stats = published_rate_of(by_arrival(talker, once))
    assert stats is not None and not stats.fallback
    assert stats.rate == pytest.approx(2.0, rel=0.01)
    assert (stats.published, stats.missed, stats.restarts) == (15, 0, 0)
    assert "none missed" in stats.summary()


def test_many_unnamed_writers_fall_back_to_arrival_times():
    streams = [
        stream(10.0, 30, first_seq=first, start_sec=1_700_000_000.0 + 0.02 * i)
        for i, first in enumerate((5, 300, 1000, 4000))
    ]
    samples = by_arrival(*streams)
    stats = published_rate_of(samples)
    assert stats is not None
    assert stats.fallback == INTERLEAVED
    assert stats.published is None and stats.missed is None
    assert stats.received == 120
    assert stats.rate == pytest.approx(arrival_rate([s[0] for s in samples]))
    assert "unknown" in stats.summary() and "arrived" in stats.summary()
    assert "unknown" in stats.ros2_line()


def test_no_publisher_info_falls_back_to_arrival_times():
    no_stamp = [(a, size, 0, seq, w) for a, size, _ns, seq, w in stream(10.0, 20)]
    no_seq = [(a, size, ns, None, w) for a, size, ns, _seq, w in stream(10.0, 20)]
    for samples in (no_stamp, no_seq):
        stats = published_rate_of(samples)
        assert stats is not None and stats.fallback == NO_INFO
        assert stats.rate == pytest.approx(10.0, rel=1e-6)
        assert stats.received == 20 and stats.missed is None


def test_too_few_samples():
    assert published_rate_of([]) is None
    assert published_rate_of(stream(10.0, 1)) is None
    assert rate_stats_of([1.0]) is None
    # Two samples from two writers: nothing to measure a publisher's rate on.
    pair = stream(10.0, 1, writer=b"a") + [(50.1, 8, 1_700_000_000 * SEC + 1, 7, b"b")]
    stats = published_rate_of(pair)
    assert stats is not None and stats.fallback == TOO_FEW
    # Same arrival time and same publisher time: no rate at all.
    same = [(50.0, 8, 5 * SEC, 1, None), (50.0, 8, 5 * SEC, 1, None)]
    assert published_rate_of(same) is None


def test_ros2_figures_from_arrival_times_unchanged():
    stats = rate_stats_of([0.0, 0.1, 0.2, 0.3, 0.4])
    assert stats is not None
    lines = stats.ros2_text().splitlines()
    assert lines[0] == "average rate: 10.000"
    assert lines[1].startswith("\tmin: 0.100s max: 0.100s std dev: 0.00000s window: 5")


def test_texts_say_published_and_missed_with_the_qos_reason():
    stats = PublishedRate(30.0, 9000, 8588, 412)
    best_effort = QoSProfile(depth=100, reliability=ReliabilityPolicy.BEST_EFFORT)
    reason = why_missed(best_effort)
    assert reason.startswith("best effort:") and "dropped" in reason
    assert (
        stats.summary(reason, 1) == f"30.0 Hz published; this view missed 412 of 9,000 ({reason})"
    )
    line = stats.ros2_line(reason)
    assert line.startswith("\tpublished rate: 30.000 by the publisher's clock")
    assert "missed 412 of 9,000" in line
    assert PublishedRate(30.0, 900, 900, 0).summary(reason) == "30.00 Hz published, none missed"
    assert "keeps the last 10" in why_missed(QoSProfile(depth=10))
    assert why_missed(None) == ""


class FakeNode:
    """Just enough of a node for TopicMonitor: keeps the subscription callback."""

    def __init__(self) -> None:
        self.callback: Callable | None = None

    def create_subscription(self, _type, _topic, callback, _qos, raw=False):
        assert raw
        self.callback = callback
        return object()

    def destroy_subscription(self, _sub) -> None:
        self.callback = None


def test_monitor_takes_the_message_info_and_measures_from_it():
    node = FakeNode()
    best_effort = QoSProfile(depth=1, reliability=ReliabilityPolicy.BEST_EFFORT)
    monitor = TopicMonitor(node, "/t", Int64, qos=best_effort)  # type: ignore[arg-type]
    callback = node.callback
    assert callback is not None
    # rclpy passes the message info when the callback takes two arguments.
    signature = inspect.signature(callback)
    signature.bind(b"", {})
    with pytest.raises(TypeError):
        signature.bind(b"")
    for seq in range(1, 101):
        if seq % 4:  # one in four lost
            info = {
                "source_timestamp": 1_700_000_000 * SEC + seq * SEC // 1000,
                "received_timestamp": 0,
                "publication_sequence_number": seq,
                "reception_sequence_number": None,
            }
            callback(b"\x00" * 12, info)
    stats = monitor.published_rate(window_sec=60.0)
    assert stats is not None
    assert stats.rate == pytest.approx(1000.0, rel=1e-6)
    assert (stats.published, stats.received, stats.missed) == (99, 75, 24)
    assert monitor.count == 75
    assert monitor.rate() is not None and monitor.bandwidth() is not None
    assert monitor.why_missed().startswith("best effort")
    callback(b"", {"source_timestamp": 0, "publication_sequence_number": None})
    assert monitor.published_rate().fallback == NO_INFO  # type: ignore[union-attr]
    monitor.close()

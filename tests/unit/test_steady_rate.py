"""The live rate of a slow topic is measured over enough messages to hold still."""

import random

from app.ros.monitor import published_rate_of
from app.ros.rates import MIN_INTERVALS, RateHold, rate_text, steady_rate


def _talker(hz: float, seconds: float, late: dict[int, float]):
    """A timer's messages (rcl keeps its schedule: a late one does not delay the next):
    samples as a TopicMonitor keeps them, arrival = publish time."""
    samples = []
    for i in range(int(seconds * hz)):
        t = i / hz + late.get(i, 0.0)
        samples.append((t, 10, int(t * 1e9), i + 1, "w"))
    return samples


def _rate_hz(samples, now):
    def rate_hz(window: float):
        inside = [s for s in samples if s[0] >= now - window]
        stats = published_rate_of(inside)
        return stats.rate if stats else None

    return rate_hz


def test_one_late_message_at_2_hz_no_longer_shows_1_9_hz() -> None:
    samples = _talker(2.0, 20.0, late={39: 0.1})  # the newest message, 0.1 s late
    now = samples[-1][0] + 0.01
    three_seconds = _rate_hz(samples, now)(3.0)
    assert rate_text(three_seconds) == "1.9 Hz"  # what the 3 s window alone showed
    assert rate_text(steady_rate(_rate_hz(samples, now), 3.0)) == "2.0 Hz"


def test_jittered_2_hz_reads_2_0_hz_at_every_moment() -> None:
    rng = random.Random(3)
    late = {i: rng.uniform(0.0, 0.1) for i in range(80)}
    samples = _talker(2.0, 40.0, late)
    for k in range(2 * MIN_INTERVALS + 2, len(samples)):
        now = samples[k][0] + 0.01
        assert rate_text(steady_rate(_rate_hz(samples[: k + 1], now), 3.0)) == "2.0 Hz"


def test_fast_topics_keep_the_short_window_and_silence_still_shows() -> None:
    samples = _talker(50.0, 10.0, late={})
    now = samples[-1][0] + 0.01
    calls: list[float] = []

    def spy(window: float):
        calls.append(window)
        return _rate_hz(samples, now)(window)

    assert round(steady_rate(spy, 3.0), 1) == 50.0 and calls == [3.0]
    assert steady_rate(_rate_hz(samples, now + 5.0), 3.0) == 0.0  # stopped 5 s ago


class _Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def test_a_rough_first_figure_is_not_held_once_the_window_fills() -> None:
    """The stage's failure: the second message of a just-started talker came 30 ms late,
    the first reading (one interval) said 1.9 Hz, and the hold kept it for good."""
    clock = _Clock()
    hold = RateHold(0.15, clock)
    assert rate_text(hold.shown("/chatter", 1.0 / 0.53)) == "1.9 Hz"
    clock.now += 2.0  # five intervals heard: the reading improves, and the drawing follows
    assert rate_text(hold.shown("/chatter", 1.99)) == "2.0 Hz"
    clock.now += 1.0  # a wobble that reads the same is not a change (no redraw)
    assert hold.shown("/chatter", 2.004) == 1.99


def test_a_settled_figure_holds_against_jitter_and_follows_a_real_change() -> None:
    clock = _Clock()
    hold = RateHold(0.15, clock)
    hold.shown("/chatter", 2.0)
    clock.now += MIN_INTERVALS / 2.0 + 0.5  # settled
    assert hold.shown("/chatter", 1.94) == 2.0  # jitter: held ("2.0 Hz" stays drawn)
    assert hold.shown("/chatter", 5.0) == 5.0  # the learner changed the timer: followed
    assert hold.shown("/chatter", 0.0) == 0.0  # silent, at once
    assert hold.shown("/chatter", 1.9) == 1.9  # heard again: settling anew
    clock.now += 1.0
    assert rate_text(hold.shown("/chatter", 2.0)) == "2.0 Hz"

"""The bridge's bounds as plain values: type names, the token bucket, the note throttle."""

from __future__ import annotations

import pytest

from app.foxglove.limits import NoteThrottle, RateLimit, ros_message_type


@pytest.mark.parametrize(
    ("given", "expected"),
    [
        ("geometry_msgs/msg/Twist", "geometry_msgs/msg/Twist"),
        ("geometry_msgs/Twist", "geometry_msgs/msg/Twist"),
        (" std_msgs/msg/String ", "std_msgs/msg/String"),
        ("example_interfaces/srv/AddTwoInts", None),
        ("action_tutorials/action/Fibonacci", None),
        ("../../etc/passwd", None),
        ("Twist", None),
        ("", None),
        ("a/b/c/d", None),
        ("geometry_msgs/msg/Twist; rm -rf /", None),
    ],
)
def test_only_ros_message_type_names_are_taken(given, expected):
    assert ros_message_type(given) == expected


class _Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def test_the_token_bucket_allows_a_burst_then_its_rate():
    clock = _Clock()
    bucket = RateLimit(rate=5.0, burst=3, clock=clock)
    assert [bucket.allow() for _ in range(5)] == [True, True, True, False, False]
    clock.now += 1.0  # five tokens earned, but the bucket holds three
    assert sum(bucket.allow() for _ in range(10)) == 3
    clock.now += 0.2  # one token
    assert [bucket.allow(), bucket.allow()] == [True, False]


def test_a_note_is_said_once_per_period_and_a_flood_of_notes_is_bounded():
    clock = _Clock()
    throttle = NoteThrottle(every=2.0, remember=3, clock=clock)
    assert throttle.due("a") and not throttle.due("a")
    assert throttle.due("b") and throttle.due("c")
    assert not throttle.due("d")  # three remembered within the period: the rest wait
    clock.now += 2.5
    assert throttle.due("a") and throttle.due("d")

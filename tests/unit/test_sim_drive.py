"""The newest drive in a ground-truth track, and how fast simulated time ran during it."""

from __future__ import annotations

import pytest

from app.lessons.checks._sim_drive import newest_drive
from app.lessons.checks._sim_topics import Pose

HZ = 30.0  # /ground_truth/odom per simulated second


def track(factor: float, seconds: float, speed: float, rest: float = 1.0, x0: float = 0.0):
    """(wall, pose): standing ``rest`` s, driving ``seconds`` s at ``speed``, standing again,
    all in simulated time, on a world running at ``factor`` of real time."""
    out, t, x = [], 0.0, x0
    total = rest + seconds + rest
    while t <= total:
        if rest <= t < rest + seconds:
            x += speed / HZ
        out.append((1000.0 + t / factor, Pose(t, x, 0.0, 0.0)))
        t += 1 / HZ
    return out


@pytest.mark.parametrize("factor", [0.4, 1.0, 2.0])
def test_the_factor_is_simulated_over_wall_time_while_the_robot_moved(factor):
    drive = newest_drive(track(factor, 4.0, 0.2))
    assert drive is not None
    assert drive.factor == pytest.approx(factor, rel=0.02)
    assert drive.end.x - drive.start.x == pytest.approx(0.8, abs=0.01)
    assert drive.share == pytest.approx(min(1.0, factor), rel=0.02)
    assert bool(drive.slower_words()) == (factor < 0.95)
    if factor < 0.95:
        assert f"the world ran at {factor:g}x of real time" in drive.slower_words()


def test_no_motion_or_a_reset_alone_is_no_drive():
    assert newest_drive(track(1.0, 0.0, 0.0)) is None
    # Put back at the start by /reset_world after a drive: a jump, and no drive since.
    driven = track(1.0, 3.0, 0.2)
    wall, last = driven[-1]
    jumped = [*driven, (wall + 0.1, Pose(last.t + 0.1, 0.0, 0.0, 0.0))]
    assert newest_drive(jumped) is None


def test_only_the_newest_drive_counts():
    first = track(1.0, 3.0, 0.2)  # at real time, ending at x = 0.6
    wall, last = first[-1]
    second = [
        (wall + w - 1000.0 + 1 / HZ, Pose(last.t + p.t + 1 / HZ, last.x + p.x, 0.0, 0.0))
        for w, p in track(0.5, 2.0, 0.2)
    ]
    drive = newest_drive([*first, *second])
    assert drive is not None
    assert drive.factor == pytest.approx(0.5, rel=0.02)
    assert drive.start.x == pytest.approx(0.6, abs=0.01)

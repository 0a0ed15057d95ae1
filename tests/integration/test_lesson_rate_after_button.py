"""Lesson 08: after the step's button sets publish_rate_hz, /greeting's rate is judged on
what was sent since then only.

The rate changes in one step ("Change the rate", a set_param button) and is measured
in the next ("Measure the new rate", topic_rate 4-6 Hz). A tap that already listened
at the old 2 Hz (the learner looked at the measuring step first, or came back to it)
held both timers' messages in its window and read a mix (3-4 Hz) for about 5 s. The
runtime notes when the node answered the button's request; topic_rate leaves out
everything before it: every reading after the click is either still measuring or the
new rate, never a mix.
"""

from __future__ import annotations

import re
import threading
import time

import pytest

from app.lessons.runtime import PASS, WAITING, LessonRuntime
from app.ros.graph import snapshot
from tests.conftest import wait_until
from tests.course_data import shared_course

pytestmark = pytest.mark.ros
RATE = re.compile(r"at ([\d.]+) Hz over")


def test_the_rate_after_the_button_is_the_new_one_only(probe, supervisor):
    lesson = next(each for each in shared_course().lessons if each.id == "10_parameters")
    change, measure = lesson.steps[1], lesson.steps[2]
    (button,) = change.actions
    (check,) = measure.checks
    lessons = LessonRuntime(probe.node, supervisor)
    stop = threading.Event()

    def watch_graph() -> None:  # as the dashboard's UI loop does
        while not stop.wait(0.2):
            try:
                lessons.graph = snapshot(probe.node)
            except Exception:  # a graph query raced a leaving node: the next one will do
                continue

    thread = threading.Thread(target=watch_graph, daemon=True)
    thread.start()
    try:
        supervisor.start("parameters_node")
        # The measuring step looked at first: its tap hears the old 2 Hz timer.
        wait_until(
            lambda: 1.8 <= _rate(lessons.evaluate(check).reason) <= 2.2,
            timeout=30,
            interval=0.2,
            what=lambda: f"the old rate: {lessons.evaluate(check).reason}",
        )
        lessons.perform(button)
        clicked = time.monotonic()
        readings = []
        while time.monotonic() - clicked < 8.0:
            result = lessons.evaluate(check)
            readings.append(f"{time.monotonic() - clicked:.1f} s {result.state}: {result.reason}")
            if _rate(result.reason) < 4.0:  # a mix of 2 and 5 Hz, or the old rate
                pytest.fail("\n".join(readings))
            assert result.state in (PASS, WAITING), "\n".join(readings)
            time.sleep(0.2)
        assert result.state == PASS, "\n".join(readings)
        print("\n".join(readings[::5]))
    finally:
        stop.set()
        thread.join()
        lessons.close()


def _rate(reason: str) -> float:
    """The rate a topic_rate reading gives (inf: still measuring)."""
    found = RATE.search(reason)
    return float(found[1]) if found else float("inf")

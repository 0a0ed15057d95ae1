"""See why it failed: a wrong wall_stop solution is graded in the simulated world, its
plot marks the moment it came too close, and "Watch this attempt" plays the run on stage
with the robot where the recorded ground truth put it (read here by the independent
``mcap`` reader, not by our code)."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import pytest
from playwright.sync_api import Page, expect

from tests.bags.readers import mcap_messages
from tests.browser.helpers import click, expect_text, open_page
from tests.browser.replay_helpers import go_to_moments, grade_in_browser, newest_at
from tests.conftest import ARTIFACTS, DashboardProcess, free_port
from tests.course_data import shared_exercises

EXERCISE = shared_exercises().get("wall_stop")
MISTAKE = next(m for m in EXERCISE.mistakes if m.path.stem == "front_is_index_zero")


def _ground_truth(bag: Path) -> list[tuple[float, float, float]]:
    """(seconds since the bag's first message, x, y) of each /ground_truth/odom message."""
    messages = mcap_messages(bag)
    start = min(stamp for _topic, stamp, _msg in messages)
    return [
        ((stamp - start) / 1e9, m.pose.pose.position.x, m.pose.pose.position.y)
        for topic, stamp, m in messages
        if topic == "/ground_truth/odom"
    ]


def _robot(page: Page) -> dict[str, float]:
    robot = page.locator("#replay-robot")
    return {k: float(robot.get_attribute(f"data-{k}") or "nan") for k in ("t", "x", "y")}


@pytest.mark.timeout(400)  # a grading in the simulated world: 150 s on a loaded CI machine
def test_a_failed_simulation_attempt_is_plotted_and_replayed(browser, ros_env, tmp_path):
    bags = tmp_path / "bags"
    env = {**ros_env, "ROS2_CLASSROOM_BAGS": str(bags)}
    dashboard = DashboardProcess(env, free_port(), ["--progress-dir", str(tmp_path / "p")])
    page = browser.new_page(viewport={"width": 1400, "height": 900})
    try:
        open_page(page, dashboard.url)
        grade_in_browser(page, EXERCISE, MISTAKE.path.read_text(encoding="utf-8"))
        verdict = re.compile(r"of the wall ahead at (\d+\.\d) s: closer than the bound")
        expect_text(page, verdict, 150_000)

        # The plot of what was judged is under the results, and the attempt keeps it.
        told = page.get_by_text(re.compile(r"ros2 bag info attempts/")).first
        expect(told).to_be_visible(timeout=20_000)
        name = re.search(r"ros2 bag info (attempts/\S+?-fail)\b", told.inner_text())
        assert name, told.inner_text()
        attempt = bags / name.group(1)
        traces = json.loads((attempt / "traces.json").read_text(encoding="utf-8"))
        assert traces and traces[-1]["broken_why"].startswith("closer than")
        said = page.get_by_text(verdict).filter(visible=True).first.inner_text()
        at = float(verdict.search(said).group(1))
        assert traces[-1]["broken_at"] <= at + 0.05, (traces[-1]["broken_at"], at)
        assert list(attempt.glob("plot-*.png"))
        plot = page.locator("img").filter(visible=True)
        assert plot.count() >= 1

        # Watch it: the run plays on stage, the robot where the file's ground truth says.
        click(page, "Watch this attempt")
        expect_text(page, re.compile(r"\d+ messages in \d+\.\d s\. It plays from the start"))
        truth = _ground_truth(attempt)
        assert len(truth) > 20, len(truth)
        robot = page.locator("#replay-robot")
        expect(robot).to_be_visible(timeout=20_000)
        # It plays from the start; once it ended, go to three moments by the slider's number
        # box, as a learner types a time (a loaded machine plays on too fast for sampling to
        # catch three moments).
        for wanted in go_to_moments(page, [p[0] for p in truth]):
            drawn = _robot(page)
            newest = newest_at(truth, wanted)
            assert abs(drawn["t"] - newest[0]) < 1e-5, (drawn, newest, wanted)
            assert math.dist((drawn["x"], drawn["y"]), newest[1:]) < 0.002, (drawn, newest)
    finally:
        page.screenshot(path=str(ARTIFACTS / "attempt-replay.png"))
        page.close()
        dashboard.stop()

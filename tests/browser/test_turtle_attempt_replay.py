"""Turtlesim attempts play as turtlesim: a wrong turtle_follower (the lookup the wrong way
round) is graded, and "Watch this attempt" plays its recording as turtlesim's window, each
turtle where the recorded ``/<turtle>/pose`` put it at the moment typed in the time box
(read here by the independent ``mcap`` reader, not by our code)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from playwright.sync_api import Page, expect

from tests.bags.readers import mcap_messages
from tests.browser.helpers import click, expect_text, open_page
from tests.browser.replay_helpers import go_to_moments, grade_in_browser, newest_at
from tests.conftest import ARTIFACTS, DashboardProcess, free_port
from tests.course_data import shared_exercises

EXERCISE = shared_exercises().get("turtle_follower")
MISTAKE = next(m for m in EXERCISE.mistakes if m.path.stem == "inverted_lookup")


def _turtle_poses(bag: Path) -> dict[str, list[tuple[float, float, float]]]:
    """(seconds since the bag's first message, x, y) of each turtle's pose messages."""
    messages = mcap_messages(bag)
    start = min(stamp for _topic, stamp, _msg in messages)
    poses: dict[str, list[tuple[float, float, float]]] = {}
    for topic, stamp, msg in messages:
        found = re.fullmatch(r"/(turtle\d+)/pose", topic)
        if found:
            poses.setdefault(found.group(1), []).append(((stamp - start) / 1e9, msg.x, msg.y))
    return poses


def _drawn_turtles(page: Page) -> dict[str, dict[str, float]]:
    return page.evaluate(
        "() => Object.fromEntries([...document.querySelectorAll('.replay-turtle')].map("
        "g => [g.dataset.name, {t: +g.dataset.t, x: +g.dataset.x, y: +g.dataset.y}]))"
    )


@pytest.mark.timeout(400)  # a grading with turtlesim: about a minute on a loaded machine
def test_a_failed_turtlesim_attempt_plays_in_turtlesims_window(browser, ros_env, tmp_path):
    bags = tmp_path / "bags"
    env = {**ros_env, "ROS2_CLASSROOM_BAGS": str(bags)}
    dashboard = DashboardProcess(env, free_port(), ["--progress-dir", str(tmp_path / "p")])
    page = browser.new_page(viewport={"width": 1400, "height": 900})
    try:
        open_page(page, dashboard.url)
        grade_in_browser(page, EXERCISE, MISTAKE.path.read_text(encoding="utf-8"))
        expect_text(page, re.compile(r"needed below 1 m"), 150_000)
        told = page.get_by_text(re.compile(r"ros2 bag info attempts/")).first
        expect(told).to_be_visible(timeout=20_000)
        name = re.search(r"ros2 bag info (attempts/\S+?-fail)\b", told.inner_text())
        assert name, told.inner_text()
        poses = _turtle_poses(bags / name.group(1))
        assert sorted(poses) == ["turtle1", "turtle2"], sorted(poses)

        click(page, "Watch this attempt")
        expect_text(
            page, re.compile(r"messages in \d+\.\d s\. It plays from the start in turtlesim")
        )
        picture = page.locator("svg.stage-replay")
        expect(picture.locator(".replay-turtle").first).to_be_visible(timeout=20_000)
        # turtlesim's blue ground, 11.09 m at the window's 45 px a metre.
        assert picture.locator("rect[fill='#4556ff']").count() == 1
        for wanted in go_to_moments(page, [p[0] for p in poses["turtle2"]]):
            drawn = _drawn_turtles(page)
            for turtle, samples in poses.items():
                newest = newest_at(samples, wanted)
                assert abs(drawn[turtle]["t"] - newest[0]) < 1e-5, (turtle, drawn, newest)
                assert abs(drawn[turtle]["x"] - newest[1]) < 0.002, (turtle, drawn, newest)
                assert abs(drawn[turtle]["y"] - newest[2]) < 0.002, (turtle, drawn, newest)
        picture.screenshot(path=str(ARTIFACTS / "turtle-attempt-replay-window.png"))
    finally:
        page.screenshot(path=str(ARTIFACTS / "turtle-attempt-replay.png"))
        page.close()
        dashboard.stop()

"""A learner completes lessons by clicking only; progress survives reloads and restarts."""

from __future__ import annotations

import json

import pytest
from playwright.sync_api import expect

from app.lessons.panel import action_button_label
from tests.browser.helpers import (
    answer_quiz,
    click,
    click_next,
    expect_text,
    open_folder,
    open_lesson,
    open_page,
    open_tab,
)
from tests.conftest import DashboardProcess, free_port
from tests.course_data import shared_course

pytestmark = [pytest.mark.browser, pytest.mark.ros]
COURSE = shared_course()


def complete_by_clicking(page, lesson, done_within_ms: int = 45_000) -> None:
    open_tab(page, "Lessons")
    open_lesson(page, lesson)
    for index, step in enumerate(lesson.steps):
        expect_text(page, f"Step {index + 1} of {len(lesson.steps)}: {step.title}")
        for action in step.actions:
            click(page, action_button_label(action))
            page.wait_for_timeout(300)  # a learner reads the result before the next click
        for check in step.checks:
            if check.kind == "quiz":
                answer_quiz(page, check)
        try:
            expect(page.get_by_text("✓ step done")).to_be_visible(timeout=done_within_ms)
        except AssertionError as error:
            # the lesson panel's own lines say what the step still waits for
            raise AssertionError(
                f"step {index + 1} ({step.title}) not done within {done_within_ms} ms; "
                f"the lesson panel says: {_checks_text(page)}"
            ) from error
        if index + 1 < len(lesson.steps):
            click_next(page)


def _checks_text(page) -> str:
    """The lesson panel's Checks block as the learner reads it (what is left, and why)."""
    body = page.inner_text("body", timeout=10_000)
    start = body.find("Checks")
    return " / ".join(body[start : start + 400].splitlines()) if start >= 0 else "(no Checks)"


def done_cells(page):
    """The outline's done marks (the outline folder starts collapsed)."""
    open_tab(page, "Lessons")
    open_folder(page, "Course outline")
    return page.get_by_role("cell", name="✓", exact=True)


@pytest.mark.parametrize("lesson_id", ["04_first_node", "05_topics"])
def test_complete_a_lesson_and_keep_progress(page, dashboard, ros_env, progress_dir, lesson_id):
    lesson = COURSE.lesson(lesson_id)
    complete_by_clicking(page, lesson)
    expect(done_cells(page)).to_have_count(1, timeout=10_000)

    saved = json.loads((progress_dir / "default.json").read_text())
    assert sorted(saved["lessons"][lesson_id]["passed"]) == list(range(len(lesson.steps)))

    page.reload()
    open_tab(page, "Lessons")
    expect(done_cells(page)).to_have_count(1, timeout=15_000)

    dashboard.stop()
    restarted = DashboardProcess(ros_env, free_port(), ["--progress-dir", str(progress_dir)])
    try:
        open_page(page, restarted.url)
        open_tab(page, "Lessons")
        expect(done_cells(page)).to_have_count(1, timeout=15_000)
        expect_text(page, lesson.title)
    finally:
        restarted.stop()


def test_complete_the_lifecycle_lesson_by_clicking_transitions(page):
    complete_by_clicking(page, COURSE.lesson("11_lifecycle"))


def test_complete_the_bags_lesson_whose_buttons_type_into_the_console(page):
    """Record, replay with no talker, replay looping at double rate: the Console runs them."""
    complete_by_clicking(page, COURSE.lesson("21_bags"))
    open_tab(page, "Console")  # shows the last command, still looping
    expect_text(page, "$ ros2 bag play talker_bag -r 2 -l")


# 18 steps with three colcon builds (one of them CMake + rosidl + a compiler): ~70 s on two
# idle cores, ~230 s when the cores are shared with another test run.
@pytest.mark.timeout(480)
def test_complete_the_workspace_lesson_building_and_running_the_learners_own_package(page):
    """Unit 15 by clicking: pkg create, files written, colcon build, source, ros2 run,
    'No executable found', the fix, a launch file, an interface package; real colcon."""
    # An interface package's build (CMake, rosidl, a compiler) takes 10-60 s on 2 busy cores.
    complete_by_clicking(page, COURSE.lesson("20_workspaces_packages"), done_within_ms=180_000)
    open_tab(page, "Console")
    expect_text(page, "$ ros2 run py_pubsub num_talker")

"""An exercise as a learner does it: type, Run, Check, fix, pass; the code survives
a reload and a SIGKILL of the dashboard."""

from __future__ import annotations

import re
import signal

from playwright.sync_api import Page, expect

from app.exercises.model import load_exercises
from tests.browser.helpers import choose, click, expect_text, open_tab
from tests.conftest import DashboardProcess, free_port

EXERCISE = load_exercises().get("multiply_service")
WRONG = (EXERCISE.path / "mistakes" / "adds.py").read_text(encoding="utf-8")


def _open_editor(page: Page):
    open_tab(page, "Exercise")
    choose(page, "Exercise", f"{EXERCISE.unit:02d} · {EXERCISE.title}")
    choose(page, "On stage", "Code")  # lesson 1 has the graph on stage
    page.get_by_role("tab", name="Your code").click()
    frame_locator = page.frame_locator(f"iframe[src*='slug={EXERCISE.slug}']")
    return frame_locator, _frame(page)


def _frame(page: Page):
    """The editor's frame once it shows this exercise's saved code."""
    locator = page.frame_locator(f"iframe[src*='slug={EXERCISE.slug}']")
    expect(locator.locator("#status")).to_have_text(re.compile("saved|connected"))
    frame = page.frame(url=re.compile(rf"editor\.html\?slug={EXERCISE.slug}"))
    assert frame is not None
    return frame


def _type_code(page: Page, frame_locator, code: str) -> None:
    """Select everything in the editor and paste ``code``, as a learner would."""
    frame_locator.locator(".ace_content").click()
    page.keyboard.press("Control+A")
    page.keyboard.insert_text(code)
    expect(frame_locator.locator("#status")).to_have_text("saved ✓", timeout=10_000)


def _editor_text(frame) -> str:
    return frame.evaluate("window.classroomEditor.getValue()")


def test_wrong_then_right_then_survives_reload_and_sigkill(page, dashboard, ros_env, progress_dir):
    frame_locator, frame = _open_editor(page)
    assert "TODO" in _editor_text(frame)  # the starter code is there first

    _type_code(page, frame_locator, WRONG)
    click(page, "Run my node")
    expect_text(page, re.compile(r"running \(pid \d+\) · on the graph"))
    click(page, "Check my node")
    expect_text(page, re.compile(r"/multiply answered sum=-?\d+ for a=-?\d+, b=-?\d+; expected"))
    expect_text(page, "1 of 2 checks passed")

    _type_code(page, frame_locator, EXERCISE.reference)
    click(page, "Run my node")
    expect_text(page, re.compile(r"running \(pid \d+\) · on the graph"))
    click(page, "Check my node")
    expect_text(page, "All checks pass. Exercise done!")
    expect_text(page, "✓ done")

    page.reload()
    open_tab(page, "Exercise")
    choose(page, "Exercise", f"{EXERCISE.unit:02d} · {EXERCISE.title}  ✓")
    page.get_by_role("tab", name="Your code").click()
    frame = _frame(page)
    assert _editor_text(frame) == EXERCISE.reference

    dashboard.proc.send_signal(signal.SIGKILL)
    dashboard.proc.wait(10)
    again = DashboardProcess(ros_env, free_port(), ["--progress-dir", str(progress_dir)])
    try:
        page.goto(again.url)
        open_tab(page, "Exercise")
        choose(page, "Exercise", f"{EXERCISE.unit:02d} · {EXERCISE.title}  ✓")
        choose(page, "On stage", "Code")  # a new dashboard: lesson 1's stage again
        page.get_by_role("tab", name="Your code").click()
        frame = _frame(page)
        assert _editor_text(frame) == EXERCISE.reference
        expect_text(page, "✓ done")  # the pass was saved with the progress too
    finally:
        again.stop()

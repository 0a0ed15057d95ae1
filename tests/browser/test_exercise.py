"""An exercise as a learner does it: type, Run, Check, fix, pass; the code survives
a reload and a SIGKILL of the dashboard."""

from __future__ import annotations

import re
import signal

from playwright.sync_api import Page, expect

from tests.browser.helpers import (
    choose,
    click,
    expect_editor_loaded,
    expect_text,
    open_page,
    open_tab,
)
from tests.browser.test_ros2_panels import expect_regex, field
from tests.conftest import DashboardProcess, free_port
from tests.course_data import shared_exercises

EXERCISE = shared_exercises().get("multiply_service")
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
    expect_editor_loaded(locator)
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
    # The attempt was recorded, and the Console's `ros2 bag info` reads it as shown.
    told = page.get_by_text(re.compile(r"This attempt was recorded")).first
    expect(told).to_be_visible(timeout=20_000)
    found = re.search(r"ros2 bag info (attempts/\S+?-fail)\b", told.inner_text())
    assert found, told.inner_text()
    open_tab(page, "Console")
    field(page, "Command").fill(f"ros2 bag info {found.group(1)}")
    click(page, "Run")
    expect_regex(page, r"Topic: /rosout \| Type: rcl_interfaces/msg/Log \| Count: [1-9]", 30_000)
    open_tab(page, "Exercise")

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
        open_page(page, again.url)
        open_tab(page, "Exercise")
        choose(page, "Exercise", f"{EXERCISE.unit:02d} · {EXERCISE.title}  ✓")
        choose(page, "On stage", "Code")  # a new dashboard: lesson 1's stage again
        page.get_by_role("tab", name="Your code").click()
        frame = _frame(page)
        assert _editor_text(frame) == EXERCISE.reference
        expect_text(page, "✓ done")  # the pass was saved with the progress too
    finally:
        again.stop()


def _open_from_tree(editor, path: str) -> None:
    """Files, unfold each folder on the way, click the file (as a learner does)."""
    files = editor.get_by_role("button", name="Files")
    if files.get_attribute("aria-expanded") != "true":
        files.click()
    parts = path.split("/")
    for i, part in enumerate(parts[:-1]):
        same_name_before = parts[:i].count(part)
        item = editor.locator(f"[role=treeitem][aria-label='{part}/']").nth(same_name_before)
        if item.get_attribute("aria-expanded") != "true":
            item.locator(":scope > span").click()
    editor.locator(f"[role=treeitem][aria-label='{parts[-1]}']").locator(":scope > span").click()


NODE = """import rclpy


def main():
    rclpy.init()
    node = rclpy.create_node('my_node')
    node.destroy_node()
"""


def test_workspace_files_in_the_editor_complete_lint_and_format(page, progress_dir):
    """Two files of ~/ros2_ws in tabs; completion with rclpy's signature; a lint mark while
    typing (no Run); Format rewrites and saves the file."""
    from app.exercises.code_assist import format_code

    package = progress_dir / "default.ros2_ws" / "src" / "my_package"
    (package / "my_package").mkdir(parents=True)
    (package / "my_package" / "__init__.py").write_text("")
    node = package / "my_package" / "my_node.py"
    node.write_text(NODE)
    (package / "setup.py").write_text("from setuptools import setup\n\nsetup(name='my_package')\n")
    open_tab(page, "Exercise")
    choose(page, "On stage", "Code")
    page.get_by_role("tab", name="Your code").click()
    editor = page.frame_locator("iframe[src*='editor.html']")
    expect_editor_loaded(editor)
    for path in ("src/my_package/my_package/my_node.py", "src/my_package/setup.py"):
        _open_from_tree(editor, path)
    expect(editor.get_by_role("tab", name="setup.py")).to_have_attribute("aria-selected", "true")
    editor.get_by_role("tab", name="my_node.py").click()
    frame = page.frame(url=re.compile(r"editor\.html"))
    assert frame is not None
    assert frame.evaluate("window.classroomEditor.getValue()") == NODE

    frame.evaluate("window.classroomEditor.gotoLine(6, 1000, false)")
    page.keyboard.press("Enter")
    page.keyboard.type("node.create_pub", delay=40)
    popup = editor.locator(".ace_autocomplete")
    expect(popup).to_contain_text("create_publisher", timeout=30_000)
    expect(editor.locator(".ace_doc-tooltip")).to_contain_text(
        "create_publisher(msg_type, topic: str, qos_profile", timeout=30_000
    )
    page.keyboard.press("Enter")  # take it
    page.keyboard.type("(")
    expect(editor.locator("#signature")).to_contain_text("msg_type", timeout=30_000)
    page.keyboard.type("String, 'chatter',   10")
    page.keyboard.press("Escape")
    # String was never imported: a mark appears in the gutter as soon as it is saved.
    warning = editor.locator(".ace_gutter-cell.ace_warning")
    expect(warning).to_have_count(1, timeout=15_000)
    marks = frame.evaluate("window.classroomEditor.session.getAnnotations()")
    assert [m["text"] for m in marks] == ["undefined name 'String'"]
    expect(editor.locator("#status")).to_have_text("saved ✓")
    typed = node.read_text()
    assert "node.create_publisher(String, 'chatter',   10)" in typed

    editor.get_by_role("button", name="Format").click()
    expect(editor.locator("#status")).to_have_text("formatted and saved ✓")
    assert node.read_text() == format_code(typed, "my_node.py") != typed
    assert 'node.create_publisher(String, "chatter", 10)' in node.read_text()
    assert frame.evaluate("window.classroomEditor.getValue()") == node.read_text()
    # The other file kept its own text, and the exercise its own tab.
    editor.get_by_role("tab", name="setup.py").click()
    assert "setup(name='my_package')" in frame.evaluate("window.classroomEditor.getValue()")
    expect(editor.get_by_role("tab", name=re.compile(r"\.py$"))).to_have_count(3)

"""The README's pictures, taken from the real product in headless Chromium.

Starts a dashboard with a throw-away progress folder, works through the
product as a learner would and saves PNGs into docs/images/. Run with
``make screenshots`` (it needs DDS, so it runs in the tests' private network
namespace).
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from playwright.sync_api import Browser, Locator, Page, expect, sync_playwright  # noqa: E402

from app.dds import configure_dds_env  # noqa: E402
from app.exercises.model import load_exercises  # noqa: E402
from app.lessons.panel import NEXT_LABEL, answer_button_label  # noqa: E402
from app.lessons.schema import load_course  # noqa: E402
from app.ui import GROUP_OF  # noqa: E402

IMAGES = ROOT / "docs" / "images"
LAPTOP = {"width": 1366, "height": 768}  # a school laptop: each stage is shown at this size
DESK = {"width": 1500, "height": 900}
PORT = 8193
CLASS_PORT = 8311  # the teacher page one below
NEXT = NEXT_LABEL  # "Skip (N checks not passed)" until the step's checks pass


def _wait_ready(log: Path, proc: subprocess.Popen, ready: str) -> None:
    deadline = time.monotonic() + 90
    while ready not in log.read_text(errors="replace"):
        if proc.poll() is not None or time.monotonic() > deadline:
            raise SystemExit(f"the dashboard did not start:\n{log.read_text(errors='replace')}")
        time.sleep(0.2)


def _choose(page: Page, label: str, option: str) -> None:
    page.get_by_label(label).click()
    page.get_by_role("option", name=option, exact=True).click()


def _shown(page: Page, text: str | re.Pattern[str]) -> Locator:
    """``text`` where it is on screen (other tabs keep hidden copies)."""
    return page.get_by_text(text).filter(visible=True).first


def _dismiss_toasts(page: Page) -> None:
    """viser warns about software WebGL (no GPU here); close it so it hides nothing."""
    page.wait_for_timeout(1500)
    for button in page.locator(".mantine-Notification-closeButton").all():
        button.click()


def _tool(page: Page, name: str) -> None:
    """Open a tool as a learner does: its group's tab (Learn, Run, ...), then its own."""
    page.get_by_role("tab", name=GROUP_OF[name], exact=True).click()
    page.get_by_role("tab", name=name, exact=True).click()


def _lesson(page: Page, unit: int | str, step: int) -> None:
    """Open lesson ``unit`` (a number or a lesson id) at step ``step`` (1-based) with Next."""
    lesson = next(lesson for lesson in load_course().lessons if unit in (lesson.unit, lesson.id))
    _tool(page, "Lessons")
    _choose(page, "Lesson", f"{lesson.unit:02d} · {lesson.title}")
    heading = page.get_by_text(re.compile(r"^Step \d+ of \d+")).filter(visible=True).first
    titles = "|".join(re.escape(s.title) for s in lesson.steps)  # this lesson's, not the last's
    expect(heading).to_have_text(re.compile(rf"^Step \d+ of {len(lesson.steps)}: ({titles})"))
    for _ in range(len(lesson.steps)):  # the lesson opens where the learner left it
        match = re.match(r"Step (\d+)", heading.inner_text())
        at = int(match.group(1)) if match else step
        if at == step:
            break
        page.get_by_role("button", name=NEXT if at < step else "Back", exact=True).click()
        expect(heading).not_to_have_text(re.compile(rf"^Step {at} of"))
    expect(heading).to_have_text(re.compile(rf"^Step {step} of {len(lesson.steps)}"))


def topics_lesson(page: Page) -> None:
    """The opening picture: mid-way through the topics unit, its checks ticking green."""
    for step, label in ((1, "Start talker"), (3, "Start listener"), (4, "Start listener2")):
        _lesson(page, "05_topics", step)
        page.get_by_role("button", name=label, exact=True).click()
    expect(page.get_by_text("✓ step done").first).to_be_visible(timeout=60_000)
    page.wait_for_timeout(800)
    page.screenshot(path=str(IMAGES / "lesson.png"))


def _stage_shot(page: Page, name: str, settle_ms: int = 2500) -> None:
    """The screen at 1366x768, as a school laptop shows it: ``stage-<name>.png``."""
    page.set_viewport_size(LAPTOP)
    page.wait_for_timeout(settle_ms)
    page.screenshot(path=str(IMAGES / f"stage-{name}.png"))
    page.set_viewport_size(DESK)


def stage_graph(page: Page) -> None:
    """The same lesson at 1366x768 with a service server too: a call travels as a pulse."""
    _start(page, "add_two_ints_server")
    _tool(page, "Services")
    expect(_shown(page, "Type: tutorial_interfaces/srv/AddTwoInts")).to_be_visible(timeout=30_000)
    page.set_viewport_size(LAPTOP)
    expect(page.locator('svg.stage-graph g[data-name="/listener2"]')).to_be_visible()
    page.wait_for_timeout(2500)  # rates settle, dots on their way
    page.get_by_role("button", name="Call", exact=True).click()
    page.wait_for_function(  # a pulse (the request, then the response) on its way
        "() => [...document.querySelectorAll('svg.stage-graph g.sg-pulse')]"
        ".some((g) => getComputedStyle(g).visibility === 'visible')",
        polling=30,
        timeout=10_000,
    )
    page.screenshot(path=str(IMAGES / "stage-graph.png"))
    page.set_viewport_size(DESK)


def stage_turtlesim(page: Page) -> None:
    """The turtlesim lesson: turtlesim's window on stage, the trail it drew, the step beside."""
    _lesson(page, "02_turtlesim_cli", 3)
    _stage_shot(page, "turtlesim")


def stage_tf(page: Page) -> None:
    """The tf2 lesson's view_frames step: the live TF tree of the turtle demo on stage."""
    _tool(page, "Nodes")
    _choose(page, "Launch group", "turtle_tf2_demo")
    page.get_by_role("button", name="Start group", exact=True).click()
    _lesson(page, "16_tf2_turtlesim", 4)
    expect(page.locator("div.stage-tf").get_by_text("turtle2").first).to_be_visible(timeout=60_000)
    _stage_shot(page, "tf", settle_ms=4000)  # rates and buffer lengths settle
    _tool(page, "Nodes")  # a clean world for the pictures that follow
    page.get_by_role("button", name="Stop group", exact=True).click()


def live_graph(page: Page) -> None:
    """The talker and both listeners as the Graph tab draws them (the nodes keep running)."""
    _tool(page, "Graph")
    expect(_shown(page, "/listener2")).to_be_visible(timeout=30_000)
    page.wait_for_timeout(2500)  # a few graph refreshes: rates settle
    page.screenshot(path=str(IMAGES / "graph.png"))


def lifecycle_drawing(page: Page) -> None:
    """A managed node configured by clicking the drawing's edge."""
    _start(page, "lifecycle_talker")
    _tool(page, "Lifecycle")
    edge = page.locator('g.live-edge a[aria-label^="configure:"]')
    edge.locator("text").click(timeout=30_000)
    expect(page.get_by_text("Transitioning successful").first).to_be_visible(timeout=30_000)
    page.wait_for_timeout(2500)
    page.screenshot(path=str(IMAGES / "lifecycle.png"))


def arm_scene(page: Page) -> None:
    """camera -> coordinate transform -> arm: the 3D view follows the arm by itself."""
    _tool(page, "Nodes")
    _choose(page, "Launch group", "camera_to_arm")
    page.get_by_role("button", name="Start group", exact=True).click()
    _tool(page, "3D view")
    expect(page.get_by_text("gripper at").first).to_be_visible(timeout=60_000)
    _choose(page, "On stage", "3D scene")  # the stage steps aside: the scene gets the room
    page.wait_for_timeout(500)
    page.mouse.move(1000, 480)
    for _ in range(4):  # zoom in towards the arm, as a scroll wheel does
        page.mouse.wheel(0, -240)
        page.wait_for_timeout(150)
    page.wait_for_timeout(4000)  # the arm on its way to the target
    page.screenshot(path=str(IMAGES / "scene.png"))
    _lesson(page, "15_frames_and_arm", 4)  # a unit whose stage is the 3D scene
    _stage_shot(page, "scene", settle_ms=4000)


def turtlesim_drive(page: Page) -> None:
    """Turtlesim in its tab: started and driven with the arrow keys, a turn left in the trail."""
    _tool(page, "Turtlesim")
    page.get_by_role("button", name="Start turtlesim_node", exact=True).click()
    expect(_shown(page, "turtles: turtle1")).to_be_visible(timeout=30_000)
    page.get_by_role("button", name="Start turtle_teleop_key", exact=True).click()
    expect(_shown(page, "is running")).to_be_visible(timeout=30_000)
    page.get_by_text("TurtleSim", exact=True).click()  # the page, not a field, has the focus
    for key in ["ArrowUp"] * 3 + ["ArrowLeft"] * 4 + ["ArrowUp"] * 3:
        page.keyboard.press(key)
        page.wait_for_timeout(250)
    page.wait_for_timeout(2500)  # turtlesim stops the turtle 1 s after the last key
    page.screenshot(path=str(IMAGES / "turtlesim.png"))
    stage_turtlesim(page)


def _console(page: Page, command: str, shown: str) -> None:
    _tool(page, "Console")
    field = page.get_by_text("Command", exact=True).locator("visible=true").first
    field.locator("xpath=ancestor::div[contains(@class,'mantine-Flex-root')][1]//input").fill(
        command
    )
    page.get_by_role("button", name="Run", exact=True).click()
    expect(_shown(page, shown)).to_be_visible(timeout=60_000)


def tf_panel(page: Page) -> None:
    """The TF tab: a static and a dynamic broadcaster typed in the Console, and tf2_echo."""
    _console(
        page,
        "ros2 run tf2_ros static_transform_publisher --x 1 --y 2 --yaw 1.5707963 "
        "--frame-id world --child-frame-id turtle1",
        "[exit code 0]",
    )
    _console(page, "ros2 run turtle_tf2_py fixed_frame_tf2_broadcaster", "[exit code 0]")
    _choose(page, "On stage", "3D scene")
    _tool(page, "TF")
    # world, turtle1, carrot1 (and any frame an earlier picture's nodes left, marked stale)
    expect(_shown(page, re.compile(r"^\d+ frames in 1 tree"))).to_be_visible(timeout=60_000)
    expect(_shown(page, "- Translation: [-1.000, 2.000")).to_be_visible(timeout=30_000)
    page.wait_for_timeout(1500)
    page.screenshot(path=str(IMAGES / "tf_panel.png"))
    _console(page, "ros2 run --stop /fixed_frame_tf2_broadcaster", "stopped")
    _console(page, "ros2 run --stop /static_transform_publisher", "stopped")


def _start(page: Page, node: str) -> None:
    _tool(page, "Nodes")
    _choose(page, "Catalog node", node)
    page.get_by_role("button", name="Start", exact=True).click()
    expect(page.get_by_text(f"Started {node}").first).to_be_visible(timeout=30_000)


def exercise_graded(page: Page) -> None:
    """An exercise mid-way: a plausible mistake, Run, Check, and the reason shown."""
    exercise = load_exercises().get("multiply_service")
    wrong = (exercise.path / "mistakes" / "adds.py").read_text(encoding="utf-8")
    _tool(page, "Exercise")
    _choose(page, "Exercise", f"{exercise.unit:02d} · {exercise.title}")
    _choose(page, "On stage", "Code")
    page.get_by_role("tab", name="Your code").click()
    editor = page.frame_locator(f"iframe[src*='slug={exercise.slug}']")
    editor.locator(".ace_content").click()
    page.keyboard.press("Control+A")
    page.keyboard.insert_text(wrong)
    expect(editor.locator("#status")).to_have_text("saved ✓", timeout=10_000)
    editor.locator(".ace_content").click()
    page.keyboard.press("Control+Home")
    page.get_by_role("button", name="Run my node").click()
    expect(_shown(page, "on the graph ✓")).to_be_visible(timeout=30_000)
    page.get_by_role("button", name="Check my node").click()
    expect(_shown(page, "checks passed")).to_be_visible(timeout=60_000)
    page.get_by_text("Output of your node").click()  # fold the task away: results in view
    page.get_by_text("Task", exact=True).click()
    page.wait_for_timeout(800)
    page.screenshot(path=str(IMAGES / "exercise.png"))
    _stage_shot(page, "code", settle_ms=1500)


@contextmanager
def _running(argv: list[str], env: dict[str, str], log: Path, ready: str) -> Iterator[None]:
    """``python -m app <argv>`` until the block ends; it is ready once ``ready`` is logged."""
    with open(log, "wb") as out:
        proc = subprocess.Popen(
            [sys.executable, "-m", "app", *argv],
            cwd=ROOT, env=env, stdout=out, stderr=subprocess.STDOUT,
        )  # fmt: skip
        try:
            _wait_ready(log, proc, ready)
            yield
        finally:
            proc.terminate()
            proc.wait(30)


def _open(browser: Browser, url: str, width: int = 1500) -> Page:
    page = browser.new_page(viewport={**DESK, "width": width})
    page.goto(url)
    page.get_by_role("tab").first.wait_for()
    _dismiss_toasts(page)
    return page


def _on_failure_keep(page: Page, tmp: str) -> None:
    page.screenshot(path=str(Path(tmp) / "failed.png"))
    shutil.copy(Path(tmp) / "failed.png", ROOT / "test-artifacts")


def walked_gallery(browser: Browser, env: dict[str, str], tmp: str) -> None:
    """The lessons' gallery, on a dashboard of its own (a fresh learner), 1366x768."""
    argv = ["serve", "--port", str(PORT + 1), "--progress-dir", str(Path(tmp) / "walk")]
    with _running(argv, env, Path(tmp) / "walk.log", "is ready"):
        page = browser.new_page(viewport=LAPTOP)
        page.goto(f"http://127.0.0.1:{PORT + 1}/")
        page.get_by_role("tab").first.wait_for()
        _dismiss_toasts(page)
        try:
            undone = lesson_gallery(page)
        except Exception:
            _on_failure_keep(page, tmp)
            raise
        page.close()
    print(f"{len(undone)} steps left undone by a learner who only clicks:", *undone, sep="\n  ")


def learner_dashboard(browser: Browser, env: dict[str, str], tmp: str) -> None:
    argv = ["serve", "--port", str(PORT), "--progress-dir", str(Path(tmp) / "progress")]
    with _running(argv, env, Path(tmp) / "dashboard.log", "is ready"):
        page = _open(browser, f"http://127.0.0.1:{PORT}/")
        try:
            takes = (topics_lesson, stage_graph, live_graph, lifecycle_drawing, turtlesim_drive)
            takes += (stage_tf, exercise_graded, tf_panel)
            for take in (*takes, arm_scene):  # the scene folds the code away
                take(page)
        except Exception:
            _on_failure_keep(page, tmp)
            raise
        page.close()


GALLERY = IMAGES / "lessons"
STEP_DONE_MS = 20_000  # a step that needs typing (the learner's own code) is left undone


def _walk_step(page: Page, step) -> bool:
    """Do a step as a learner who only clicks: its buttons, then the right answers; True
    when its checks passed within STEP_DONE_MS."""
    for action in step.actions:
        if action.kind == "open_panel":
            continue  # the tools stay as they are: the pictures show the card and the stage
        label = action.get("label") or action.kind.replace("_", " ")
        button = page.get_by_role("button", name=label, exact=True)
        if button.is_enabled(timeout=10_000):  # a Stop with nothing to stop is greyed
            button.click()
            page.wait_for_timeout(400)
    for check in step.checks:
        if check.kind == "quiz":
            answer = answer_button_label(check["answer"], chosen=False)
            page.get_by_role("button", name=answer, exact=True).click()
    try:
        expect(_shown(page, "✓ step done")).to_be_visible(timeout=STEP_DONE_MS)
        return True
    except AssertionError:
        return False


# The column scrolled back to its top: the picture shows the lesson's and the step's head
# as a learner opening the step sees them (doing the step scrolled down to its checks).
_COLUMN_TO_TOP = """() => {
  const title = [...document.querySelectorAll('*')].find((e) => e.children.length === 0
    && /^Lesson \\d+ of \\d+/.test(e.textContent.trim()) && e.getBoundingClientRect().width);
  for (let box = title && title.parentElement; box; box = box.parentElement)
    if (/(auto|scroll)/.test(getComputedStyle(box).overflowY)) box.scrollTop = 0;
}"""


def _shoot_step(page: Page, path: Path) -> None:
    page.evaluate(_COLUMN_TO_TOP)
    page.wait_for_timeout(300)
    page.screenshot(path=str(path), quality=70)


def lesson_gallery(page: Page) -> list[str]:
    """Every lesson from its first step to its last, in order and without reloading, as a
    learner who clicks the buttons walks it: a picture of each lesson's first and last step
    (docs/images/lessons/, the README's gallery). Returns the steps left undone."""
    GALLERY.mkdir(parents=True, exist_ok=True)
    undone: list[str] = []
    for lesson in load_course().lessons:
        _lesson(page, lesson.id, 1)
        for index, step in enumerate(lesson.steps):
            last = index + 1 == len(lesson.steps)
            if last and len(lesson.steps) > 1:  # what was built, before its stops are pressed
                page.wait_for_timeout(1500)
                _shoot_step(page, GALLERY / f"{lesson.unit:02d}-last.jpg")
            if not _walk_step(page, step):
                undone.append(f"{lesson.id} step {index + 1}: {step.title}")
            if index == 0:
                page.wait_for_timeout(1500)  # the stage settles (a node joins the graph)
                _shoot_step(page, GALLERY / f"{lesson.unit:02d}-first.jpg")
            if not last:
                page.get_by_role("button", name=NEXT).click()
        print(f"{lesson.id}: walked", flush=True)
    return undone


def gallery_markdown() -> str:
    """The README's gallery: a row per lesson, its first and last step."""
    rows = ["| Lesson | First step | Last step |", "|---|---|---|"]
    for lesson in load_course().lessons:
        pictures = [
            f"![{lesson.title}, {which} step](docs/images/lessons/{lesson.unit:02d}-{which}.jpg)"
            for which in ("first", "last")
        ]
        rows.append(f"| {lesson.unit} · {lesson.title} | {pictures[0]} | {pictures[1]} |")
    return "\n".join(rows)


def teacher_page(browser: Browser, env: dict[str, str], tmp: str) -> None:
    """A class of three: one mid-lesson with a node running, one stuck on a quiz, one idle."""
    token = "screenshots-teacher-token"
    argv = [
        "classroom", "--learners", "3", "--base-port", str(CLASS_PORT), "--base-domain-id", "60",
        "--classroom-domain-id", "94", "--teacher-port", str(CLASS_PORT - 1),
        "--teacher-token", token, "--progress-dir", str(Path(tmp) / "class"),
    ]  # fmt: skip
    with _running(argv, env, Path(tmp) / "classroom.log", "Teacher page"):
        first = _open(browser, f"http://127.0.0.1:{CLASS_PORT}/")
        _start(first, "talker")
        _lesson(first, 1, 3)
        second = _open(browser, f"http://127.0.0.1:{CLASS_PORT + 1}/")
        _lesson(second, 1, 2)
        teacher = _open(browser, f"http://localhost:{CLASS_PORT - 1}/?token={token}", 1700)
        try:
            expect(_shown(teacher, "3 learners")).to_be_visible(timeout=30_000)
            expect(_shown(teacher, "talker")).to_be_visible(timeout=30_000)
            teacher.wait_for_timeout(1500)
            teacher.screenshot(path=str(IMAGES / "teacher.png"))
        except Exception:
            _on_failure_keep(teacher, tmp)
            raise


def gradebook_pictures(browser: Browser, env: dict[str, str], tmp: str) -> None:
    """The LTI gradebook (docs/gradebook_screenshot.py: it needs no DDS)."""
    from docs.gradebook_screenshot import gradebook

    gradebook(browser, IMAGES, tmp)


def main() -> int:
    IMAGES.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    configure_dds_env(env, domain_id=93, network=False)
    with tempfile.TemporaryDirectory() as tmp, sync_playwright() as playwright:
        browser = playwright.chromium.launch(
            executable_path="/usr/bin/chromium", args=["--no-sandbox", "--disable-dev-shm-usage"]
        )
        only = sys.argv[1:]  # e.g. "gallery": one part; none: every picture
        parts = {
            "dashboard": learner_dashboard,
            "teacher": teacher_page,
            "gradebook": gradebook_pictures,
            "gallery": walked_gallery,
        }
        for name, take in parts.items():
            if not only or name in only:
                take(browser, env, tmp)
        browser.close()
    for image in sorted(IMAGES.glob("*.png")):
        print(f"wrote {image.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

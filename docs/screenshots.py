"""The README's pictures, taken from the real product in headless Chromium.

Starts a dashboard with a throw-away progress folder, works through the
product as a learner would and saves PNGs into docs/images/. Run with
``make screenshots`` (it needs DDS, so it runs in the tests' private network
namespace).
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from playwright.sync_api import Page, expect, sync_playwright  # noqa: E402

from app.dds import configure_dds_env  # noqa: E402
from app.exercises.model import load_exercises  # noqa: E402

IMAGES = ROOT / "docs" / "images"
PORT = 8193


def _wait_ready(log: Path, proc: subprocess.Popen) -> None:
    deadline = time.monotonic() + 60
    while "is ready" not in log.read_text(errors="replace"):
        if proc.poll() is not None or time.monotonic() > deadline:
            raise SystemExit(f"the dashboard did not start:\n{log.read_text(errors='replace')}")
        time.sleep(0.2)


def _choose(page: Page, label: str, option: str) -> None:
    page.get_by_label(label).click()
    page.get_by_role("option", name=option, exact=True).click()


def _dismiss_toasts(page: Page) -> None:
    """viser warns about software WebGL (no GPU here); close it so it hides nothing."""
    page.wait_for_timeout(1500)
    for button in page.locator(".mantine-Notification-closeButton").all():
        button.click()


def exercise_graded(page: Page) -> None:
    """An exercise mid-way: a plausible mistake, Run, Check, and the reason shown."""
    exercise = load_exercises().get("multiply_service")
    wrong = (exercise.path / "mistakes" / "adds.py").read_text(encoding="utf-8")
    page.get_by_role("tab", name="Exercise").click()
    _choose(page, "Exercise", f"{exercise.unit:02d} · {exercise.title}")
    page.get_by_role("tab", name="Your code").click()
    editor = page.frame_locator(f"iframe[src*='slug={exercise.slug}']")
    editor.locator(".ace_content").click()
    page.keyboard.press("Control+A")
    page.keyboard.insert_text(wrong)
    expect(editor.locator("#status")).to_have_text("saved ✓", timeout=10_000)
    editor.locator(".ace_content").click()
    page.keyboard.press("Control+Home")
    page.get_by_role("button", name="Run my node").click()
    expect(page.get_by_text("on the graph ✓").first).to_be_visible(timeout=30_000)
    page.get_by_role("button", name="Check my node").click()
    expect(page.get_by_text("checks passed").first).to_be_visible(timeout=60_000)
    page.get_by_text("Output of your node").click()  # fold the task away: results in view
    page.get_by_text("Task", exact=True).click()
    page.wait_for_timeout(800)
    page.screenshot(path=str(IMAGES / "exercise.png"))


def main() -> int:
    IMAGES.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    configure_dds_env(env, domain_id=93, network=False)
    with tempfile.TemporaryDirectory() as tmp:
        log = Path(tmp) / "dashboard.log"
        with open(log, "wb") as out:
            proc = subprocess.Popen(
                [sys.executable, "-m", "app", "serve", "--port", str(PORT),
                 "--progress-dir", str(Path(tmp) / "progress")],
                cwd=ROOT, env=env, stdout=out, stderr=subprocess.STDOUT,
            )  # fmt: skip
            try:
                _wait_ready(log, proc)
                with sync_playwright() as playwright:
                    browser = playwright.chromium.launch(
                        executable_path="/usr/bin/chromium",
                        args=["--no-sandbox", "--disable-dev-shm-usage"],
                    )
                    page = browser.new_page(viewport={"width": 1500, "height": 900})
                    page.goto(f"http://127.0.0.1:{PORT}/")
                    page.get_by_role("tab", name="Lessons").wait_for()
                    _dismiss_toasts(page)
                    exercise_graded(page)
                    browser.close()
            finally:
                proc.terminate()
                proc.wait(15)
    for image in sorted(IMAGES.glob("*.png")):
        print(f"wrote {image.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

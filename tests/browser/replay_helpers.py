"""Shared by the replay tests: the player's pick of a pose at a time, and going to moments
by the time slider's box as a learner types them."""

from __future__ import annotations

import re
from collections.abc import Iterator

from playwright.sync_api import Page, expect

from app.exercises.model import Exercise
from tests.browser.helpers import choose, click, expect_editor_loaded, expect_text, open_tab
from tests.browser.test_exercise import _type_code


def newest_at(samples: list[tuple[float, float, float]], t: float) -> tuple[float, float, float]:
    """The newest sample at or before ``t``, as the player picks it. Exactly: both clocks are
    the bag's receive times since its first message. A loaded machine's recording has gaps
    (the simulator starved: ci27's 0.3 s window never saw a pose) and bursts (poses 1 ms
    apart: a 2 ms tolerance compared the drawn pose with the next one)."""
    at_or_before = [(p[0], n, p) for n, p in enumerate(samples) if p[0] <= t + 1e-9]
    return max(at_or_before)[2]  # of two at one time, the later in the file


def go_to_moments(page: Page, times: list[float]) -> Iterator[float]:
    """Let the replay play to its end, then type three moments (at a quarter, half and three
    quarters of ``times``, to 0.1 s as the slider steps) into the time slider's box; yields
    each once the picture is drawn at it.

    Once the picture is drawn the button says "Pause" until the replay ends, so "Play" then
    means it ended: nothing moves the cursor after that but the typed times. (Clicking
    "Pause" instead races the end: a click that lands just after it starts the replay over,
    as Play at the end does, while the page still shows "Play".)

    The picture says its cursor (``data-cursor``): that, not the drawn pose's time, tells
    the typed time was taken. The pose is the newest one at or before the cursor, which may
    be long before it when the recording has a gap (in ci27 the robot stood at 0.4 s into
    the trial with the cursor at 2.9 s: the test then waited for a pose within 0.3 s of
    the cursor that the file did not have).
    """
    play = page.get_by_role("button", name=re.compile(r"^(Play|Pause)$"))
    expect(play).to_have_text(re.compile("Play"), timeout=int((times[-1] + 60) * 1000))
    time_box = (
        page.get_by_text("Time (s)", exact=True)
        .locator("visible=true")
        .first.locator("xpath=ancestor::div[contains(@class,'mantine-Flex-root')][1]//input")
        .last
    )
    for share in (0.25, 0.5, 0.75):
        wanted = round(times[int(len(times) * share)], 1)
        time_box.fill(str(wanted))
        time_box.press("Enter")
        page.wait_for_function(
            "(t) => { const svg = document.querySelector('svg.stage-replay');"
            " return svg && Math.abs(parseFloat(svg.dataset.cursor) - t) < 0.001; }",
            arg=wanted,
            timeout=20_000,
        )
        yield wanted


def grade_in_browser(page: Page, exercise: Exercise, code: str) -> None:
    """As a learner: open ``exercise``, type ``code`` in its editor, run it, Check my node."""
    open_tab(page, "Exercise")
    choose(page, "Exercise", f"{exercise.unit:02d} · {exercise.title}")
    page.get_by_role("tab", name="Your code").click()
    editor = page.frame_locator(f"iframe[src*='slug={exercise.slug}']")
    expect_editor_loaded(editor)
    _type_code(page, editor, code)
    click(page, "Run my node")
    expect_text(page, re.compile(r"running \(pid \d+\) · on the graph"), 60_000)
    click(page, "Check my node")

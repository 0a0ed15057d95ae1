"""The Turtlesim tab: the beginner tutorial's turtle, drawn live and driven from the page.

One walk through what the tutorial does, checked on the drawn image's pixels
(the frame is a lossless PNG, so colours are exact): arrow keys move turtle1
and leave a pen trail, a turtle spawned from the Services panel appears, and
``background_r`` set in the Parameters panel repaints the background.
"""

from __future__ import annotations

import re

import pytest
from playwright.sync_api import Page, expect

from tests.browser.helpers import choose_when_listed, click, open_tab
from tests.browser.test_topics_params_graph import field

pytestmark = [pytest.mark.browser, pytest.mark.ros]

PEN = [179, 184, 255]
TURTLE_BODY = [46, 139, 87]
METER, WORLD = 45.0, (500 - 1) / 45.0

# Colour statistics of the drawn TurtleSim image: pen pixels, turtle pixels near a
# point (x, y in pixels), and the colour of the top-left corner.
PIXELS_JS = """([pen, body, x, y]) => {
  const label = [...document.querySelectorAll('p')].find((e) => e.textContent === 'TurtleSim');
  const img = label && label.parentElement && label.parentElement.querySelector('img');
  if (!img || img.naturalWidth !== 500 || !img.complete) return null;
  const canvas = document.createElement('canvas');
  canvas.width = 500; canvas.height = 500;
  const ctx = canvas.getContext('2d');
  ctx.drawImage(img, 0, 0);
  const data = ctx.getImageData(0, 0, 500, 500).data;
  const same = (i, c) => data[i] === c[0] && data[i + 1] === c[1] && data[i + 2] === c[2];
  let penPixels = 0, bodyNear = 0;
  for (let i = 0; i < data.length; i += 4) {
    if (same(i, pen)) penPixels++;
    const px = (i / 4) % 500, py = Math.floor(i / 4 / 500);
    if (Math.abs(px - x) < 20 && Math.abs(py - y) < 20 && same(i, body)) bodyNear++;
  }
  return {penPixels, bodyNear, corner: [data[0], data[1], data[2]]};
}"""


def pixels(page: Page, x: float = 0.0, y: float = 0.0) -> dict | None:
    arg = [PEN, TURTLE_BODY, x * METER, (WORLD - y) * METER]
    return page.evaluate(PIXELS_JS, arg)


def wait_pixels(page: Page, test: str, x: float = 0.0, y: float = 0.0, timeout: float = 20_000):
    """Wait until ``test`` (JS, on the statistics ``s``) holds for the drawn image."""
    arg = [PEN, TURTLE_BODY, x * METER, (WORLD - y) * METER]
    # The statistics that met the test (a second read could land between two frames).
    handle = page.wait_for_function(
        f"(arg) => {{ const s = ({PIXELS_JS})(arg); return s && ({test}) ? s : null; }}",
        arg=arg,
        polling=200,
        timeout=timeout,
    )
    return handle.json_value()


def choose(page: Page, label: str, option: str) -> None:
    choose_when_listed(page, label, option, exact=True)


def settled_pen_pixels(page: Page) -> int:
    """The trail's pixel count once it stopped growing."""
    count: int | None = None
    for _ in range(30):
        page.wait_for_timeout(700)
        seen = pixels(page)
        if seen is None:  # read while the next frame was loading: not a reading
            continue
        now: int = seen["penPixels"]
        if now == count:
            return now
        count = now
    pytest.fail(f"the trail never settled (last count {count})")


def expect_status(page: Page, pattern: str, timeout: float = 30_000) -> None:
    found = page.get_by_text(re.compile(pattern)).locator("visible=true").first
    expect(found).to_be_visible(timeout=timeout)


def test_keys_drive_spawn_shows_and_background_follows_the_parameter(page):
    open_tab(page, "Turtlesim")
    expect_status(page, r"ros2 run turtlesim turtlesim_node")
    click(page, "Start turtlesim_node")
    expect_status(page, r"Drawing `?/turtlesim`? · turtles: turtle1 ")
    click(page, "Start turtle_teleop_key")  # once the page stopped moving under the pointer
    expect_status(page, r"/teleop_turtle`? is running")
    # turtle1 at the centre, no trail yet, the default background.
    start = wait_pixels(page, "s.bodyNear > 50 && s.corner[0] === 69", WORLD / 2, WORLD / 2)
    assert start["penPixels"] == 0 and start["corner"] == [69, 86, 255]

    # Arrow keys on the page (not in a field) drive turtle1 forward, east: a trail.
    page.get_by_text("TurtleSim", exact=True).click()
    for _ in range(4):
        page.keyboard.press("ArrowUp")
        page.wait_for_timeout(150)
    moved = wait_pixels(page, "s.penPixels > 200", timeout=20_000)
    assert moved["penPixels"] > 200  # at least 1.5 m of a 3-pixel pen
    # A button does the same through the same teleop node: the trail grows.
    click(page, "↑")
    wait_pixels(page, f"s.penPixels > {moved['penPixels'] + 50}", timeout=20_000)
    settled = settled_pen_pixels(page)  # turtlesim stops the turtle 1 s after the last key

    # Spawn turtle2 at (2, 2) from the Services panel, as `ros2 service call /spawn` does.
    open_tab(page, "Services")
    page.evaluate("() => document.activeElement && document.activeElement.blur()")  # no field
    for _ in range(3):  # arrow keys drive only while the Turtlesim tab is shown
        page.keyboard.press("ArrowUp")
    choose(page, "Service", "/spawn")
    field(page, "x (float)").fill("2")
    field(page, "y (float)").fill("2")
    click(page, "Call")
    expect_status(page, r"name='turtle2'")
    open_tab(page, "Turtlesim")
    expect_status(page, r"turtles: turtle1, turtle2 ")
    wait_pixels(page, "s.bodyNear > 50", 2.0, 2.0)

    # background_r = 150 from the Parameters panel repaints the window.
    open_tab(page, "Parameters")
    choose(page, "Node", "/turtlesim")
    value = field(page, "background_r")
    value.fill("150")
    value.press("Enter")
    click(page, "Set background_r")
    expect_status(page, r"Set parameter successful")
    open_tab(page, "Turtlesim")
    after = wait_pixels(page, "s.corner[0] === 150")
    assert after["corner"] == [150, 86, 255]
    # The trail stays on the new background, and the keys pressed elsewhere drove nothing.
    assert after["penPixels"] == settled


def test_the_stage_follows_the_sims_the_learner_starts_last(page):
    """Lesson 3's multisim, started while the first turtlesim still runs, takes the stage."""
    from tests.browser.helpers import start_group, start_node

    start_node(page, "turtlesim_node")
    choose(page, "On stage", "Turtlesim")
    expect_status(page, r"^/turtlesim · turtles: turtle1$")
    start_group(page, "multisim")
    choose(page, "On stage", "Turtlesim")
    # The two sims of one launch may be discovered a second apart: the first by name stays
    # on the left, the second is drawn beside it.
    expect_status(
        page,
        r"^/turtlesim1/turtlesim \(left\) · turtles: turtle1 · "
        r"/turtlesim2/turtlesim \(right\) · turtles: turtle1 · also running: /turtlesim$",
    )
    pair = page.get_by_role("img", name=re.compile("TurtleSim × 2"))
    expect(pair).to_be_visible()
    box = pair.bounding_box()
    assert box is not None and box["width"] > 1.8 * box["height"]  # side by side

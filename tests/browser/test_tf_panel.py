"""The TF tab with real broadcasters started from the Console: the tree, who publishes each
frame, the tf2_echo readout, the view_frames picture, and a frame going stale.

A static_transform_publisher puts turtle1 under world (x 1, y 2, turned 90°);
the tutorial's fixed_frame_tf2_broadcaster puts carrot1 2 m to turtle1's left
on /tf at 10 Hz. So carrot1 in world is at (-1, 2, 0), turned 90°: the readout
must say so, computed by tf2 in the dashboard.
"""

from __future__ import annotations

import base64
import re
import time

import pytest
from playwright.sync_api import Page, expect

from tests.browser.helpers import choose, click, open_tab
from tests.browser.test_ros2_panels import expect_regex, expect_shown, field
from tests.conftest import ARTIFACTS

pytestmark = [pytest.mark.browser, pytest.mark.ros]

STATIC = (
    "ros2 run tf2_ros static_transform_publisher --x 1 --y 2 --yaw 1.5707963 "
    "--frame-id world --child-frame-id turtle1"
)
IMG_JS = "() => [...document.querySelectorAll('img')].find((i) => i.alt.startsWith('view_frames'))"


def expect_line(page: Page, pattern: str) -> None:
    """A line of the tf2_echo readout (a code block: one text, many lines) matches."""
    block = page.locator("pre").filter(has_text="- Translation:").locator("visible=true").first
    expect(block).to_have_text(re.compile(pattern, re.MULTILINE), timeout=30_000)


def console(page: Page, command: str, shown: str) -> None:
    open_tab(page, "Console")
    field(page, "Command").fill(command)
    click(page, "Run")
    expect_shown(page, shown, timeout=60_000)


def test_tf_tab_tree_publishers_echo_view_frames_and_stale(page: Page) -> None:
    console(page, STATIC, "[exit code 0]")
    console(page, "ros2 run turtle_tf2_py fixed_frame_tf2_broadcaster", "[exit code 0]")
    open_tab(page, "TF")
    # The tree, each frame under its parent, with who broadcasts it and how.
    expect_regex(page, r"^world · root \(no parent\)\s*turtle1", timeout=40_000)
    expect_regex(
        page,
        r"^turtle1 · parent world · static \(latched on /tf_static, sent [\d.]+ s ago\) · "
        r"by /static_transform_publisher_[0-9A-Za-z]{16}\s*carrot1",
    )
    expect_regex(
        page,
        r"^carrot1 · parent turtle1 · dynamic · (9\.\d|10) Hz · last 0\.\d s ago · "
        r"by /fixed_frame_tf2_broadcaster$",
    )
    expect_shown(page, "3 frames in 1 tree · 1 static, 1 dynamic")
    # tf2_echo of the deepest frame from the root, as the tab picks it first.
    expect_shown(page, "ros2 run tf2_ros tf2_echo world carrot1")
    z = r"-?0\.000"  # a zero may print as -0.000, as tf2_echo prints it
    for line in (
        rf"^- Translation: \[-1\.000, 2\.000, {z}\]$",
        rf"^- Rotation: in Quaternion \[{z}, {z}, 0\.707, 0\.707\]$",
        rf"^- Rotation: in RPY \(degree\) \[{z}, {z}, 90\.000\]$",
        rf"^ +{z} +-1\.000 +{z} +-1\.000$",
    ):
        expect_line(page, line)
    # The learner picks the other way round: carrot1's frame, where is world?
    choose(page, "Target frame", "carrot1")
    choose(page, "Source frame", "world")
    expect_shown(page, "ros2 run tf2_ros tf2_echo carrot1 world")
    expect_line(page, rf"^- Translation: \[-2\.000, -1\.000, {z}\]$")
    expect_line(page, rf"^- Rotation: in Quaternion \[{z}, {z}, -0\.707, 0\.707\]$")
    page.screenshot(path=str(ARTIFACTS / "tf-panel.png"))

    # view_frames in the Console: its picture appears in the TF tab.
    console(page, "ros2 run tf2_tools view_frames", "[exit code 0]")
    open_tab(page, "TF")
    page.wait_for_function(IMG_JS, polling=200, timeout=40_000)
    src = page.evaluate(f"({IMG_JS})().src")
    svg = base64.b64decode(src.split(",", 1)[1]).decode()
    assert svg.startswith("<svg") and ">carrot1</text>" in svg and ">world</text>" in svg, svg[:200]
    expect_regex(page, r"^frames_[\d\-_.]+\.svg \(and frames_[\d\-_.]+\.gv, its graphviz source\)")
    page.locator("img[alt^='view_frames']").scroll_into_view_if_needed()
    page.screenshot(path=str(ARTIFACTS / "tf-panel-view-frames.png"))

    # Bad input: a quaternion of length zero is refused by tf2, in one line in the tab.
    console(
        page,
        "ros2 topic pub --once /tf tf2_msgs/msg/TFMessage "
        '"{transforms: [{header: {frame_id: world}, child_frame_id: broken, '
        'transform: {rotation: {w: 0.0}}}]}"',
        "[exit code 0]",
    )
    open_tab(page, "TF")
    expect_shown(
        page,
        'tf2 says: TF_DENORMALIZED_QUATERNION: Ignoring transform for child_frame_id "broken"',
    )
    expect(page.get_by_text(re.compile(r"^broken · "))).to_have_count(0)

    # The broadcaster stops: carrot1 goes stale, in words; the static frame does not.
    console(page, "ros2 run --stop /fixed_frame_tf2_broadcaster", "stopped (exit code 0)")
    stopped = time.monotonic()
    open_tab(page, "TF")
    try:
        expect_regex(
            page,
            r"^carrot1 · parent turtle1 · dynamic · ⚠️ STALE: no transform for [\d.]+ s · "
            r"by /fixed_frame_tf2_broadcaster \(that publisher is gone\)$",
            timeout=30_000,
        )
    except AssertionError as exc:  # say what the tab showed instead (cb18c3d's CI, quiet)
        shown = page.get_by_text(re.compile(r"^carrot1 · ")).locator("visible=true")
        lines = [shown.nth(i).inner_text() for i in range(shown.count())]
        raise AssertionError(f"{time.monotonic() - stopped:.1f} s after the stop: {lines}") from exc
    print(f"carrot1 stale and its publisher gone {time.monotonic() - stopped:.1f} s after the stop")
    expect_shown(page, "· ⚠️ 1 stale")
    expect(page.get_by_text(re.compile(r"^turtle1 · .*STALE"))).to_have_count(0)
    # tf2 still answers with carrot1's last transform; the readout says it is old.
    expect_shown(page, "carrot1 went stale: with time zero tf2 answers with the last transform")
    page.screenshot(path=str(ARTIFACTS / "tf-panel-stale.png"))
    console(page, "ros2 run --stop /static_transform_publisher", "stopped (exit code 0)")

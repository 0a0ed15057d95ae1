"""The TF tab's words, from plain data: the tree, stale and gone publishers, loops, pictures."""

from __future__ import annotations

from pathlib import Path

from app.panels.tf_panel import default_pair, describe, picture_path, stale_between, tree_markdown
from app.ros.tf_sources import RATE_MIN_ARRIVALS, RATE_WINDOW, FrameInfo, _Record

WORLD = FrameInfo("world", "")
BASE = FrameInfo("base_link", "world", rate=50.0, age=0.01, publisher="/robot_state_publisher")
CAM = FrameInfo("camera", "base_link", static=True, age=3.0, publisher="/cam_tf")


def test_tree_puts_each_frame_under_its_parent():
    text = tree_markdown([BASE, CAM, WORLD])
    assert text.splitlines() == [
        "3 frames in 1 tree · 1 static, 1 dynamic",
        "",
        "- **`world`** · root (no parent)",
        "  - **`base_link`** · parent `world` · dynamic · 50 Hz · last 0.0 s ago · "
        "by `/robot_state_publisher`",
        "    - **`camera`** · parent `base_link` · static (latched on /tf_static, sent 3.0 s ago)"
        " · by `/cam_tf`",
    ]
    assert tree_markdown([]) == "No TF frames yet: nothing on `/tf` or `/tf_static`."


def test_stale_gone_and_unknown_publishers_are_said_in_words():
    gone = FrameInfo(
        "base_link", "world", age=4.25, stale=True, publisher="/rsp", publisher_here=False
    )
    assert describe(gone) == (
        "**`base_link`** · parent `world` · dynamic · ⚠️ **STALE**: no transform for 4.2 s · "
        "by `/rsp` (that publisher is gone)"
    )
    quiet = FrameInfo("base_link", "world", age=2.0, stale=True, publisher="/rsp")
    assert "**STALE**: no transform for 2.0 s · by `/rsp`" in describe(quiet)
    static_gone = FrameInfo(
        "camera", "base_link", static=True, publisher="/x", publisher_here=False
    )
    assert "(publisher gone: listeners started from now on will not get it)" in describe(
        static_gone
    )
    assert "publisher not known yet" in describe(FrameInfo("a", "b"))
    two = FrameInfo(
        "a", "b", publisher="/p", conflict="also sent with parent `c` by `/q` 0.2 s ago"
    )
    assert describe(two).endswith(
        "⚠️ **two parents**: also sent with parent `c` by `/q` 0.2 s ago "
        "(tf2 warns TF_PARENT_CHANGED)"
    )
    assert stale_between([WORLD, gone, CAM], "camera", "world") == ["base_link"]
    assert stale_between([WORLD, BASE, CAM], "camera", "world") == []


def test_a_loop_is_no_tree_and_the_first_pair_is_the_deepest_frame():
    loop = [FrameInfo("a", "b"), FrameInfo("b", "a"), WORLD, BASE]
    assert tree_markdown(loop).splitlines()[-1] == (
        "- ⚠️ In a loop, so in no tree (TF must be a tree): `a`, `b`"
    )
    assert default_pair([WORLD, BASE, CAM]) == ("world", "camera")
    assert default_pair([]) == ("", "")


def test_the_picture_is_the_one_view_frames_printed_last():
    lines = [
        "view_frames: the picture is /tmp/v/frames_2026-01-01_10.00.00.svg",
        "[INFO] [1.0] [view_frames]: Generating graph...",
        "view_frames: the picture is /tmp/v/frames_2026-01-01_10.00.09.svg",
        "view_frames: the picture is /etc/passwd",
    ]
    assert picture_path(lines) == Path("/tmp/v/frames_2026-01-01_10.00.09.svg")
    assert picture_path(["view_frames: the picture is relative/frames_x.svg"]) is None


def test_a_rate_needs_enough_arrivals_and_uses_the_newest_window():
    record = _Record("world", False, 0.0, b"")
    for k in range(RATE_MIN_ARRIVALS - 1):
        record.arrivals.append(k / 10)
    assert record.rate() is None  # from a few arrivals one late sample would skew it
    record.arrivals.append((RATE_MIN_ARRIVALS - 1) / 10)
    assert abs(record.rate() - 10.0) < 1e-9
    for k in range(RATE_MIN_ARRIVALS, 100):
        record.arrivals.append(k / 10 if k < 50 else 5.0 + (k - 50) / 20)  # 10 Hz, then 20 Hz
    assert len(record.arrivals) == RATE_WINDOW and abs(record.rate() - 20.0) < 1e-9

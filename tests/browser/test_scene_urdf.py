"""The 3D view draws the robot of /robot_description from its URDF and moves it from /tf.

A real robot_state_publisher (ours, as a process) publishes the tutorial's
flexible robot; the test publishes /joint_states and watches the page: the
robot's links appear, the gripper slides when its joint moves, a frame can
be made the Fixed Frame, and a broken description is one line in the panel.
While the robot is described, the lesson-13 desk's own frames give way.
"""

from __future__ import annotations

import contextlib
import math
import os
import signal
import subprocess
import sys

import pytest
from playwright.sync_api import expect
from rclpy.qos import DurabilityPolicy, QoSProfile
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from urdf_tutorial import share_directory

from tests.browser.helpers import choose_when_listed, open_tab, start_group
from tests.browser.scene_helpers import Repeater, world_position
from tests.conftest import ARTIFACTS

pytestmark = [pytest.mark.browser, pytest.mark.ros]

FLEXIBLE = share_directory() / "urdf" / "06-flexible.urdf"
POLE = "/tf_view/frames/gripper_pole"
# The pole's shape: a mesh under its TF frame.
HAS_VISUAL_JS = (
    "(n) => !!window.__viserMutable && Object.keys(window.__viserMutable.nodeRefFromName)"
    ".some((k) => k.startsWith(n + '/visual'))"
)
HAS_NODE_JS = "(n) => !!window.__viserMutable && (n in window.__viserMutable.nodeRefFromName)"
# The lesson-13 desk's own camera frustum: it gives way while a robot_state_publisher runs.
DESK_FRUSTUM = "/base_link/camera/frustum"
SHOWN_JS = "(n) => { const o = window.__viserMutable.nodeRefFromName[n]; return !!o && o.visible; }"
MOVED_JS = (
    "([name, old, far]) => { const o = window.__viserMutable.nodeRefFromName[name];"
    " if (!o) return false; o.updateWorldMatrix(true, false); const e = o.matrixWorld.elements;"
    " return Math.hypot(e[12]-old[0], e[13]-old[1], e[14]-old[2]) > far; }"
)


def test_robot_appears_moves_and_bad_description_is_one_line(page, probe, ros_env) -> None:
    rsp = subprocess.Popen(
        [sys.executable, "-m", "robot_state_publisher", str(FLEXIBLE)],
        env=ros_env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
    )  # fmt: skip
    states = probe.node.create_publisher(JointState, "/joint_states", 10)

    def joints(i: int) -> JointState:
        msg = JointState()
        msg.header.stamp = probe.node.get_clock().now().to_msg()
        msg.name = ["gripper_extension", "head_swivel", "left_gripper_joint"]
        msg.position = [-0.175 + 0.17 * math.sin(i * 0.15), i * 0.05, 0.3]
        return msg

    repeater = Repeater(states, joints, 0.05)
    try:
        open_tab(page, "3D view")
        page.wait_for_function(HAS_VISUAL_JS, arg=POLE, polling=100, timeout=40_000)
        expect(page.get_by_text("14 links").first).to_be_visible(timeout=20_000)
        page.wait_for_function(
            HAS_NODE_JS, arg="/tf_view/frames/head/name", polling=100, timeout=20_000
        )
        page.wait_for_function(f"(n) => !({SHOWN_JS})(n)", arg=DESK_FRUSTUM, timeout=20_000)
        start = world_position(page, POLE)
        assert start is not None
        page.wait_for_function(MOVED_JS, arg=[POLE, start, 0.05], polling=100, timeout=20_000)
        page.screenshot(path=str(ARTIFACTS / "scene-urdf-flexible.png"))

        # The Fixed Frame chooser: with left_leg fixed, that frame sits at the origin.
        choose_when_listed(page, "Fixed Frame", "left_leg")
        page.wait_for_function(
            "(n) => { const o = window.__viserMutable.nodeRefFromName[n]; if (!o) return false;"
            " o.updateWorldMatrix(true, false); const e = o.matrixWorld.elements;"
            " return Math.hypot(e[12], e[13], e[14]) < 1e-3; }",
            arg="/tf_view/frames/left_leg",
            polling=100,
            timeout=20_000,
        )

        # A broken description: one line in the panel, the drawn robot stays.
        latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        bad = probe.node.create_publisher(String, "/robot_description", latched)
        broken = (
            '<robot name="bad"><link name="a"/><joint name="j" type="fixed">'
            '<parent link="nowhere"/><child link="a"/></joint></robot>'
        )
        bad.publish(String(data=broken))
        expect(
            page.get_by_text("parent link [nowhere] of joint [j] not found").first
        ).to_be_visible(timeout=20_000)
        assert page.evaluate(HAS_VISUAL_JS, POLE)

        # The joint states stop: the moving frames go stale, visibly; the fixed ones do not.
        repeater.stop()
        expect(page.get_by_text("Stale (publisher silent)").first).to_be_visible(timeout=20_000)
        status = page.get_by_text("Stale (publisher silent)").first.inner_text()
        assert "gripper_pole" in status and "left_leg," not in status

        # No robot_state_publisher any more: the desk comes back.
        probe.node.destroy_publisher(bad)
        os.killpg(rsp.pid, signal.SIGINT)
        page.wait_for_function(SHOWN_JS, arg=DESK_FRUSTUM, polling=200, timeout=30_000)
    finally:
        repeater.stop()
        with contextlib.suppress(ProcessLookupError):  # the test may have stopped it
            os.killpg(rsp.pid, signal.SIGINT)
        try:
            rsp.wait(timeout=10)
        except subprocess.TimeoutExpired:
            os.killpg(rsp.pid, signal.SIGKILL)
            rsp.wait(timeout=5)


def test_joint_sliders_drive_joint_state_publisher(page) -> None:
    """display.launch.py as a group: moving a slider in the browser moves the robot."""
    start_group(page, "urdf_tutorial_display")
    open_tab(page, "3D view")
    page.wait_for_function(HAS_VISUAL_JS, arg=POLE, polling=100, timeout=40_000)
    row = page.get_by_text("gripper_extension", exact=True).locator(
        "xpath=ancestor::div[contains(@class,'Flex-root')][1]"
    )
    slider = row.get_by_role("slider").first
    slider.wait_for(timeout=20_000)
    page.wait_for_function(SHOWN_JS, arg=POLE, polling=100, timeout=30_000)
    start = world_position(page, POLE)
    assert start is not None
    slider.focus()
    page.keyboard.press("Home")  # all the way in: -0.35 m along the pole's axis
    page.wait_for_function(MOVED_JS, arg=[POLE, start, 0.3], polling=100, timeout=20_000)

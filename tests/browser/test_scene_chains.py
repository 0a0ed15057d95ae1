"""The 3D view with the real perception chains started from the Nodes tab, as a learner would."""

from __future__ import annotations

import pytest
from playwright.sync_api import expect

from tests.browser.helpers import open_folder, open_tab, start_group
from tests.browser.scene_helpers import wait_scene_points

pytestmark = [pytest.mark.browser, pytest.mark.ros]

# Distance the gripper joint moved since ``old`` (world coordinates), from the page.
MOVED_JS = """([name, old, metres]) => {
  const o = window.__viserMutable && window.__viserMutable.nodeRefFromName[name];
  if (!o) return false;
  o.updateWorldMatrix(true, false);
  const e = o.matrixWorld.elements;
  return Math.hypot(e[12] - old[0], e[13] - old[1], e[14] - old[2]) > metres;
}"""
HAS_NODE_JS = "(name) => !!(window.__viserMutable && window.__viserMutable.nodeRefFromName[name])"
IMAGE_SRC_JS = """() => {
  const label = [...document.querySelectorAll('p')].find((e) => e.textContent === 'Camera image');
  const img = label && label.parentElement && label.parentElement.querySelector('img');
  return img && img.naturalWidth > 64 ? img.src : null;
}"""


def test_arm_chain_moves_the_arm_and_shows_the_target(page):
    start_group(page, "camera_to_arm")
    open_tab(page, "3D view")
    # Nothing picked by hand: the 3D view follows /joint_states by itself.
    expect(page.get_by_text("gripper at").first).to_be_visible(timeout=45_000)
    start = page.evaluate(
        "(n) => { const o = window.__viserMutable.nodeRefFromName[n];"
        " o.updateWorldMatrix(true, false); const e = o.matrixWorld.elements;"
        " return [e[12], e[13], e[14]]; }",
        "/base_link/arm/joint4",
    )
    page.wait_for_function(
        MOVED_JS, arg=["/base_link/arm/joint4", start, 0.02], polling=100, timeout=45_000
    )
    # The object in the camera frame and in the base frame, each drawn in its own frame.
    for name in (
        "/base_link/camera/stamped/pos_in_cam_frame",
        "/base_link/stamped/pos_in_robot_base_frame",
    ):
        page.wait_for_function(HAS_NODE_JS, arg=name, polling=100, timeout=30_000)
    # Moving the camera in the view sets the node's parameters.
    open_folder(page, "Camera ↔ base transform")
    row = page.get_by_text("z (m)", exact=True).locator(
        "xpath=ancestor::div[contains(@class,'Flex-root')][1]"
    )
    row.get_by_role("slider").focus()
    page.keyboard.press("ArrowRight")
    expect(page.get_by_text("parameters set").first).to_be_visible(timeout=20_000)


def test_slam_chain_draws_map_trajectory_and_camera_image(page):
    start_group(page, "slam")
    open_tab(page, "3D view")
    # The map cloud (frame "map", drawn at base_link) and the trajectory markers.
    shown = wait_scene_points(page, "/base_link/cloud", 1, timeout_ms=90_000)
    assert shown > 0
    page.wait_for_function(
        HAS_NODE_JS, arg="/base_link/markers/trajectory_0", polling=100, timeout=30_000
    )
    page.get_by_label("Image on the 3D camera").check()
    first = page.wait_for_function(IMAGE_SRC_JS, polling=200, timeout=30_000).json_value()
    page.wait_for_function(
        f"(old) => {{ const s = ({IMAGE_SRC_JS})(); return s && s !== old; }}",
        arg=first,
        polling=200,
        timeout=30_000,
    )
    # One click brings the (far away, sparse) SLAM map into view.
    before = page.evaluate("() => window.__viserMutable.camera.position.toArray()")
    page.get_by_role("button", name="Look at the cloud").click()
    page.wait_for_function(
        "(old) => { const p = window.__viserMutable.camera.position;"
        " return Math.hypot(p.x - old[0], p.y - old[1], p.z - old[2]) > 0.05; }",
        arg=before,
        polling=100,
        timeout=10_000,
    )
    page.wait_for_timeout(500)

"""The 3D view draws the MuJoCo world of sim_drive and drives its robot from the keyboard.

One learner's walk, in one dashboard and one browser: start the launch group
``sim_drive`` from the Nodes tab, open the 3D view, and see the room (its
walls, from the simulator's own model), the robot from its URDF at its TF
frames, the arm from ``/arm/robot_description``, the laser scan as points and
the camera image on the robot's camera frustum. The up arrow drives the
robot: its drawn base_link moves forward. "Follow the robot" moves the 3D
camera along with it.
"""

from __future__ import annotations

import math

import pytest
from playwright.sync_api import Page, expect

from tests.browser.helpers import choose, expect_text, open_tab, start_group
from tests.browser.scene_helpers import wait_scene_points
from tests.conftest import ARTIFACTS

pytestmark = [pytest.mark.browser, pytest.mark.ros]

WORLD = "/tf_view/frames/world"
BASE = "/tf_view/frames/base_link"
FRUSTUM = "/tf_view/frames/camera_optical_frame/camera_view"
# How many scene nodes' names start with a prefix.
COUNT_JS = """(prefix) => !window.__viserMutable ? 0 :
  Object.keys(window.__viserMutable.nodeRefFromName).filter((k) => k.startsWith(prefix)).length"""
# The scene node is mounted, shown (itself and every parent) and holds a texture (an image).
HAS_IMAGE_JS = """(name) => {
  const obj = window.__viserMutable && window.__viserMutable.nodeRefFromName[name];
  if (!obj) return false;
  for (let o = obj; o; o = o.parent) if (!o.visible) return false;
  let found = false;
  obj.traverse((c) => { if (c.material && c.material.map && c.material.map.image) found = true; });
  return found;
}"""
# Where scene node ``name`` is in the frame of node ``frame`` (ROS axes: three.js's world
# is turned so that its y is up), as [x, y, z]; null if either is missing.
POSITION_IN_JS = """([name, frame]) => {
  const nodes = window.__viserMutable && window.__viserMutable.nodeRefFromName;
  const obj = nodes && nodes[name], ref = nodes && nodes[frame];
  if (!obj || !ref) return null;
  obj.updateWorldMatrix(true, false); ref.updateWorldMatrix(true, false);
  const p = obj.getWorldPosition(obj.position.clone());
  return ref.worldToLocal(p).toArray();
}"""
# The 3D camera's position in the frame of node ``frame``.
CAMERA_IN_JS = """(frame) => {
  const m = window.__viserMutable, ref = m && m.nodeRefFromName[frame];
  if (!m || !m.camera || !ref) return null;
  ref.updateWorldMatrix(true, false);
  return ref.worldToLocal(m.camera.position.clone()).toArray();
}"""


# Counts WebGL's program links and frames (clears), from before the page's first script.
COUNT_GL_JS = """(() => {
  const counts = (window.__glCounts = { linkProgram: 0, clear: 0 });
  for (const proto of [WebGLRenderingContext.prototype, WebGL2RenderingContext.prototype])
    for (const name of Object.keys(counts)) {
      const real = proto[name];
      proto[name] = function (...args) { counts[name] += 1; return real.apply(this, args); };
    }
})()"""
# The uuid of the material the scan's points are drawn with (viser makes a new one each
# time the colours change).
SCAN_MATERIAL_JS = """() => {
  const obj = window.__viserMutable && window.__viserMutable.nodeRefFromName["/laser_scan/points"];
  let uuid = null;
  if (obj) obj.traverse((c) => { if (c.isPoints) uuid = c.material.uuid; });
  return uuid;
}"""


def count(page: Page, prefix: str) -> int:
    return int(page.evaluate(COUNT_JS, prefix))


def wait_count(page: Page, prefix: str, at_least: int, timeout: float = 60_000) -> None:
    page.wait_for_function(
        f"(p) => ({COUNT_JS})(p) >= {at_least}", arg=prefix, polling=200, timeout=timeout
    )


def position_in_world(page: Page, name: str) -> list[float]:
    return page.evaluate(POSITION_IN_JS, [name, WORLD])


def drive_forward(page: Page, presses: int) -> None:
    """Tap the up arrow as a held key repeats (each press: one /cmd_vel)."""
    for _ in range(presses):
        page.keyboard.press("ArrowUp")
        page.wait_for_timeout(100)


def test_the_world_is_drawn_and_the_robot_drives_from_the_keyboard(page: Page) -> None:
    page.add_init_script(COUNT_GL_JS)
    page.reload()
    start_group(page, "sim_drive")
    # The room from /sim_world/static_markers, under TF's world frame: floor, 4 walls, 3 objects.
    # Drawn whichever tool is open; the page builds it before it is asked for more (software
    # WebGL on a loaded machine answered no click for 30 s while it did: the CI run of 2026-12-01).
    wait_count(page, f"{WORLD}/sim_world/", 8)
    open_tab(page, "3D view")
    choose(page, "On stage", "3D scene")  # the canvas, not the live graph, in the middle
    wait_count(page, f"{WORLD}/sim_objects/cube_", 1)  # the loose cube
    # The robot from /robot_description (its URDF) and the arm from /arm/robot_description.
    wait_count(page, f"{BASE}/visual", 1)
    wait_count(page, "/tf_view/frames/upper_arm/arm_visual", 1)
    expect_text(page, "World drawn from /sim_world/static_markers", timeout=30_000)
    expect_text(page, "Robot arm from /arm/robot_description", timeout=30_000)

    # The scan as points, and the camera's picture on its frustum at camera_optical_frame.
    assert wait_scene_points(page, "/laser_scan/points", 300, timeout_ms=60_000) >= 300
    page.wait_for_function(HAS_IMAGE_JS, arg=FRUSTUM, polling=200, timeout=60_000)
    expect_text(page, "On the camera at TF frame camera_optical_frame", timeout=30_000)
    expect_text(page, "from its camera_info", timeout=30_000)
    page.wait_for_timeout(1_500)  # the camera settles on the room's overview

    # Each scan comes with new colours (by range), so viser makes the cloud a new material;
    # the point shader is not compiled again for it (app/scene/point_shader.py).
    material, before = page.evaluate(SCAN_MATERIAL_JS), page.evaluate("({...window.__glCounts})")
    page.wait_for_function(f"(m) => ({SCAN_MATERIAL_JS})() !== m", arg=material, timeout=10_000)
    # The scene is drawn on: five more frames (software WebGL on a loaded machine drew
    # 4 in 2 s in the CI of 2026-12-03, so frames are counted, not seconds).
    page.wait_for_function(
        "(n) => window.__glCounts.clear >= n", arg=before["clear"] + 5, timeout=30_000
    )
    after = page.evaluate("({...window.__glCounts})")
    assert after["linkProgram"] == before["linkProgram"], (before, after)
    page.screenshot(path=str(ARTIFACTS / "sim-world-view.png"))

    # The up arrow: the drawn base_link moves forward (+x: the robot starts facing +x).
    expect_text(page, "/sim_world and /sim_teleop_key are running", timeout=30_000)
    page.mouse.click(300, 300)  # on the 3D canvas: the keys no longer go to the dropdown
    start = position_in_world(page, BASE)
    assert math.hypot(start[0], start[1]) < 0.05, start  # the robot starts at the origin
    drive_forward(page, 10)
    page.wait_for_function(
        f"(a) => {{ const p = ({POSITION_IN_JS})(a); return p && p[0] > {start[0] + 0.2}; }}",
        arg=[BASE, WORLD],
        polling=100,
        timeout=20_000,
    )
    moved = position_in_world(page, BASE)
    assert abs(moved[1] - start[1]) < 0.05, (start, moved)  # straight ahead

    # Follow the robot: the 3D camera moves along as it drives on.
    page.get_by_label("Follow the robot").check()
    page.wait_for_timeout(1_000)
    before = page.evaluate(CAMERA_IN_JS, WORLD)
    drive_forward(page, 6)
    page.wait_for_function(
        f"(f) => {{ const p = ({CAMERA_IN_JS})(f); return p && p[0] > {before[0] + 0.1}; }}",
        arg=WORLD,
        polling=100,
        timeout=20_000,
    )
    expect(page.get_by_text("rays hit something").first).to_be_visible()
    page.screenshot(path=str(ARTIFACTS / "sim-world-follow.png"))

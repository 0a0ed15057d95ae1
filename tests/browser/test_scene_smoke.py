"""The 3D view: a learner picks a cloud, an image and a joint topic and sees them live.

An empty view says what would show there; it stops saying so once something is drawn.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from builtin_interfaces.msg import Time
from geometry_msgs.msg import Point, PointStamped
from playwright.sync_api import expect
from sensor_msgs.msg import Image, JointState, PointCloud2
from visualization_msgs.msg import Marker, MarkerArray

from app.scene.image_codec import rgb_to_image_msg
from nodes.common.pointcloud import xyz_to_pointcloud2
from tests.browser.helpers import choose_when_listed, open_tab
from tests.browser.scene_helpers import (
    Repeater,
    now_stamp,
    synthetic_cloud_points,
    wait_scene_points,
    world_position,
)
from tests.conftest import ARTIFACTS

pytestmark = [pytest.mark.browser, pytest.mark.ros]

CLOUD_POINTS = 50_000
# A scene node is mounted (labels register their name with a null object).
HAS_NODE_JS = "(n) => !!window.__viserMutable && (n in window.__viserMutable.nodeRefFromName)"
GONE_JS = "(n) => !!window.__viserMutable && !window.__viserMutable.nodeRefFromName[n]"
# The empty scene's hint is in viser's scene tree, shown (arg true) or hidden (arg false).
HINT_SHOWN_JS = (
    "(shown) => { const tree = window.__viserSceneTree;"
    " const node = tree && tree.getState()['/empty_scene_hint'];"
    " return !!node && (node.visibility ?? true) === shown; }"
)
# src of the image under the "Camera image" label once it shows a picture (not the blank one).
CAMERA_IMAGE_SRC_JS = """() => {
  const label = [...document.querySelectorAll('p')].find((e) => e.textContent === 'Camera image');
  const img = label && label.parentElement && label.parentElement.querySelector('img');
  return img && img.naturalWidth === 160 ? img.src : null;
}"""


def pick(page, label: str, topic: str) -> None:
    """Choose ``topic`` once the dashboard has discovered it (the graph refreshes at 5 Hz)."""
    choose_when_listed(page, label, topic, timeout=30.0)


def test_point_cloud_image_and_arm_show_up_live(page, probe):
    # Nothing on the graph, so nothing drawn: the view says what would show there. Waited
    # for before this test's publishers exist: their joint angles put the desk's arm in
    # the view, and ci128 (a busy loop beside the run) saw the dashboard discover them
    # first. (Waited for with them, it passed only while the dashboard had not yet.)
    open_tab(page, "3D view")
    page.wait_for_function(HINT_SHOWN_JS, arg=True, polling=100, timeout=10_000)
    node = probe.node
    # A marker topic that only has a listener (as a lesson check's on /cam/camera_pose):
    # the Markers row follows it, and the scene, which still draws nothing, keeps its hint.
    # (Taking the old topic's markers away counted as a message received, so the hint went
    # for good: lessons 22 to 24 showed a bare grid.)
    listener = node.create_subscription(MarkerArray, "/test/markers_nobody_sends", lambda _m: 0, 1)
    try:
        expect(page.get_by_label("Marker topic", exact=True)).to_have_value(
            "/test/markers_nobody_sends", timeout=20_000
        )
        expect(page.get_by_text("Markers shown: none yet")).to_be_visible(timeout=10_000)
        page.wait_for_timeout(1000)  # five more refreshes: the hint would have gone by now
        assert page.evaluate(HINT_SHOWN_JS, True), "the hint went with nothing drawn"
    finally:
        node.destroy_subscription(listener)
    pts, colours = synthetic_cloud_points(CLOUD_POINTS)
    cloud_pub = node.create_publisher(PointCloud2, "/test/cloud", 1)
    image_pub = node.create_publisher(Image, "/test/camera/image", 1)
    joint_pub = node.create_publisher(JointState, "/test/joint_states", 10)

    def cloud(i: int) -> PointCloud2:
        sec, nanosec = now_stamp()
        return xyz_to_pointcloud2(
            pts, colours, frame_id="base_link", stamp=Time(sec=sec, nanosec=nanosec)
        )

    def image(i: int) -> Image:
        rgb = np.zeros((120, 160, 3), np.uint8)
        rgb[:, :, 0] = (i * 40) % 256  # the red channel changes with every frame
        rgb[40:80, 60:100] = (30, 200, 60)
        return rgb_to_image_msg(rgb, "bgr8")

    def joints(i: int) -> JointState:
        msg = JointState()
        msg.name = ["base_yaw", "shoulder_pitch", "elbow_pitch", "wrist_pitch"]
        t = i * 0.1
        msg.position = [math.sin(t), 0.6 + 0.3 * math.sin(t), -1.0, -0.8]
        return msg

    repeaters = [
        Repeater(cloud_pub, cloud, 0.2),
        Repeater(image_pub, image, 0.2),
        Repeater(joint_pub, joints, 0.05),
    ]
    try:
        pick(page, "Cloud topic", "/test/cloud")
        shown = wait_scene_points(page, "/base_link/cloud", CLOUD_POINTS, timeout_ms=40_000)
        assert shown == CLOUD_POINTS
        page.wait_for_function(HINT_SHOWN_JS, arg=False, polling=100, timeout=10_000)  # drawn
        expect(page.get_by_text(f"{CLOUD_POINTS:,} points").first).to_be_visible(timeout=10_000)

        pick(page, "Image topic", "/test/camera/image")
        first = page.wait_for_function(CAMERA_IMAGE_SRC_JS, polling=100, timeout=20_000)
        first_src = first.json_value()
        page.wait_for_function(
            f"(old) => {{ const src = ({CAMERA_IMAGE_SRC_JS})(); return src && src !== old; }}",
            arg=first_src,
            polling=100,
            timeout=20_000,
        )
        expect(page.get_by_text("160×120").first).to_be_visible(timeout=10_000)

        pick(page, "Joint topic", "/test/joint_states")
        start = world_position(page, "/base_link/arm/joint4")
        page.wait_for_function(
            "([name, old]) => { const o = window.__viserMutable.nodeRefFromName[name];"
            " if (!o) return false; o.updateWorldMatrix(true, false);"
            " const e = o.matrixWorld.elements;"
            " return Math.hypot(e[12]-old[0], e[13]-old[1], e[14]-old[2]) > 0.02; }",
            arg=["/base_link/arm/joint4", start],
            polling=100,
            timeout=20_000,
        )
        expect(page.get_by_text("gripper at").first).to_be_visible(timeout=10_000)
        page.screenshot(path=str(ARTIFACTS / "scene-live-probe.png"))
    finally:
        for r in repeaters:
            r.stop()


def _marker(kind: int, mid: int, action: int = Marker.ADD) -> Marker:
    m = Marker()
    m.header.frame_id = "base_link"
    m.ns, m.id, m.type, m.action = "demo", mid, kind, action
    m.pose.position.x, m.pose.position.y, m.pose.position.z = -0.3, 0.1 * mid, 0.2
    m.pose.orientation.w = 1.0
    m.scale.x = m.scale.y = m.scale.z = 0.08
    m.color.r, m.color.g, m.color.a = 0.9, 0.3, 1.0
    if kind == Marker.LINE_STRIP:
        m.scale.x = 0.01
        m.points = [Point(x=0.1 * i, y=0.0, z=0.05 * i) for i in range(5)]
    m.text = "hello marker"
    return m


def test_markers_add_modify_and_delete(page, probe):
    pub = probe.node.create_publisher(MarkerArray, "/test/markers", 10)
    kinds = (Marker.SPHERE, Marker.CUBE, Marker.ARROW, Marker.LINE_STRIP, Marker.TEXT_VIEW_FACING)
    state = {"delete_cube": False}

    def markers(i: int) -> MarkerArray:
        arr = MarkerArray()
        arr.markers = [_marker(k, n) for n, k in enumerate(kinds)]
        if state["delete_cube"]:
            arr.markers[1] = _marker(Marker.CUBE, 1, Marker.DELETE)
        return arr

    repeater = Repeater(pub, markers, 0.2)
    try:
        open_tab(page, "3D view")
        pick(page, "Marker topic", "/test/markers")
        page.wait_for_function(
            HAS_NODE_JS, arg="/base_link/markers/demo_0", polling=100, timeout=30_000
        )
        for n in range(len(kinds)):
            page.wait_for_function(
                HAS_NODE_JS, arg=f"/base_link/markers/demo_{n}", polling=100, timeout=30_000
            )
        expect(page.get_by_text("Markers shown:").first).to_be_visible(timeout=10_000)
        state["delete_cube"] = True
        page.wait_for_function(
            GONE_JS,
            arg="/base_link/markers/demo_1",
            polling=100,
            timeout=20_000,
        )
        assert page.evaluate(HAS_NODE_JS, "/base_link/markers/demo_0")
    finally:
        repeater.stop()


# The camera lesson's desk: base_link and camera marks, drawn by the view itself.
DESK_SHOWN_JS = (
    "() => { const o = window.__viserMutable && window.__viserMutable.nodeRefFromName["
    "'/base_link/camera/frustum']; return !!o && o.visible; }"
)


def test_the_desk_shows_only_while_a_node_feeds_it(page, probe):
    """Lessons after the camera lesson showed its base_link and camera marks with nothing
    running (under the URDF robot, the capstone's map): they show while a node publishes
    what they draw, here a stamped point in the camera frame."""
    open_tab(page, "3D view")
    page.wait_for_function(HAS_NODE_JS, arg="/base_link/camera/frustum", timeout=30_000)
    page.wait_for_timeout(2_000)  # a few graph refreshes
    assert not page.evaluate(DESK_SHOWN_JS), "the desk shows with no node feeding it"
    publisher = probe.node.create_publisher(PointStamped, "/pos_in_cam_frame", 10)

    def point(i: int) -> PointStamped:
        msg = PointStamped()
        msg.header.frame_id = "camera"
        msg.point.z = 0.5
        return msg

    repeater = Repeater(publisher, point, 0.1)
    drawn = "/base_link/camera/stamped/pos_in_cam_frame"
    try:
        page.wait_for_function(DESK_SHOWN_JS, polling=200, timeout=30_000)
        page.wait_for_function(HAS_NODE_JS, arg=drawn, polling=200, timeout=30_000)
    finally:
        repeater.stop()
        probe.node.destroy_publisher(publisher)
    page.wait_for_function(f"() => !({DESK_SHOWN_JS})()", polling=200, timeout=30_000)
    # Its publisher gone, the point goes too: a stopped node's point does not stand on.
    gone = "(n) => !(window.__viserMutable.nodeRefFromName[n] || {}).visible"
    page.wait_for_function(gone, arg=drawn, polling=200, timeout=30_000)


def test_a_map_published_once_is_drawn_on_the_floor_of_its_frame(page, probe):
    """A latched /map (as map_server and the grid mapper publish it) shows up in the Map row."""
    import array

    from geometry_msgs.msg import TransformStamped
    from nav_msgs.msg import OccupancyGrid
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from tf2_msgs.msg import TFMessage

    latched = QoSProfile(
        depth=1,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )
    grid = OccupancyGrid()
    grid.header.frame_id = "map"
    grid.info.width, grid.info.height, grid.info.resolution = 40, 20, 0.1
    grid.info.origin.position.x, grid.info.origin.position.y = -2.0, -1.0
    grid.info.origin.orientation.w = 1.0
    cells = [-1] * 800
    cells[: 40 * 10] = [0] * 400  # the lower half known free, a wall across its middle
    cells[40 * 5 : 40 * 6] = [100] * 40
    grid.data = array.array("b", cells)
    probe.node.create_publisher(OccupancyGrid, "/map", latched).publish(grid)  # once only
    link = TransformStamped()
    link.header.frame_id, link.child_frame_id = "map", "odom"
    link.transform.rotation.w = 1.0
    probe.node.create_publisher(TFMessage, "/tf_static", latched).publish(
        TFMessage(transforms=[link])
    )

    open_tab(page, "3D view")
    picture = "/tf_view/frames/map/occupancy_grid"
    page.wait_for_function(HAS_NODE_JS, arg=picture, polling=200, timeout=30_000)
    expect(page.get_by_text("40 x 20 cells of 0.1 m").first).to_be_visible(timeout=20_000)
    note = page.get_by_text("50 % known, in").first  # `map` is code: TF has the frame
    expect(note).to_be_visible(timeout=20_000)
    assert "stopped publishing" not in page.locator("body").inner_text()  # latched: normal
    page.screenshot(path=str(ARTIFACTS / "scene-map.png"))

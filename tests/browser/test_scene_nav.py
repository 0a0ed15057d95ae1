"""The 3D view for navigation: amcl's particles and the plan on the map, and rviz's 2D Pose
Estimate and Nav2 Goal, each set by two clicks on the floor."""

from __future__ import annotations

import array
import math
import threading

import numpy as np
import pytest
from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped, TransformStamped
from nav2_msgs.action import NavigateToPose
from nav2_msgs.msg import Particle, ParticleCloud
from nav_msgs.msg import OccupancyGrid, Path
from playwright.sync_api import Page, expect
from playwright.sync_api import TimeoutError as PlaywrightTimeout
from rclpy.action import ActionServer
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from tf2_msgs.msg import TFMessage

from tests.browser.helpers import choose, open_tab
from tests.browser.scene_helpers import Repeater
from tests.conftest import ARTIFACTS

pytestmark = [pytest.mark.browser, pytest.mark.ros]

LATCHED = QoSProfile(
    depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)
BEST_EFFORT = QoSProfile(depth=5, reliability=ReliabilityPolicy.BEST_EFFORT)
HAS_NODE_JS = "(n) => !!window.__viserMutable && (n in window.__viserMutable.nodeRefFromName)"
# The page pixel where the floor point (x, y) of TF frame `map` shows, and what is there.
FLOOR_TO_SCREEN_JS = """([x, y]) => {
  const m = window.__viserMutable;
  const frame = m.nodeRefFromName['/tf_view/frames/map'];
  const camera = m.camera;
  frame.updateWorldMatrix(true, false);
  camera.updateMatrixWorld();
  const v = camera.position.clone().set(x, y, 0).applyMatrix4(frame.matrixWorld).project(camera);
  const canvas = [...document.querySelectorAll('canvas')].sort(
    (a, b) => b.clientWidth * b.clientHeight - a.clientWidth * a.clientHeight)[0];
  const r = canvas.getBoundingClientRect();
  const px = r.left + (v.x + 1) / 2 * r.width, py = r.top + (1 - v.y) / 2 * r.height;
  const hit = document.elementFromPoint(px, py);
  return [px, py, hit ? hit.tagName : null];
}"""
PARTICLES = 500
CLICKED = ((0.6, -0.2), (0.6, 0.4))  # the robot's spot, then a point straight ahead (+y)
GOAL_CLICKED = ((0.2, 0.4), (-0.4, 0.4))  # where to go, then a point behind it (-x)


NAV_LAYERS = ("particle_cloud", "nav_path", "occupancy_grid")


def wait_scene_nodes(page: Page, names: list[str], timeout_ms: int = 60_000) -> None:
    """Wait until the scene has every node of ``names``; on a timeout, say which are missing."""
    try:
        page.wait_for_function(
            f"(names) => names.every({HAS_NODE_JS})", arg=names, polling=200, timeout=timeout_ms
        )
    except PlaywrightTimeout:
        present = page.evaluate(f"(names) => names.filter({HAS_NODE_JS})", names)
        missing = [name for name in names if name not in present]
        raise AssertionError(f"not in the 3D scene after {timeout_ms} ms: {missing}") from None


def click_floor(page: Page, points: tuple[tuple[float, float], ...]) -> None:
    """Click each floor point of `map` in the canvas, waiting for the first to be taken.

    A first click that a loaded browser let pass unnoticed is clicked again, as a
    learner would; one still not taken after that fails the test.
    """
    taken = page.get_by_text("Now click in the direction").first
    for i, point in enumerate(points):
        for attempt in range(2 if i == 0 else 1):
            x, y, hit = page.evaluate(FLOOR_TO_SCREEN_JS, list(point))
            assert hit == "CANVAS", f"floor point {point} is under {hit} at ({x:.0f}, {y:.0f})"
            page.mouse.click(x, y)
            if i > 0:
                break
            try:  # the first click is taken: the second sets the heading
                taken.wait_for(state="visible", timeout=10_000)
                break
            except PlaywrightTimeout:
                if attempt == 1:
                    raise


def office_map() -> OccupancyGrid:
    """A 6 m x 4 m room at 5 cm cells: free inside, walls round it, a desk in it."""
    grid = OccupancyGrid()
    grid.header.frame_id = "map"
    width, height, res = 120, 80, 0.05
    grid.info.width, grid.info.height, grid.info.resolution = width, height, res
    grid.info.origin.position.x, grid.info.origin.position.y = -2.0, -2.0
    grid.info.origin.orientation.w = 1.0
    cells = np.zeros((height, width), np.int8)
    cells[:2, :] = cells[-2:, :] = cells[:, :2] = cells[:, -2:] = 100
    cells[50:60, 20:40] = 100  # a desk
    grid.data = array.array("b", cells.ravel().tolist())
    return grid


def particle_cloud(seed: int) -> ParticleCloud:
    """amcl's cloud a moment after a pose estimate: a blob around (0.3, -0.5), facing +x."""
    rng = np.random.default_rng(seed)
    xy = rng.normal((0.3, -0.5), 0.25, size=(PARTICLES, 2))
    yaw = rng.normal(0.0, 0.3, PARTICLES)
    weights = rng.uniform(0.2, 1.0, PARTICLES)
    msg = ParticleCloud()
    msg.header.frame_id = "map"
    for (x, y), a, w in zip(
        xy.tolist(), yaw.tolist(), (weights / weights.sum()).tolist(), strict=True
    ):
        p = Particle(weight=w)
        p.pose.position.x, p.pose.position.y = x, y
        p.pose.orientation.z, p.pose.orientation.w = math.sin(a / 2), math.cos(a / 2)
        msg.particles.append(p)
    return msg


def plan() -> Path:
    """From the particles round the desk to the far corner: 60 poses."""
    msg = Path()
    msg.header.frame_id = "map"
    for t in np.linspace(0.0, 1.0, 60):
        pose = PoseStamped()
        pose.header.frame_id = "map"
        pose.pose.position.x = 0.3 + 2.8 * t
        pose.pose.position.y = -0.5 + 1.8 * math.sin(t * math.pi / 2) ** 2
        pose.pose.orientation.w = 1.0
        msg.poses.append(pose)
    return msg


def test_particles_and_the_plan_lie_on_the_map_and_two_clicks_set_the_pose(page, probe):
    node = probe.node
    link = TransformStamped()
    link.header.frame_id, link.child_frame_id = "map", "odom"
    link.transform.rotation.w = 1.0
    node.create_publisher(TFMessage, "/tf_static", LATCHED).publish(TFMessage(transforms=[link]))
    node.create_publisher(OccupancyGrid, "/map", LATCHED).publish(office_map())
    node.create_publisher(Path, "/plan", LATCHED).publish(plan())  # once, as a planner does
    clouds = [particle_cloud(seed) for seed in range(3)]
    cloud_pub = node.create_publisher(ParticleCloud, "/particle_cloud", BEST_EFFORT)
    repeater = Repeater(cloud_pub, lambda i: clouds[i % 3], 0.5)
    estimates: list[PoseWithCovarianceStamped] = []
    arrived = threading.Event()

    def on_estimate(msg: PoseWithCovarianceStamped) -> None:
        estimates.append(msg)
        arrived.set()

    node.create_subscription(PoseWithCovarianceStamped, "/initialpose", on_estimate, 10)
    try:
        open_tab(page, "3D view")
        choose(page, "On stage", "3D scene")  # the canvas, not the live graph, in the middle
        wait_scene_nodes(page, [f"/tf_view/frames/map/{name}" for name in NAV_LAYERS])
        expect(page.get_by_text(f"{PARTICLES} particles, spread 0.").first).to_be_visible(
            timeout=20_000
        )
        expect(page.get_by_text("60 poses, 3.").first).to_be_visible(timeout=20_000)
        page.screenshot(path=str(ARTIFACTS / "scene-nav-particles-path.png"))

        page.get_by_role("button", name="2D Pose Estimate").click()
        expect(page.get_by_text("click the floor where the robot is").first).to_be_visible(
            timeout=10_000
        )
        click_floor(page, CLICKED)
        assert arrived.wait(15.0), "no /initialpose came"
        (msg,) = estimates
        assert msg.header.frame_id == "map"
        position = msg.pose.pose.position
        assert math.hypot(position.x - CLICKED[0][0], position.y - CLICKED[0][1]) < 0.05
        q = msg.pose.pose.orientation
        yaw = math.atan2(2 * q.w * q.z, 1 - 2 * q.z * q.z)
        assert abs(yaw - math.pi / 2) < math.radians(5)
        assert list(msg.pose.covariance)[0] == 0.25
        expect(page.get_by_text("ros2 topic pub --once /initialpose").first).to_be_visible(
            timeout=10_000
        )
        page.screenshot(path=str(ARTIFACTS / "scene-nav-pose-estimate.png"))

        # Nav2 Goal: a navigator that reports the distance left, then succeeds when told.
        goals: list[NavigateToPose.Goal] = []
        finish = threading.Event()

        def execute(handle):  # the probe's executor thread: it may wait here a moment
            goals.append(handle.request)
            handle.publish_feedback(NavigateToPose.Feedback(distance_remaining=1.25))
            finish.wait(15.0)
            handle.succeed()
            return NavigateToPose.Result()

        server = ActionServer(node, NavigateToPose, "/navigate_to_pose", execute)
        try:
            page.get_by_role("button", name="Nav2 Goal").click()
            expect(
                page.get_by_text("click the floor where the robot should go").first
            ).to_be_visible(timeout=10_000)
            click_floor(page, GOAL_CLICKED)
            expect(page.get_by_text("1.25 m").first).to_be_visible(timeout=15_000)
            (goal,) = goals
            assert goal.pose.header.frame_id == "map"
            at = goal.pose.pose.position
            assert math.hypot(at.x - GOAL_CLICKED[0][0], at.y - GOAL_CLICKED[0][1]) < 0.05
            assert abs(abs(goal.pose.pose.orientation.z) - 1.0) < 0.01  # facing -x
            expect(
                page.get_by_text("ros2 action send_goal /navigate_to_pose").first
            ).to_be_visible()
            finish.set()
            expect(page.get_by_text("Goal reached").first).to_be_visible(timeout=15_000)
        finally:
            finish.set()
            server.destroy()
    finally:
        repeater.stop()

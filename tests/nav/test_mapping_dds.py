"""The grid mapper over real DDS: the office world, a short drive, a map that matches the plan.

sim_world (office, ``publish_world_tf:=false``), the robot's
robot_state_publisher and grid_mapper run under the supervisor as the
``office_mapping`` launch group starts them; the test drives the robot on
/cmd_vel (a turn on the spot in the corridor, a few metres east, another
turn), then judges the latched /map against the world file's floor plan
(``app.lessons.checks._world_map``) and the TF tree the mapper completes.
Finally map_saver_cli saves that map as Nav2 would, and the files load back
as the same map.
"""

from __future__ import annotations

import math
import subprocess
import sys
import threading
import time
from typing import Any

import numpy as np
import pytest
from geometry_msgs.msg import Twist
from nav2_map_server.map_io import load_map_from_yaml
from nav_msgs.msg import OccupancyGrid, Odometry
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_srvs.srv import Empty
from tf2_msgs.msg import TFMessage

from app import PROJECT_ROOT
from app.catalog import lookup
from app.lessons.checks._world_map import load_world_map
from nodes.common.occupancy_grid import cell_centres, map_agreement, plan_distance
from tests.conftest import wait_until

pytestmark = [pytest.mark.ros, pytest.mark.timeout(180)]

LATCHED = QoSProfile(
    depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)
# As tf2's static listener: every latched /tf_static message (the mapper's and
# robot_state_publisher's), not only the newest one.
STATIC = QoSProfile(
    depth=100, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)
SIM_ARGS = ("-p", "camera_rate:=0.0", "-p", "real_time_factor:=2.0")
AGREEMENT_AIM = 90.0  # % of the cells the map knows (the benchmark's tour aims at 95)


class Watcher:
    """What the test sees: the newest map, the robot's true pose, the TF edges."""

    def __init__(self, node: Any) -> None:
        self.lock = threading.Lock()
        self.map: OccupancyGrid | None = None
        self.maps = 0
        self.map_at = time.monotonic()
        self.truth: tuple[float, float, float, float] | None = None  # t, x, y, yaw
        self.edges: set[tuple[str, str]] = set()
        self.static_edges: set[tuple[str, str]] = set()
        node.create_subscription(OccupancyGrid, "/map", self.on_map, LATCHED)
        node.create_subscription(Odometry, "/ground_truth/odom", self.on_truth, 10)
        node.create_subscription(TFMessage, "/tf", self.on_tf, 50)
        node.create_subscription(TFMessage, "/tf_static", self.on_static, STATIC)
        self.cmd = node.create_publisher(Twist, "/cmd_vel", 10)

    def on_map(self, msg: OccupancyGrid) -> None:
        with self.lock:
            self.map, self.maps = msg, self.maps + 1
            self.map_at = time.monotonic()

    def quiet_for(self) -> float:
        """Seconds since the last map came."""
        with self.lock:
            return time.monotonic() - self.map_at

    def on_truth(self, msg: Odometry) -> None:
        q = msg.pose.pose.orientation
        yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
        stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        with self.lock:
            self.truth = (stamp, msg.pose.pose.position.x, msg.pose.pose.position.y, yaw)

    def on_tf(self, msg: TFMessage) -> None:
        with self.lock:
            self.edges |= {(t.header.frame_id, t.child_frame_id) for t in msg.transforms}

    def on_static(self, msg: TFMessage) -> None:
        with self.lock:
            self.static_edges |= {(t.header.frame_id, t.child_frame_id) for t in msg.transforms}

    def pose(self) -> tuple[float, float, float, float]:
        wait_until(lambda: self.truth, timeout=60, what="/ground_truth/odom")
        with self.lock:
            assert self.truth is not None
            return self.truth

    def drive(
        self,
        linear: float,
        angular: float,
        done: Any,
        limit: float = 40.0,
        heading: float | None = None,
    ) -> None:
        """Publish a velocity at 10 Hz (wall) until ``done(pose)`` holds; with ``heading``,
        steer to keep it (on a loaded machine a turn's last command, taken late, left the
        robot driving north into the corridor's wall where the test meant east)."""
        deadline = time.monotonic() + limit
        while not done(pose := self.pose()):
            assert time.monotonic() < deadline, f"the drive did not finish: {pose}"
            turn = angular
            if heading is not None:
                error = math.atan2(math.sin(heading - pose[3]), math.cos(heading - pose[3]))
                turn = max(-0.8, min(0.8, 1.5 * error))
            self.cmd.publish(Twist(linear=_vec(linear), angular=_vec(z=turn)))
            time.sleep(0.1)
        self.cmd.publish(Twist())


def _vec(x: float = 0.0, z: float = 0.0) -> Any:
    from geometry_msgs.msg import Vector3

    return Vector3(x=float(x), z=float(z))


def turn_once(watcher: Watcher, rate: float = 1.5) -> None:
    """A full turn on the spot, counted from the true heading."""
    state = {"last": watcher.pose()[3], "turned": 0.0}

    def done(pose: tuple[float, float, float, float]) -> bool:
        step = math.atan2(math.sin(pose[3] - state["last"]), math.cos(pose[3] - state["last"]))
        state["turned"] += step
        state["last"] = pose[3]
        return abs(state["turned"]) >= 2 * math.pi

    watcher.drive(0.0, rate, done)


def face(watcher: Watcher, heading: float, limit: float = 40.0) -> None:
    """Turn on the spot until the true heading is ``heading`` (a loaded machine's late stop
    can leave a full turn a quarter turn long: the drive after it would meet a wall)."""
    deadline = time.monotonic() + limit
    while True:
        yaw = watcher.pose()[3]
        error = math.atan2(math.sin(heading - yaw), math.cos(heading - yaw))
        if abs(error) < 0.05:
            break
        assert time.monotonic() < deadline, f"could not face {heading}: {watcher.pose()}"
        turn = max(-0.8, min(0.8, 1.5 * error))
        watcher.cmd.publish(Twist(linear=_vec(0.0), angular=_vec(z=turn)))
        time.sleep(0.1)
    watcher.cmd.publish(Twist())


def agreement_of(msg: OccupancyGrid) -> Any:
    plan = load_world_map("office")
    origin = (msg.info.origin.position.x, msg.info.origin.position.y)
    xs, ys = cell_centres(origin, msg.info.resolution, msg.info.width, msg.info.height)
    distance = plan_distance(plan.obstacles, xs, ys)
    return map_agreement(np.array(msg.data, np.int8), distance, msg.info.resolution)


def test_driving_the_office_builds_a_map_that_agrees_with_the_floor_plan(
    probe, supervisor, tmp_path
):
    started = time.monotonic()
    watcher = Watcher(probe.node)
    supervisor.start_program(lookup("sim_office_mapping"), SIM_ARGS)
    supervisor.start("sim_robot_state_publisher")
    supervisor.start("grid_mapper")
    wait_until(lambda: watcher.maps > 0, timeout=60, what=lambda: _logs(supervisor))
    up = time.monotonic() - started

    turn_once(watcher)
    face(watcher, 0.0)  # east, along the corridor
    watcher.drive(0.3, 0.0, lambda pose: pose[1] >= 1.5, heading=0.0)  # pose: (t, x, y, yaw)
    turn_once(watcher, rate=-1.5)
    end = watcher.pose()[0]

    def fresh() -> OccupancyGrid | None:  # a map with every scan of the drive in it
        with watcher.lock:
            msg = watcher.map
        stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9 if msg else -1.0
        return msg if stamp >= end else None

    msg = wait_until(fresh, timeout=30, what="a /map stamped after the drive")
    assert isinstance(msg, OccupancyGrid)
    assert msg.header.frame_id == "map" and msg.info.resolution == pytest.approx(0.05)
    assert set(np.unique(np.array(msg.data, np.int8)).tolist()) <= {-1, 0, 100}
    result = agreement_of(msg)
    print(f"\nmapping: {result.text()}; nodes up in {up:.1f} s")
    assert result.percent >= AGREEMENT_AIM, result.text()
    assert result.occupied >= 300 and result.free >= 4000, result.text()  # it mapped a lot
    # The TF tree the mapper completes: map -> odom (ours) -> base_link, map -> world.
    with watcher.lock:
        edges, static = set(watcher.edges), set(watcher.static_edges)
    assert ("map", "odom") in edges and ("odom", "base_link") in edges
    assert ("world", "odom") not in edges  # sim_world left odom's parent to the mapper
    assert ("map", "world") in static
    assert not any("Traceback" in line for line in supervisor.output("grid_mapper"))

    # Nav2's map_saver_cli saves that latched map; the files load back as the same grid.
    # The world is paused first: no more scans, so the map the saver gets is the newest one.
    pause = probe.node.create_client(Empty, "/pause_physics")
    assert pause.wait_for_service(timeout_sec=10)
    paused = pause.call_async(Empty.Request())
    wait_until(paused.done, timeout=10, what="/pause_physics")
    wait_until(  # the mapper publishes once a second while its map changes
        lambda: watcher.quiet_for() > 2.5, timeout=30, what="a map that stops changing"
    )
    base = tmp_path / "maps" / "office"
    saving = time.monotonic()
    saved = subprocess.run(
        [sys.executable, "-m", "nodes.map_saver_cli", "-f", str(base)],
        cwd=PROJECT_ROOT,
        env={**probe_env(), "PYTHONUNBUFFERED": "1"},
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert saved.returncode == 0, saved.stdout + saved.stderr
    print(f"map_saver_cli: saved in {time.monotonic() - saving:.1f} s (process start included)")
    assert "Map saved successfully" in saved.stdout + saved.stderr
    with watcher.lock:
        newest = watcher.map
    loaded = load_map_from_yaml(f"{base}.yaml")
    assert loaded.ok, loaded.reason
    assert newest is not None and loaded.map is not None
    assert (loaded.map.info.width, loaded.map.info.height) == (
        newest.info.width,
        newest.info.height,
    )
    assert list(loaded.map.data) == list(newest.data)
    print(f"mapping test: {time.monotonic() - started:.1f} s in all")


def probe_env() -> dict[str, str]:
    import os

    return dict(os.environ)  # ros_env put this test's domain and DDS profile into it


def _logs(supervisor: Any) -> str:
    parts = []
    for name in ("sim_office_mapping", "sim_robot_state_publisher", "grid_mapper"):
        parts.append(f"--- {name}:\n" + "\n".join(supervisor.output(name, last=15)))
    return "a /map from grid_mapper\n" + "\n".join(parts)

"""The controller's progress checker counts the node's clock: simulated time under use_sim_time.

Nav2's SimpleProgressChecker compares the node's clock with the time of the
last progress. With the world at another speed than real time, the wall
clock would give a robot that cannot move ten simulated seconds at 1x,
twenty at 2x, a hundred at 10x. Here the real controller_server runs with
``use_sim_time``; this test's own rclpy context stands in for the world:
/clock ten times faster than the wall, a robot that stays where it is (map ->
odom -> base_link on /tf_static) and an empty room on /map. A path three
metres long is sent to ``follow_path``; the robot never moves, so the goal
must end FAILED_TO_MAKE_PROGRESS once ``movement_time_allowance`` (10 s) of
simulated time has passed, one wall second or so, not ten.
"""

from __future__ import annotations

import threading
import time

import pytest
import rclpy
from builtin_interfaces.msg import Time as TimeMsg
from geometry_msgs.msg import PoseStamped, TransformStamped
from lifecycle_msgs.msg import Transition
from lifecycle_msgs.srv import ChangeState
from nav2_msgs.action import FollowPath
from nav_msgs.msg import OccupancyGrid, Path
from rclpy.context import Context
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock
from tf2_msgs.msg import TFMessage

from app.catalog import lookup
from app.ros.action_client import ThreadSafeActionClient
from tests.nav.goal_helpers import wait_future

pytestmark = [pytest.mark.ros, pytest.mark.timeout(120)]

LATCHED = QoSProfile(
    depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)
ABORTED = 6  # action_msgs/GoalStatus
SPEED_UP = 10.0  # simulated seconds per wall second on /clock
TICK_SEC = 0.02  # wall seconds between two /clock messages
ALLOWANCE_SEC = 10.0  # progress_checker.movement_time_allowance, the controller's default
CLOCK_LAG_SEC = 1.0  # simulated: a tenth of a wall second, how far behind its clock may be


class StandIns:
    """The world's part: /clock at SPEED_UP, a standing robot on /tf_static, a room on /map."""

    def __init__(self) -> None:
        self.context = Context()
        rclpy.init(context=self.context)
        self.node = Node("clock_stand_ins", context=self.context)
        self.lock = threading.Lock()
        self.sim_ns = 100 * 10**9
        self._clock = self.node.create_publisher(Clock, "/clock", 10)
        transforms = []
        for parent, child in (("map", "odom"), ("odom", "base_link")):
            tf = TransformStamped()
            tf.header.frame_id, tf.child_frame_id = parent, child
            tf.transform.rotation.w = 1.0
            transforms.append(tf)
        self._static = self.node.create_publisher(TFMessage, "/tf_static", LATCHED)
        self._static.publish(TFMessage(transforms=transforms))
        room = OccupancyGrid()
        room.header.frame_id = "map"
        room.info.resolution = 0.05
        room.info.width = room.info.height = 120  # 6 m x 6 m, free
        room.info.origin.position.x = room.info.origin.position.y = -3.0
        room.info.origin.orientation.w = 1.0
        room.data = [0] * (120 * 120)
        self._map = self.node.create_publisher(OccupancyGrid, "/map", LATCHED)
        self._map.publish(room)
        # Goals go from the test's thread while the executor spins in another: rclpy's own
        # ActionClient can drop the answer then ("Ignoring unexpected goal response", seen).
        self.follow = ThreadSafeActionClient(self.node, FollowPath, "follow_path")
        self.change_state = self.node.create_client(ChangeState, "/controller_server/change_state")
        self._executor = MultiThreadedExecutor(num_threads=2, context=self.context)
        self._executor.add_node(self.node)
        self._spinner = threading.Thread(target=self._executor.spin, daemon=True)
        self._spinner.start()
        self._ticking = threading.Event()
        self._ticker = threading.Thread(target=self._tick, daemon=True)
        self._ticker.start()

    def _tick(self) -> None:
        """Simulated time SPEED_UP times the wall's, by the wall clock between messages."""
        last = time.monotonic()
        while not self._ticking.wait(TICK_SEC):
            now = time.monotonic()
            with self.lock:
                self.sim_ns += int((now - last) * SPEED_UP * 1e9)
                stamp = self.sim_ns
            last = now
            self._clock.publish(Clock(clock=TimeMsg(sec=stamp // 10**9, nanosec=stamp % 10**9)))

    def sim_sec(self) -> float:
        with self.lock:
            return self.sim_ns * 1e-9

    def close(self) -> None:
        self._ticking.set()
        self._ticker.join(timeout=2.0)
        self._executor.shutdown(timeout_sec=2.0)
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)


def _transition(stand_ins: StandIns, transition: int) -> None:
    assert stand_ins.change_state.wait_for_service(timeout_sec=30), "no controller_server"
    request = ChangeState.Request(transition=Transition(id=transition))
    answer = wait_future(stand_ins.change_state.call_async(request), 30, "change_state's answer")
    assert answer.success, f"controller_server refused transition {transition}"


def _east_path(length: float) -> Path:
    path = Path()
    path.header.frame_id = "map"
    for i in range(int(length / 0.05) + 1):
        pose = PoseStamped()
        pose.header.frame_id = "map"
        pose.pose.position.x = 0.05 * i
        pose.pose.orientation.w = 1.0
        path.poses.append(pose)
    return path


def test_no_progress_is_judged_in_simulated_time(supervisor):
    stand_ins = StandIns()
    try:
        supervisor.start_program(lookup("controller_server"), ["-p", "use_sim_time:=true"])
        _transition(stand_ins, Transition.TRANSITION_CONFIGURE)
        _transition(stand_ins, Transition.TRANSITION_ACTIVATE)
        assert stand_ins.follow.wait_for_server(timeout_sec=30)
        sim0, wall0 = stand_ins.sim_sec(), time.monotonic()
        handle = wait_future(
            stand_ins.follow.send_goal_async(FollowPath.Goal(path=_east_path(3.0))),
            30,
            "follow_path's answer",
        )
        assert handle.accepted
        outcome = wait_future(handle.get_result_async(), 30, "follow_path's result")
        sim, wall = stand_ins.sim_sec() - sim0, time.monotonic() - wall0
        assert outcome.status == ABORTED, f"the goal ended with status {outcome.status}"
        code = outcome.result.error_code
        assert code == FollowPath.Result.FAILED_TO_MAKE_PROGRESS, (
            f"error {code}: {outcome.result.error_msg}"
        )
        # Judged by the node's clock: the allowance in simulated seconds, a tenth of it in
        # wall seconds (wall-clock judging would take the whole allowance in wall seconds).
        # The controller's clock is the last /clock it has read, a message or two behind this
        # test's (ci35: it gave up 9.83 s by this test's clock, 17 ms of wall time short).
        assert sim >= ALLOWANCE_SEC - CLOCK_LAG_SEC, f"gave up after {sim:.2f} simulated s"
        assert wall < ALLOWANCE_SEC / 2, (
            f"gave up after {wall:.1f} wall s ({sim:.1f} simulated): by the wall clock"
        )
    finally:
        stand_ins.close()

"""The lessons' TF check kinds on real publishers: each passes, and each can fail.

A broadcaster node in this process (over DDS, not a mock) sends a static
``world -> base`` on /tf_static, a moving ``base -> wheel`` on /tf, and a
``world -> ghost`` on a *volatile* /tf_static publisher (the late-joiner
mistake). The checks run through ``LessonRuntime`` as the lesson panel runs
them, with the graph snapshot refreshed as the dashboard does.
"""

from __future__ import annotations

import math
import time

import pytest
from geometry_msgs.msg import TransformStamped
from rclpy.qos import QoSProfile
from tf2_msgs.msg import TFMessage
from tf2_ros import StaticTransformBroadcaster, TransformBroadcaster

from app.lessons.registry import FAIL, PASS, WAITING
from app.lessons.runtime import LessonRuntime
from app.lessons.schema import Spec
from app.ros.graph import snapshot

pytestmark = pytest.mark.ros


def stamped(node, parent: str, child: str, x: float, yaw: float = 0.0) -> TransformStamped:
    t = TransformStamped()
    t.header.stamp = node.get_clock().now().to_msg()
    t.header.frame_id, t.child_frame_id = parent, child
    t.transform.translation.x = x
    t.transform.rotation.z, t.transform.rotation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return t


@pytest.fixture
def lessons(supervisor):
    from app.ros.runtime import RosRuntime

    runtime = RosRuntime()
    rt = LessonRuntime(runtime.node, supervisor)
    yield rt
    rt.close()
    runtime.shutdown()


def settle(rt: LessonRuntime, spec: Spec, timeout: float, want: str = PASS) -> tuple[str, str]:
    """Evaluate as the panel does until the check is in state ``want`` or the time is up.

    (Before discovery a check may fail with "nobody publishes"; the panel looks again.)
    """
    deadline = time.monotonic() + timeout
    while True:
        rt.graph = snapshot(rt.node)
        result = rt.evaluate(spec)
        if result.state == want or time.monotonic() > deadline:
            return result.state, result.reason
        time.sleep(0.2)


def test_tf_checks_pass_and_fail_on_real_publishers(lessons, probe):
    rt = lessons
    frame = Spec("tf_frame", {"frame": "base", "parent": "world"})
    transform = Spec(
        "tf_transform",
        {"target": "world", "source": "base", "x": 1.0, "yaw": 0.5, "tolerance": 0.001},
    )
    moves = Spec("tf_moves", {"frame": "wheel", "at_least": 0.3})
    late = Spec("tf_late_joiner", {"frame": "base", "parent": "world"})
    # Nobody publishes yet: every kind fails at once, with a reason.
    rt.graph = snapshot(rt.node)
    for spec in (frame, transform, moves, late):
        result = rt.evaluate(spec)
        assert result.state == FAIL and "nobody publishes" in result.reason, (spec.kind, result)

    node = probe.node
    static = StaticTransformBroadcaster(node)
    static.sendTransform(stamped(node, "world", "base", 1.0, yaw=0.5))
    volatile = node.create_publisher(TFMessage, "/tf_static", QoSProfile(depth=1))
    volatile.publish(TFMessage(transforms=[stamped(node, "world", "ghost", 2.0)]))
    dynamic = TransformBroadcaster(node)
    start = time.monotonic()
    timer = node.create_timer(
        0.05,
        lambda: dynamic.sendTransform(stamped(node, "base", "wheel", time.monotonic() - start)),
    )
    try:
        assert settle(rt, frame, 15)[0] == PASS
        state, reason = settle(rt, Spec("tf_frame", {"frame": "base", "parent": "map"}), 5, FAIL)
        assert state == FAIL and "has the parent 'world'" in reason, reason

        assert settle(rt, transform, 10)[0] == PASS
        wrong = Spec(
            "tf_transform", {"target": "world", "source": "base", "x": 1.0, "tolerance": 0.01}
        )
        state, reason = settle(rt, wrong, 5, FAIL)  # the yaw is missing from the expectation
        assert state == FAIL and "0.500 rad off" in reason, reason
        # through the chain: wheel in world moves (base -> wheel on /tf), so a value it has
        # not reached yet is waited for, with the value it has now
        chain = Spec(
            "tf_transform", {"target": "world", "source": "wheel", "x": 50.0, "tolerance": 0.01}
        )
        state, reason = settle(rt, chain, 3, "none")
        assert state == WAITING and "'wheel' in 'world'" in reason, reason

        assert settle(rt, moves, 10)[0] == PASS
        state, reason = settle(rt, Spec("tf_moves", {"frame": "base", "at_least": 0.1}), 5, FAIL)
        assert state == FAIL and "static frame" in reason, reason

        assert settle(rt, late, 15)[0] == PASS
        ghost = Spec("tf_late_joiner", {"frame": "ghost", "within": 4.0})
        state, reason = settle(rt, ghost, 10, FAIL)
        assert state == FAIL and "got no 'ghost'" in reason and "transient local" in reason, reason
    finally:
        node.destroy_timer(timer)
        node.destroy_publisher(volatile)


def test_points_agree_passes_for_matrix_and_tf2_and_fails_when_the_copies_drift(lessons, probe):
    """Unit 13's camera cell: the hand-made matrix and tf2 give the same point, until the
    matrix node's own copy of the camera pose is changed and the two disagree by 10 cm."""
    from rclpy.parameter import Parameter
    from rclpy.parameter_client import AsyncParameterClient

    rt, sup = lessons, lessons.supervisor
    agree = Spec(
        "points_agree",
        {"topic": "/pos_in_robot_base_frame_tf2", "like": "/pos_in_robot_base_frame",
         "tolerance": 0.001},
    )  # fmt: skip
    for name in ("camera_publisher", "camera_static_tf", "coordinate_transform"):
        sup.start(name)
    try:
        state, why = settle(rt, agree, 5.0, want=FAIL)
        assert state == FAIL and "no publisher on /pos_in_robot_base_frame_tf2" in why, why
        sup.start("coordinate_transform_tf2_side")
        state, why = settle(rt, agree, 40.0)
        assert state == PASS and "in 'base_link'" in why and "mm apart" in why, why
        client = AsyncParameterClient(probe.node, "/coordinate_transform")
        assert client.wait_for_services(timeout_sec=10.0)
        future = client.set_parameters([Parameter("camera_z", value=0.8)])
        deadline = time.monotonic() + 10
        while not future.done() and time.monotonic() < deadline:
            time.sleep(0.05)
        state, why = settle(rt, agree, 20.0, want=FAIL)
        assert state == FAIL and "100.0 mm apart" in why, why
    finally:
        for name in (
            "coordinate_transform_tf2_side", "coordinate_transform", "camera_static_tf",
            "camera_publisher",
        ):  # fmt: skip
            sup.stop(name).result(timeout=10)

"""Probe ``joint_motion``: the grader publishes drawn values of one joint on /joint_states;
through a tf2 lookup, the joint's child (or a frame fixed on it) must sit where the URDF
joint puts it (robot_state_publisher's job, from the learner's URDF).
"""

from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING

from rclpy.time import Time
from sensor_msgs.msg import JointState
from tf2_ros import Buffer, TransformException, TransformListener

from app.exercises.probes.base import ProbeContext, register_probe
from app.exercises.probes.tf import expected_joint_pose
from app.exercises.probes.topics import others_subscribed
from app.exercises.report import Result
from app.lessons.schema import Spec
from app.ros.rotations import rotation_angle as quat_angle

if TYPE_CHECKING:
    from collections.abc import Iterable
    from typing import SupportsFloat

    from rclpy.publisher import Publisher


def _vec3(value: Iterable[SupportsFloat]) -> tuple[float, float, float]:
    x, y, z = (float(v) for v in value)
    return (x, y, z)


def _judge_joint(
    ctx: ProbeContext, buffer: Buffer, publisher: Publisher, p: Spec, value: float
) -> str:
    """'' when the judged frame follows ``value`` within 3 s, else what is wrong."""
    joint, parent = p["joint"], p["parent"]
    frame = p.get("frame", p["child"])  # the frame judged: the child, or one fixed on it
    jtype, axis = p.get("type", "revolute"), _vec3(p["axis"])
    origin, offset = _vec3(p.get("origin", [0, 0, 0])), _vec3(p.get("offset", [0, 0, 0]))
    want_xyz, want_q = expected_joint_pose(jtype, origin, axis, value, offset)
    node = ctx.call.node
    sent = time.monotonic()
    pose: tuple[tuple[float, float, float], tuple[float, ...]] | None = None
    error = "no transform yet"
    while time.monotonic() - sent < float(p.get("within", 3.0)):
        msg = JointState(name=[joint], position=[value])
        msg.header.stamp = node.get_clock().now().to_msg()
        publisher.publish(msg)
        ctx.call.sleep(0.1)
        try:
            t = buffer.lookup_transform(parent, frame, Time())
        except TransformException as exc:
            error = str(exc)
            continue
        v, r = t.transform.translation, t.transform.rotation
        pose = ((v.x, v.y, v.z), (r.x, r.y, r.z, r.w))
        if math.dist(pose[0], want_xyz) < 1e-3 and quat_angle(pose[1], want_q) < 1e-3:
            return ""
    if pose is None:
        return f"set {joint}={value}; no transform from {frame} to {parent}: {error}"
    turned = quat_angle(pose[1], (0, 0, 0, 1))
    if jtype != "prismatic" and turned < 1e-3 and abs(value) > 0.01:
        why = f"'{frame}' does not turn with {joint}: is it attached to another link?"
    else:
        why = f"'{frame}' is not where {joint}'s origin, axis and value put it"
    where = "({:.3f}, {:.3f}, {:.3f})".format(*pose[0])
    want = "({:.3f}, {:.3f}, {:.3f})".format(*want_xyz)
    return (
        f"set {joint}={value}; {frame} in {parent} is at {where}, {_turn_text(pose[1])}; "
        f"expected {want}, {_turn_text(want_q)}: {why}"
    )


def _turn_text(q: tuple[float, ...]) -> str:
    """A rotation in words: its angle and axis."""
    angle = quat_angle(q, (0, 0, 0, 1))
    s = math.sqrt(max(0.0, 1.0 - q[3] * q[3])) or 1.0
    if angle < 1e-6:
        return "not turned"
    sign = 1.0 if q[3] >= 0 else -1.0
    axis = ", ".join(f"{sign * v / s:.2f}" for v in q[:3])
    return f"turned {angle:.3f} rad about ({axis})"


@register_probe(
    "joint_motion",
    required="joint parent child axis range",
    optional="type origin frame offset samples within",
    words="publishes random values of one joint on /joint_states; the joint's child (or a "
    "frame fixed on it) must sit where the URDF's joint puts it",
    draws="random joint values inside the probe's range",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
    """Publish drawn values of one joint on /joint_states; its child must follow the URDF."""
    joint, parent = p["joint"], p["parent"]
    low, high = (float(v) for v in p["range"])
    frame = p.get("frame", p["child"])
    name = f"joint {joint} moves {frame}"
    node = ctx.call.node
    buffer = Buffer()
    listener = TransformListener(buffer, node)
    publisher = node.create_publisher(JointState, "/joint_states", 10)
    tried: list[str] = []
    try:
        deadline = time.monotonic() + 5.0
        while not others_subscribed(node, publisher, "/joint_states"):
            if time.monotonic() > deadline:
                return Result(name, False, "nothing subscribes to /joint_states")
            ctx.call.sleep(0.1)
        for _ in range(int(p.get("samples", 3))):
            value = round(ctx.rng.uniform(low, high), 3)
            wrong = _judge_joint(ctx, buffer, publisher, p, value)
            if wrong:
                return Result(name, False, wrong)
            tried.append(f"{joint}={value}")
        return Result(name, True, f"{frame} in {parent} right for {', '.join(tried)}")
    finally:
        listener.unregister()
        node.destroy_publisher(publisher)

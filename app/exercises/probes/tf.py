"""Probes for the tf2 exercises: the grader moves turtles and judges the frames and turtles.

``turtle_frame``: the grader teleports a turtle to poses drawn at grading
time and compares the learner's ``world -> turtle`` transform on /tf with
each pose. ``turtle_follow``: the grader puts the leader turtle at random
places, one after another, and the follower (steered by the learner's tf2
listener) must come within a bound of it each time. ``static_frame``: the
grader sets the learner's frame parameters to drawn names and offsets, then
joins /tf_static late and reads the frame there. ``joint_motion``: the grader
publishes drawn joint values on /joint_states and checks, through a tf2
lookup, that the joint's child (or a frame fixed on it) sits where the URDF
joint puts it (robot_state_publisher's job, from the learner's URDF).
"""

from __future__ import annotations

import math
import threading
import time
from dataclasses import dataclass
from typing import Any

from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.time import Time
from sensor_msgs.msg import JointState
from tf2_msgs.msg import TFMessage
from tf2_ros import Buffer, TransformException, TransformListener
from turtlesim.msg import Pose
from turtlesim.srv import TeleportAbsolute

from app.exercises.probes.base import Probe, ProbeContext
from app.exercises.report import Result
from app.lessons.kinds import make_kind
from app.lessons.schema import Spec
from app.ros import params
from app.ros.calls import call_service
from app.ros.errors import Ros2Error
from app.ros.monitor import TopicMonitor

WORLD_MIN, WORLD_MAX = 1.5, 9.5  # teleport targets: inside turtlesim's 11 m world, off the walls
STATIC_QOS = QoSProfile(
    depth=100, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)


@dataclass(frozen=True)
class Seen:
    """One transform as it arrived: when, its parent, translation and yaw."""

    arrival: float
    parent: str
    x: float
    y: float
    z: float
    yaw: float
    unit: bool  # the quaternion has length 1 (within 1e-3)
    static: bool = False  # came on /tf_static


def yaw_of(x: float, y: float, z: float, w: float) -> float:
    """Yaw of a quaternion (normalised first, so a wrong length cannot hide a wrong angle)."""
    n = math.sqrt(x * x + y * y + z * z + w * w) or 1.0
    x, y, z, w = x / n, y / n, z / n, w / n
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def angle_between(a: float, b: float) -> float:
    return abs(math.atan2(math.sin(a - b), math.cos(a - b)))


class FrameTap:
    """Every transform on /tf and /tf_static, newest per child frame (executor thread writes)."""

    def __init__(self, ctx: ProbeContext, static_only: bool = False) -> None:
        self._node = ctx.call.node
        self._lock = threading.Lock()
        self.newest: dict[str, Seen] = {}
        self._subs = [
            self._node.create_subscription(TFMessage, "/tf_static", self._on_static, STATIC_QOS)
        ]
        if not static_only:
            self._subs.append(self._node.create_subscription(TFMessage, "/tf", self._on_tf, 100))

    def _on_static(self, msg: TFMessage) -> None:
        self._on_tf(msg, static=True)

    def _on_tf(self, msg: TFMessage, static: bool = False) -> None:
        now = time.monotonic()
        with self._lock:
            for t in msg.transforms:
                v, r = t.transform.translation, t.transform.rotation
                length = math.sqrt(r.x**2 + r.y**2 + r.z**2 + r.w**2)
                self.newest[t.child_frame_id] = Seen(
                    now,
                    t.header.frame_id,
                    v.x,
                    v.y,
                    v.z,
                    yaw_of(r.x, r.y, r.z, r.w),
                    abs(length - 1.0) < 1e-3,
                    static,
                )

    def get(self, child: str) -> Seen | None:
        with self._lock:
            return self.newest.get(child)

    def children_of(self) -> dict[str, str]:
        with self._lock:
            return {child: seen.parent for child, seen in self.newest.items()}

    def close(self) -> None:
        for sub in self._subs:
            self._node.destroy_subscription(sub)


def _teleport(ctx: ProbeContext, turtle: str, x: float, y: float, theta: float) -> None:
    request = TeleportAbsolute.Request(x=x, y=y, theta=theta)
    call_service(ctx.call, f"/{turtle}/teleport_absolute", TeleportAbsolute, request, timeout=3.0)


def _pose_text(x: float, y: float, yaw: float) -> str:
    return f"(x={x:.2f}, y={y:.2f}, yaw={yaw:.2f})"


def _frame_mistake(seen: Seen, x: float, y: float, theta: float, tol: float) -> str:
    """What a wrong transform most likely got wrong, in words."""
    if not seen.unit:
        return (
            "the rotation is not a unit quaternion: compute it from theta with sin/cos of theta/2"
        )
    if math.hypot(seen.x - y, seen.y - x) < tol and math.hypot(seen.x - x, seen.y - y) >= tol:
        return "x and y are swapped"
    if math.hypot(seen.x - x, seen.y - y) >= tol:
        return "the translation is not the turtle's position"
    if angle_between(seen.yaw, -theta) < 0.05:
        return "the heading has the wrong sign"
    return "the heading (rotation about z) is not the turtle's theta"


def turtle_frame(ctx: ProbeContext, p: Spec) -> Result:
    """Teleport the turtle to random poses; /tf must carry parent -> turtle at each pose."""
    turtle, parent = p.get("turtle", "turtle1"), p.get("parent", "world")
    tol, count = float(p.get("tolerance", 0.01)), int(p.get("poses", 4))
    name = f"frame {parent} -> {turtle} follows the pose"
    tap = FrameTap(ctx)
    tried: list[str] = []
    try:
        for _ in range(count):
            x = round(ctx.rng.uniform(WORLD_MIN, WORLD_MAX), 2)
            y = round(ctx.rng.uniform(WORLD_MIN, WORLD_MAX), 2)
            theta = round(ctx.rng.uniform(-3.0, 3.0), 2)
            asked = time.monotonic()
            try:
                _teleport(ctx, turtle, x, y, theta)
            except Ros2Error as exc:
                return Result(name, False, f"could not teleport {turtle}: {exc}")
            deadline = asked + float(p.get("within", 3.0))
            seen = None
            while time.monotonic() < deadline:
                seen = tap.get(turtle)
                if seen is not None and seen.arrival > asked + 0.1 and seen.parent == parent:
                    if (
                        math.hypot(seen.x - x, seen.y - y) < tol
                        and abs(seen.z) < tol
                        and angle_between(seen.yaw, theta) < 0.02
                        and seen.unit
                    ):
                        break
                ctx.call.sleep(0.05)
            else:
                want = _pose_text(x, y, theta)
                if seen is None:
                    frames = tap.children_of()
                    heard = ", ".join(f"{a} -> {c}" for c, a in frames.items()) or "nothing"
                    return Result(
                        name, False, f"no transform for the child frame '{turtle}' on /tf "
                        f"(heard: {heard})"
                    )  # fmt: skip
                if seen.parent != parent:
                    return Result(
                        name,
                        False,
                        f"'{turtle}' has the parent '{seen.parent}' on /tf; expected the parent "
                        f"'{parent}' (header.frame_id is the parent, child_frame_id the turtle)",
                    )
                if seen.arrival <= asked + 0.1:
                    return Result(
                        name, False, f"teleported {turtle} to {want}; no new transform came after"
                    )
                got = _pose_text(seen.x, seen.y, seen.yaw)
                return Result(
                    name,
                    False,
                    f"teleported {turtle} to {want}; /tf says {got}: "
                    f"{_frame_mistake(seen, x, y, theta, tol)}",
                )
            tried.append(_pose_text(x, y, theta))
        return Result(name, True, f"{count} random poses, each on /tf, e.g. {tried[0]}")
    finally:
        tap.close()


def _distance(leader: TopicMonitor, follower: TopicMonitor) -> float | None:
    a, b = leader.message(), follower.message()
    if a is None or b is None:
        return None
    return math.hypot(a[1].x - b[1].x, a[1].y - b[1].y)


def turtle_follow(ctx: ProbeContext, p: Spec) -> Result:
    """Put the leader at random places; each time the follower must come within ``bound``."""
    lead, follow = p.get("leader", "turtle1"), p.get("follower", "turtle2")
    bound, within = float(p.get("bound", 1.0)), float(p.get("within", 15.0))
    name = f"{follow} follows {lead}"
    node = ctx.call.node
    leader = TopicMonitor(node, f"/{lead}/pose", Pose, keep=5, qos=10)
    follower = TopicMonitor(node, f"/{follow}/pose", Pose, keep=5, qos=10)
    done: list[str] = []
    try:
        deadline = time.monotonic() + float(p.get("spawn_within", 10.0))
        while follower.message() is None or leader.message() is None:
            if time.monotonic() > deadline:
                return Result(
                    name, False, f"no pose on /{follow}/pose: spawn {follow} (the /spawn service)"
                )
            ctx.call.sleep(0.2)
        for move in range(int(p.get("moves", 2))):
            newest = follower.message()
            assert newest is not None
            fx, fy = newest[1].x, newest[1].y
            while True:  # a place at least 3 m from the follower: a real chase
                x = round(ctx.rng.uniform(WORLD_MIN, WORLD_MAX), 2)
                y = round(ctx.rng.uniform(WORLD_MIN, WORLD_MAX), 2)
                if math.hypot(x - fx, y - fy) >= 3.0:
                    break
            try:
                _teleport(ctx, lead, x, y, round(ctx.rng.uniform(-3.0, 3.0), 2))
            except Ros2Error as exc:
                return Result(name, False, f"could not teleport {lead}: {exc}")
            start = time.monotonic()
            ctx.call.sleep(0.3)
            trace = [_distance(leader, follower) or 0.0]
            closest = trace[0]
            while (d := _distance(leader, follower) or math.inf) > bound:
                closest = min(closest, d)
                if time.monotonic() - start > within:
                    trace.append(d)
                    way = "grew" if trace[-1] > trace[0] + 0.2 else "did not close"
                    return Result(
                        name,
                        False,
                        f"move {move + 1}: put {lead} at ({x:.2f}, {y:.2f}); in {within:g} s the "
                        f"distance {way}: {trace[0]:.2f} m -> {trace[-1]:.2f} m (closest "
                        f"{closest:.2f} m, needed below {bound:g} m)",
                    )
                ctx.call.sleep(0.1)
            done.append(f"{trace[0]:.1f} m -> {d:.2f} m in {time.monotonic() - start:.1f} s")
        return Result(name, True, f"{follow} caught up after every move: {'; '.join(done)}")
    finally:
        leader.close()
        follower.close()


CHILD_WORDS = ("lidar", "camera", "imu", "gps", "sonar", "bumper", "antenna")
PARENT_WORDS = ("world", "map", "odom", "base_link")


def _late_joiner_frames(ctx: ProbeContext, within: float, child: str) -> dict[str, Seen]:
    """What a fresh transient-local /tf_static subscriber receives within ``within`` s."""
    tap = FrameTap(ctx, static_only=True)
    try:
        deadline = time.monotonic() + within
        while time.monotonic() < deadline and tap.get(child) is None:
            ctx.call.sleep(0.1)
        return dict(tap.newest)
    finally:
        tap.close()


def static_frame(ctx: ProbeContext, p: Spec) -> Result:
    """Set the node's frame parameters to drawn values; a late /tf_static joiner must get it."""
    target = p.get("node", ctx.learner_node)
    child = f"{ctx.rng.choice(CHILD_WORDS)}_{ctx.rng.randint(10, 99)}"
    parent = ctx.rng.choice(PARENT_WORDS)
    values: dict[str, float | str] = {"child_frame": child, "parent_frame": parent}
    for axis in ("x", "y", "z"):
        values[axis] = round(ctx.rng.uniform(-2.0, 2.0), 3)
    values["yaw"] = round(ctx.rng.uniform(-3.0, 3.0), 3)
    name = f"static frame {parent} -> {child}"
    asked = ", ".join(f"{k}={v!r}" for k, v in values.items())
    dynamic = FrameTap(ctx)  # hears /tf too: a frame sent there is a likely mistake
    try:
        for key, value in values.items():
            try:
                ok, reason = params.set_value(ctx.call, target, key, value)
            except Ros2Error as exc:
                return Result(name, False, f"could not set the parameter {key}: {exc}")
            if not ok:
                return Result(name, False, f"{target} refused {key}={value!r}: {reason}")
        ctx.call.sleep(float(p.get("settle", 1.5)))  # sent by now; the next reader joins late
        frames = _late_joiner_frames(ctx, float(p.get("within", 8.0)), child)
        seen = frames.get(child)
        if seen is None:
            heard = ", ".join(sorted(frames)) or "nothing"
            on_tf = dynamic.get(child)
            if on_tf is not None and not on_tf.static:
                return Result(
                    name,
                    False,
                    f"set {asked}; '{child}' went out on /tf, not /tf_static: a subscriber "
                    "that joins later never gets it (use StaticTransformBroadcaster)",
                )
            return Result(
                name,
                False,
                f"set {asked}; a subscriber that joined /tf_static late got no '{child}' "
                f"(it got: {heard}): send the frame again whenever the parameters change",
            )
        want = (float(values["x"]), float(values["y"]), float(values["z"]))
        got = f"(x={seen.x:.3f}, y={seen.y:.3f}, z={seen.z:.3f}, yaw={seen.yaw:.3f})"
        if seen.parent != parent:
            return Result(name, False, f"set {asked}; '{child}' has the parent '{seen.parent}'")
        if math.dist((seen.x, seen.y, seen.z), want) > 1e-3:
            return Result(name, False, f"set {asked}; a late joiner got {got}: wrong translation")
        if not seen.unit or angle_between(seen.yaw, float(values["yaw"])) > 1e-3:
            return Result(
                name,
                False,
                f"set {asked}; a late joiner got {got}: the heading (yaw) is wrong"
                + ("" if seen.unit else ", and the quaternion is not of length 1"),
            )
        return Result(name, True, f"set {asked}; a late joiner got {parent} -> {child} {got}")
    finally:
        dynamic.close()


def _axis_angle(axis: tuple[float, float, float], angle: float) -> tuple[float, ...]:
    """The quaternion (x, y, z, w) turning ``angle`` about ``axis`` (normalised here)."""
    n = math.sqrt(sum(a * a for a in axis)) or 1.0
    s = math.sin(angle / 2.0) / n
    return (axis[0] * s, axis[1] * s, axis[2] * s, math.cos(angle / 2.0))


def _rotate(q: tuple[float, ...], v: tuple[float, float, float]) -> tuple[float, float, float]:
    """``v`` turned by the unit quaternion ``q``."""
    x, y, z, w = q
    # v' = v + 2w (u x v) + 2 u x (u x v), u = (x, y, z)
    cx, cy, cz = y * v[2] - z * v[1], z * v[0] - x * v[2], x * v[1] - y * v[0]
    dx, dy, dz = y * cz - z * cy, z * cx - x * cz, x * cy - y * cx
    return (v[0] + 2 * (w * cx + dx), v[1] + 2 * (w * cy + dy), v[2] + 2 * (w * cz + dz))


def _quat_angle(a: tuple[float, ...], b: tuple[float, ...]) -> float:
    dot = abs(sum(p * q for p, q in zip(a, b, strict=True)))
    return 2.0 * math.acos(min(1.0, dot))


def expected_joint_pose(
    joint_type: str,
    origin: tuple[float, float, float],
    axis: tuple[float, float, float],
    value: float,
    offset: tuple[float, float, float] = (0.0, 0.0, 0.0),
) -> tuple[tuple[float, float, float], tuple[float, ...]]:
    """Where a point ``offset`` of the child sits in the parent, and the child's rotation.

    URDF: the child frame is the joint origin, then the motion along/about the axis.
    """
    if joint_type == "prismatic":
        n = math.sqrt(sum(a * a for a in axis)) or 1.0
        shift = tuple(o + a / n * value for o, a in zip(origin, axis, strict=True))
        point = tuple(p + q for p, q in zip(shift, offset, strict=True))
        return (point[0], point[1], point[2]), (0.0, 0.0, 0.0, 1.0)
    q = _axis_angle(axis, value)
    turned = _rotate(q, offset)
    point = tuple(o + t for o, t in zip(origin, turned, strict=True))
    return (point[0], point[1], point[2]), q


def _vec3(value: Any) -> tuple[float, float, float]:
    x, y, z = (float(v) for v in value)
    return (x, y, z)


def _judge_joint(ctx: ProbeContext, buffer: Buffer, publisher: Any, p: Spec, value: float) -> str:
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
        if math.dist(pose[0], want_xyz) < 1e-3 and _quat_angle(pose[1], want_q) < 1e-3:
            return ""
    if pose is None:
        return f"set {joint}={value}; no transform from {frame} to {parent}: {error}"
    turned = _quat_angle(pose[1], (0, 0, 0, 1))
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
    angle = _quat_angle(q, (0, 0, 0, 1))
    s = math.sqrt(max(0.0, 1.0 - q[3] * q[3])) or 1.0
    if angle < 1e-6:
        return "not turned"
    sign = 1.0 if q[3] >= 0 else -1.0
    axis = ", ".join(f"{sign * v / s:.2f}" for v in q[:3])
    return f"turned {angle:.3f} rad about ({axis})"


def joint_motion(ctx: ProbeContext, p: Spec) -> Result:
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
        while publisher.get_subscription_count() == 0:
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


DRAWS = {
    "turtle_frame": "random turtle poses (x, y in [1.5, 9.5] m, theta in [-3, 3] rad)",
    "turtle_follow": "a random path for the leader (places in [1.5, 9.5] m, 3 m or more away)",
    "static_frame": "random frame names and offsets (x, y, z in [-2, 2] m, yaw in [-3, 3] rad)",
    "joint_motion": "random joint values inside the probe's range",
}
KINDS = {
    "turtle_frame": make_kind("", "turtle parent poses tolerance within"),
    "turtle_follow": make_kind("", "leader follower moves bound within spawn_within"),
    "static_frame": make_kind("", "node settle within"),
    "joint_motion": make_kind(
        "joint parent child axis range", "type origin frame offset samples within"
    ),
}
PROBES: dict[str, Probe] = {
    "turtle_frame": turtle_frame,
    "turtle_follow": turtle_follow,
    "static_frame": static_frame,
    "joint_motion": joint_motion,
}

"""turtlesim_node: the ROS 2 turtlesim, as the beginner tutorials use it, without a window.

The node ``/turtlesim`` keeps turtles in a square world of 11.088889 m and
moves them every 16 ms. It is the ROS face of
``nodes/common/turtlesim_world.py``, which holds the simulation itself (and
which the dashboard draws in the browser). Names, types, QoS and log lines are
those of ROS 2 Jazzy's turtlesim, so a program written for the real one runs
unchanged against this one.

Global interfaces
- services ``clear``, ``reset`` (``std_srvs/srv/Empty``), ``spawn``
  (``turtlesim/srv/Spawn``: an empty name gets turtle2, turtle3, ...; a taken
  name is refused: the reply's name is empty and an error is logged) and
  ``kill`` (``turtlesim/srv/Kill``);
- parameters ``background_r``, ``background_g``, ``background_b`` (0..255,
  changeable while it runs) and ``holonomic`` (then ``linear.y`` moves
  sideways).

Per turtle, e.g. ``turtle1/``
- ``cmd_vel`` (``geometry_msgs/msg/Twist``, subscribed): velocities, dropped
  to zero 1 s after the last message;
- ``pose`` (``turtlesim/msg/Pose``) and ``color_sensor``
  (``turtlesim/msg/Color``), published at every update (62.5 Hz);
- services ``set_pen``, ``teleport_absolute``, ``teleport_relative``;
- the action ``rotate_absolute`` (``turtlesim/action/RotateAbsolute``): turns
  at 1 rad/s until within 0.02 rad of the goal, with feedback at every
  update; a new goal or a ``cmd_vel`` aborts it; cancel is honoured.

One addition for viewers: the hidden topic ``~/_trails``
(``/turtlesim/_trails``, ``std_msgs/msg/UInt8MultiArray``; ``ros2 topic
list`` hides it as it hides every name with a ``_`` token) carries the pen
trails as compact packets (see ``turtlesim_world.decode_trails``): the new
segments after every update that drew some, and the whole canvas after
``clear``/``reset`` or when a viewer publishes ``std_msgs/msg/Empty`` on
``~/_trails_request``. The browser's Turtlesim tab draws from it.

All topics are reliable, keep-last 7, as upstream. Everything runs on one
thread (a single-threaded executor): service and topic callbacks change the
world between two updates, exactly as upstream's ``spin_some`` + update loop.

Try it: ``ros2 run turtlesim turtlesim_node`` in the Console, then
``ros2 topic pub --once /turtle1/cmd_vel geometry_msgs/msg/Twist
"{linear: {x: 2.0}, angular: {z: 1.8}}"``.
"""

from __future__ import annotations

import math
import secrets
import time
from dataclasses import dataclass, field

from geometry_msgs.msg import Twist
from rcl_interfaces.msg import IntegerRange, ParameterDescriptor
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.action.server import ServerGoalHandle
from rclpy.exceptions import InvalidTopicNameException
from rclpy.node import Node
from rclpy.publisher import Publisher
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.service import Service
from rclpy.subscription import Subscription
from rclpy.task import Future
from rclpy.validate_topic_name import validate_topic_name
from std_msgs.msg import Empty as EmptyMsg
from std_msgs.msg import UInt8MultiArray
from std_srvs.srv import Empty
from turtlesim.action import RotateAbsolute
from turtlesim.msg import Color, Pose
from turtlesim.srv import Kill, SetPen, Spawn, TeleportAbsolute, TeleportRelative

from nodes.common.run import spin_node
from nodes.common.turtlesim_world import (
    CENTRE,
    DEFAULT_BACKGROUND,
    UPDATE_PERIOD,
    BadRequest,
    GoalOutcome,
    Rotation,
    RotationUpdate,
    TurtleReport,
    TurtleWorld,
    encode_segments,
    encode_snapshot,
)

# Upstream's topic QoS for every pose, colour and cmd_vel topic.
TOPIC_QOS = QoSProfile(depth=7, reliability=ReliabilityPolicy.RELIABLE)
# Steps run at once after a late timer: 1 s. A loaded machine (dashboard, browser and
# sim on 2 cores) stalls the timer for up to ~250 ms; beyond 1 s, time is let go.
MAX_CATCH_UP = 62
# Trails: reliable, and a late viewer still gets the last packets (a snapshot, if the
# picture has not changed since); 50 packets (0.8 s of updates) ride out a slow reader.
TRAILS_QOS = QoSProfile(
    depth=50, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)
RETIRE_AFTER = 1.0  # seconds a killed turtle's action server lingers to deliver results


def declare_rclcpp_parameters(node: Node) -> None:
    """Declare the read-only QoS-override parameters every rclcpp node of Jazzy has.

    The tutorials' ``ros2 param list`` and ``dump`` outputs show them on the
    C++ turtlesim and teleop nodes; rclpy does not create them (it does create
    ``start_type_description_service`` and ``use_sim_time``), so these two
    Python stand-ins do, with rclcpp's values, to print what the tutorials show.
    """
    fixed = ParameterDescriptor(read_only=True)
    prefix = "qos_overrides./parameter_events.publisher."
    for name, value in (
        ("depth", 1000),
        ("durability", "volatile"),
        ("history", "keep_last"),
        ("reliability", "reliable"),
    ):
        node.declare_parameter(prefix + name, value, fixed)


@dataclass
class TurtleInterfaces:
    """The topics, services and action of one turtle; destroyed when it dies."""

    pose: Publisher
    color: Publisher
    cmd_vel: Subscription
    action: ActionServer
    services: list[Service] = field(default_factory=list)


class Turtlesim(Node):
    def __init__(self) -> None:
        super().__init__("turtlesim")
        channel_range = IntegerRange(from_value=0, to_value=255, step=1)
        for channel, default in zip("rgb", DEFAULT_BACKGROUND, strict=True):
            name = {"r": "Red", "g": "Green", "b": "Blue"}[channel]
            self.declare_parameter(
                f"background_{channel}",
                default,
                ParameterDescriptor(
                    description=f"{name} channel of the background color",
                    integer_range=[channel_range],
                ),
            )
        self.declare_parameter(
            "holonomic",
            False,
            ParameterDescriptor(description="If true, then turtles will be holonomic"),
        )
        declare_rclcpp_parameters(self)

        self.world = TurtleWorld()
        self.interfaces: dict[str, TurtleInterfaces] = {}
        # Running rotate_absolute goals: goal id -> (turtle, handle, result future).
        self.goals: dict[object, tuple[str, ServerGoalHandle, Future]] = {}
        # Action servers of killed turtles: (destroy after, server). A turtle spawned
        # again under the same name (as /reset does) takes its old server back, so
        # two servers never answer one action name.
        self.retired: dict[str, tuple[float, ActionServer]] = {}

        # Trails for viewers: a random session tells a restarted sim from the old one.
        self.trails_session = secrets.randbits(32)
        self.trails_sent = 0  # the world's segment_count at the last packet
        self.trails = self.create_publisher(UInt8MultiArray, "~/_trails", TRAILS_QOS)
        self.trails_requests = self.create_subscription(
            EmptyMsg, "~/_trails_request", lambda _msg: self.publish_snapshot(), 10
        )
        self.create_service(Empty, "clear", self.on_clear)
        self.create_service(Empty, "reset", self.on_reset)
        self.create_service(Spawn, "spawn", self.on_spawn)
        self.create_service(Kill, "kill", self.on_kill)
        self.get_logger().info(
            f"Starting turtlesim with node name {self.get_fully_qualified_name()}"
        )
        self.spawn_turtle("", CENTRE, CENTRE, 0.0)
        self.next_step = time.monotonic() + UPDATE_PERIOD
        self.timer = self.create_timer(UPDATE_PERIOD, self.on_update)
        self.publish_snapshot()  # kept for viewers that join later (transient local)

    # -- time and parameters ---------------------------------------------------

    def now(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    # -- turtles come and go -----------------------------------------------------

    def spawn_turtle(self, name: str, x: float, y: float, theta: float) -> str | None:
        real_name = self.world.spawn(name, x, y, theta, self.now())
        if real_name is None:
            return None
        self.interfaces[real_name] = self.make_interfaces(real_name)
        self.get_logger().info(
            f"Spawning turtle [{real_name}] at x=[{x:f}], y=[{y:f}], theta=[{theta:f}]"
        )
        return real_name

    def make_interfaces(self, name: str) -> TurtleInterfaces:
        _deadline, action = self.retired.pop(name, (0.0, None))
        if action is None:
            action = ActionServer(
                self,
                RotateAbsolute,
                f"{name}/rotate_absolute",
                execute_callback=self.execute_rotation,
                goal_callback=lambda goal: (
                    GoalResponse.ACCEPT
                    if name in self.world.turtles and math.isfinite(goal.theta)
                    else GoalResponse.REJECT
                ),
                handle_accepted_callback=lambda handle: self.on_rotation_accepted(name, handle),
                cancel_callback=lambda _handle: CancelResponse.ACCEPT,
            )
        return TurtleInterfaces(
            pose=self.create_publisher(Pose, f"{name}/pose", TOPIC_QOS),
            color=self.create_publisher(Color, f"{name}/color_sensor", TOPIC_QOS),
            cmd_vel=self.create_subscription(
                Twist, f"{name}/cmd_vel", lambda msg: self.on_cmd_vel(name, msg), TOPIC_QOS
            ),
            services=[
                self.create_service(
                    SetPen, f"{name}/set_pen", lambda req, res: self.on_set_pen(name, req, res)
                ),
                self.create_service(
                    TeleportRelative,
                    f"{name}/teleport_relative",
                    lambda req, res: self.on_teleport_relative(name, req, res),
                ),
                self.create_service(
                    TeleportAbsolute,
                    f"{name}/teleport_absolute",
                    lambda req, res: self.on_teleport_absolute(name, req, res),
                ),
            ],
            action=action,
        )

    def remove_interfaces(self, name: str) -> None:
        parts = self.interfaces.pop(name)
        self.destroy_publisher(parts.pose)
        self.destroy_publisher(parts.color)
        self.destroy_subscription(parts.cmd_vel)
        for service in parts.services:
            self.destroy_service(service)
        # Its goals were just ended: let the server send their results, then destroy it.
        self.retired[name] = (time.monotonic() + RETIRE_AFTER, parts.action)

    def end_goal(self, rotation: Rotation | None, outcome: GoalOutcome) -> None:
        if rotation is not None:
            self.finish_goal(RotationUpdate(rotation.goal_id, 0.0, rotation.delta, outcome))

    # -- global services ---------------------------------------------------------

    def on_clear(self, _request: Empty.Request, response: Empty.Response) -> Empty.Response:
        self.get_logger().info("Clearing turtlesim.")
        self.world.clear()
        self.publish_snapshot()
        return response

    def on_reset(self, _request: Empty.Request, response: Empty.Response) -> Empty.Response:
        self.get_logger().info("Resetting turtlesim.")
        for rotation in self.world.reset(self.now()):
            self.end_goal(rotation, GoalOutcome.ABORTED)
        for name in list(self.interfaces):
            self.remove_interfaces(name)
        # The world respawned turtle1 already; give it its topics and services.
        for name, turtle in self.world.turtles.items():
            self.interfaces[name] = self.make_interfaces(name)
            self.get_logger().info(
                f"Spawning turtle [{name}] at x=[{turtle.x:f}], y=[{turtle.y:f}], "
                f"theta=[{turtle.theta:f}]"
            )
        self.publish_snapshot()
        return response

    def on_spawn(self, request: Spawn.Request, response: Spawn.Response) -> Spawn.Response:
        # rclcpp would end the node on a name ROS cannot use; we refuse it instead.
        try:
            if request.name:
                validate_topic_name(f"{request.name}/pose")
            name = self.spawn_turtle(request.name, request.x, request.y, request.theta)
        except (InvalidTopicNameException, BadRequest) as exc:
            self.get_logger().error(f"Cannot spawn a turtle named [{request.name}]: {exc}")
            return response
        if name is None:
            # rclcpp ignores the callback's "false": the client gets an empty name.
            self.get_logger().error(f"A turtle named [{request.name}] already exists")
            return response
        response.name = name
        return response

    def on_kill(self, request: Kill.Request, response: Kill.Response) -> Kill.Response:
        turtle = self.world.kill(request.name)
        if turtle is None:
            self.get_logger().error(f"Tried to kill turtle [{request.name}], which does not exist")
            return response
        self.end_goal(turtle.rotation, GoalOutcome.ABORTED)
        self.remove_interfaces(request.name)
        return response

    # -- per-turtle callbacks ----------------------------------------------------

    def on_cmd_vel(self, name: str, msg: Twist) -> None:
        if name not in self.world.turtles:
            return
        holonomic = bool(self.get_parameter("holonomic").value)
        # Steps that fell due before this command (a late timer) move with the
        # velocity the turtle had then; run them first, or a 1 s command moves
        # the turtle for 1 s plus the timer's delay (CI: 1.12 m, not 1 m).
        self.catch_up()
        try:
            aborted = self.world.command_velocity(
                name, msg.linear.x, msg.linear.y, msg.angular.z, self.now(), holonomic
            )
        except BadRequest as exc:
            self.get_logger().warn(f"Ignoring {name}/{exc}")
            return
        if aborted is not None:
            self.get_logger().warn("Velocity command received during rotation goal. Aborting goal")
            self.end_goal(aborted, GoalOutcome.ABORTED)

    def on_set_pen(self, name: str, req: SetPen.Request, res: SetPen.Response) -> SetPen.Response:
        if name in self.world.turtles:
            self.world.set_pen(name, req.r, req.g, req.b, req.width, req.off)
        return res

    def on_teleport_relative(
        self, name: str, req: TeleportRelative.Request, res: TeleportRelative.Response
    ) -> TeleportRelative.Response:
        try:
            if name in self.world.turtles:
                self.world.teleport_relative(name, req.linear, req.angular)
        except BadRequest as exc:
            self.get_logger().error(f"Ignoring {name}/{exc}")
        return res

    def on_teleport_absolute(
        self, name: str, req: TeleportAbsolute.Request, res: TeleportAbsolute.Response
    ) -> TeleportAbsolute.Response:
        try:
            if name in self.world.turtles:
                self.world.teleport_absolute(name, req.x, req.y, req.theta)
        except BadRequest as exc:
            self.get_logger().error(f"Ignoring {name}/{exc}")
        return res

    # -- the rotate_absolute action ------------------------------------------------

    def on_rotation_accepted(self, name: str, handle: ServerGoalHandle) -> None:
        goal_id = bytes(handle.goal_id.uuid)
        self.goals[goal_id] = (name, handle, Future())
        handle.execute()  # executing from now on, so a newer goal can abort it
        if name not in self.world.turtles:  # killed between the request and now
            self.finish_goal(RotationUpdate(goal_id, 0.0, 0.0, GoalOutcome.ABORTED))
            return
        previous = self.world.start_rotation(name, goal_id, handle.request.theta)
        if previous is not None:
            self.get_logger().warn(
                "Rotation goal received before a previous goal finished. Aborting previous goal"
            )
            self.end_goal(previous, GoalOutcome.ABORTED)

    async def execute_rotation(self, handle: ServerGoalHandle) -> RotateAbsolute.Result:
        """Waits for the update loop to end the goal; the loop sends feedback meanwhile."""
        entry = self.goals.get(bytes(handle.goal_id.uuid))
        if entry is None:
            return RotateAbsolute.Result()
        return await entry[2]

    def finish_goal(self, update: RotationUpdate) -> None:
        entry = self.goals.pop(update.goal_id, None)
        if entry is None:
            return
        _name, handle, result_future = entry
        result = RotateAbsolute.Result(delta=float(update.delta))
        if handle.is_active:
            if update.outcome is GoalOutcome.SUCCEEDED:
                self.get_logger().info("Rotation goal completed successfully")
                handle.succeed()
            elif update.outcome is GoalOutcome.CANCELED and handle.is_cancel_requested:
                self.get_logger().info("Rotation goal canceled")
                handle.canceled()
            else:
                handle.abort()
        result_future.set_result(result)

    # -- the 16 ms update ----------------------------------------------------------

    def on_update(self) -> None:
        self.catch_up()
        self.destroy_retired()

    def catch_up(self) -> None:
        """Run every 16 ms step that is due: one, or a few after a late timer.

        Under load a timer fires late and rcl skips the periods it missed, so
        one step per call would slow the turtles and the pose rate. Each due
        step runs at the clock time it was due (for the 1 s command timeout).
        """
        mono, ros_now = time.monotonic(), self.now()
        if mono - self.next_step > MAX_CATCH_UP * UPDATE_PERIOD:  # stalled: do not race
            self.next_step = mono
        while self.next_step <= mono:
            self.step_world(ros_now - (mono - self.next_step))
            self.next_step += UPDATE_PERIOD

    def step_world(self, now: float) -> None:
        for goal_id, (name, handle, _future) in list(self.goals.items()):
            if handle.is_cancel_requested:
                self.world.cancel_rotation(name, goal_id)
        for report in self.world.step(now):
            self.publish(report)
        self.publish_new_segments()

    def publish(self, report: TurtleReport) -> None:
        parts = self.interfaces.get(report.name)
        if parts is None:
            return
        if report.wall_hit is not None:
            self.get_logger().warn(report.wall_hit.message())
        if report.rotation is not None:
            entry = self.goals.get(report.rotation.goal_id)
            if entry is not None and report.rotation.outcome is not GoalOutcome.CANCELED:
                feedback = RotateAbsolute.Feedback(remaining=float(report.rotation.remaining))
                entry[1].publish_feedback(feedback)
            if report.rotation.outcome is not None:
                self.finish_goal(report.rotation)
        parts.pose.publish(
            Pose(
                x=float(report.x),
                y=float(report.y),
                theta=float(report.theta),
                linear_velocity=float(report.linear_velocity),
                angular_velocity=float(report.angular_velocity),
            )
        )
        r, g, b = report.color
        parts.color.publish(Color(r=r, g=g, b=b))

    # -- trails for viewers ----------------------------------------------------------

    def publish_new_segments(self) -> None:
        count = self.world.segment_count
        if count == self.trails_sent:
            return
        segments = self.world.segments_since(self.trails_sent)
        data = encode_segments(
            self.trails_session, self.world.clear_count, count - len(segments), segments
        )
        self.trails.publish(UInt8MultiArray(data=data))
        self.trails_sent = count

    def publish_snapshot(self) -> None:
        """The whole picture; segments sent after it continue from its index."""
        self.trails.publish(UInt8MultiArray(data=encode_snapshot(self.trails_session, self.world)))
        self.trails_sent = self.world.segment_count

    def destroy_retired(self) -> None:
        if not self.retired:
            return
        now = time.monotonic()
        for name in [n for n, (deadline, _server) in self.retired.items() if deadline <= now]:
            self.retired.pop(name)[1].destroy()


def main(args=None) -> None:
    spin_node(Turtlesim, args)


if __name__ == "__main__":
    main()

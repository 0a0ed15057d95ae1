"""rviz's "2D Pose Estimate" and "Nav2 Goal" tools: two clicks on the floor of the 3D view.

Press a tool's button, click the floor where the robot is (or should go),
then click again in the direction it faces (or should face): the heading runs
from the first point towards the second (rviz presses and drags; viser sends
clicks, so here it is two clicks). The floor is the plane z = 0 of the
``map`` frame where TF puts it in the Fixed Frame; while ``map`` is not on TF
yet (amcl sends map -> odom only once it knows where the robot is) the
view's origin stands for it, which is where the Map row draws the map then.

- 2D Pose Estimate publishes ``geometry_msgs/PoseWithCovarianceStamped`` on
  ``/initialpose`` in ``map``, with rviz's covariance (x and y 0.25 m², yaw
  (pi/12)² = 0.0685 rad²): amcl spreads its particles around it.
- Nav2 Goal sends ``nav2_msgs/action/NavigateToPose`` to
  ``/navigate_to_pose`` (the navigator): the note follows its feedback
  (distance remaining) to its result. Cancel stops it.

The note shows the equivalent ``ros2`` command each time.

Threads (see ``app.ui``): button presses post intents; viser's scene click
callback (its thread pool) only posts the ray; the rclpy futures' done
callbacks (the executor thread) only post what came. All state belongs to the
UI thread, and nothing here waits on ROS.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
import viser
from action_msgs.msg import GoalStatus
from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped
from nav2_msgs.action import NavigateToPose
from rclpy.node import Node
from rclpy.task import Future

from app.ros.action_client import FeedbackMessage, ThreadSafeActionClient
from app.scene.tf_view import TF_PATH, scene_name
from app.ui import MarkdownView, code_block
from app.ui.loop import UiLoop

if TYPE_CHECKING:
    import numpy.typing as npt
    from builtin_interfaces.msg import Time
    from rclpy.action.client import ClientGoalHandle

MAP_FRAME = "map"
INITIAL_POSE_TOPIC = "/initialpose"
NAVIGATE_ACTION = "/navigate_to_pose"
# rviz2's InitialPoseTool: covariance[6*0+0] = covariance[6*1+1] = 0.25 (0.5 m std dev),
# covariance[6*5+5] = (pi/12)^2 (15 degrees).
COVARIANCE_XY = 0.25
COVARIANCE_YAW = (math.pi / 12.0) ** 2
SAME_POINT = 0.01  # m: a second click this close to the first gives no heading: face +x
ESTIMATE, GOAL = "2D Pose Estimate", "Nav2 Goal"
COLOURS = {ESTIMATE: (255, 140, 0), GOAL: (220, 40, 200)}  # apart from the green particles
ARROW_LENGTH = 0.5  # m: the pose set, drawn on the floor
LIFT = 0.06
STATUS_NAMES = {
    GoalStatus.STATUS_SUCCEEDED: "SUCCEEDED",
    GoalStatus.STATUS_CANCELED: "CANCELED",
    GoalStatus.STATUS_ABORTED: "ABORTED",
}
HELP = (
    "As rviz's toolbar: press a tool, **click the floor** where the robot is (or should "
    "go), then **click again** in the direction it faces. **2D Pose Estimate** tells "
    "amcl where the robot is (`/initialpose`); **Nav2 Goal** sends the robot there "
    "(`/navigate_to_pose`)."
)


# --- pure geometry and messages (no ROS graph, no browser) ---
def floor_point(
    origin: npt.ArrayLike, direction: npt.ArrayLike, frame_pose: np.ndarray | None = None
) -> tuple[float, float] | None:
    """Where a click's ray meets the floor (z = 0) of a frame, in that frame's x, y; or None.

    ``frame_pose``: the frame's 4x4 pose in the view (None: the view's own
    origin). None when the ray runs along the floor or points away from it.
    """
    pose = np.eye(4) if frame_pose is None else np.asarray(frame_pose, np.float64)
    o = np.asarray(origin, np.float64).reshape(3)
    d = np.asarray(direction, np.float64).reshape(3)
    if not (np.isfinite(o).all() and np.isfinite(d).all()) or float(np.linalg.norm(d)) == 0.0:
        return None
    rotation, translation = pose[:3, :3], pose[:3, 3]
    o_local = rotation.T @ (o - translation)  # the ray in the frame's own axes
    d_local = rotation.T @ d
    if abs(d_local[2]) < 1e-9 * float(np.linalg.norm(d_local)):
        return None  # along the floor: it never meets it
    t = -o_local[2] / d_local[2]
    if t <= 0.0:
        return None  # the floor is behind the ray (a click at the sky)
    hit = o_local + t * d_local
    return float(hit[0]), float(hit[1])


def heading(first: tuple[float, float], second: tuple[float, float]) -> float:
    """The yaw (rad) from the first point towards the second; 0 (+x) if they coincide."""
    dx, dy = second[0] - first[0], second[1] - first[1]
    if math.hypot(dx, dy) < SAME_POINT:
        return 0.0
    return math.atan2(dy, dx)


def yaw_quaternion(yaw: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a turn about z, as ROS orders them."""
    return 0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0)


def initial_pose(
    x: float, y: float, yaw: float, frame: str = MAP_FRAME, stamp: Time | None = None
) -> PoseWithCovarianceStamped:
    """The message rviz's 2D Pose Estimate publishes."""
    msg = PoseWithCovarianceStamped()
    msg.header.frame_id = frame
    if stamp is not None:
        msg.header.stamp = stamp
    msg.pose.pose.position.x, msg.pose.pose.position.y = float(x), float(y)
    q = msg.pose.pose.orientation
    q.x, q.y, q.z, q.w = yaw_quaternion(yaw)
    covariance = [0.0] * 36
    covariance[0] = covariance[7] = COVARIANCE_XY
    covariance[35] = COVARIANCE_YAW
    msg.pose.covariance = covariance
    return msg


def navigation_goal(
    x: float, y: float, yaw: float, frame: str = MAP_FRAME, stamp: Time | None = None
) -> NavigateToPose.Goal:
    """A NavigateToPose goal (the default behaviour tree), as rviz's Nav2 Goal sends it."""
    pose = PoseStamped()
    pose.header.frame_id = frame
    if stamp is not None:
        pose.header.stamp = stamp
    pose.pose.position.x, pose.pose.position.y = float(x), float(y)
    q = pose.pose.orientation
    q.x, q.y, q.z, q.w = yaw_quaternion(yaw)
    return NavigateToPose.Goal(pose=pose)


def _pose_yaml(x: float, y: float, yaw: float) -> str:
    _qx, _qy, qz, qw = yaw_quaternion(yaw)
    return (
        f"{{position: {{x: {x:.3f}, y: {y:.3f}, z: 0.0}}, "
        f"orientation: {{x: 0.0, y: 0.0, z: {qz:.4f}, w: {qw:.4f}}}}}"
    )


def initial_pose_command(x: float, y: float, yaw: float, frame: str = MAP_FRAME) -> str:
    covariance = [0.0] * 36
    covariance[0] = covariance[7] = COVARIANCE_XY
    covariance[35] = COVARIANCE_YAW
    numbers = ", ".join(f"{v:.4g}" for v in covariance)
    return (
        f"ros2 topic pub --once {INITIAL_POSE_TOPIC} geometry_msgs/msg/PoseWithCovarianceStamped "
        f"'{{header: {{frame_id: {frame}}}, pose: {{pose: {_pose_yaml(x, y, yaw)}, "
        f"covariance: [{numbers}]}}}}'"
    )


def goal_command(x: float, y: float, yaw: float, frame: str = MAP_FRAME) -> str:
    return (
        f"ros2 action send_goal {NAVIGATE_ACTION} nav2_msgs/action/NavigateToPose "
        f"'{{pose: {{header: {{frame_id: {frame}}}, pose: {_pose_yaml(x, y, yaw)}}}}}' --feedback"
    )


def pose_arrow(x: float, y: float, yaw: float, length: float = ARROW_LENGTH) -> np.ndarray:
    """(3, 2, 3) segments of one flat arrow: a shaft and two barbs."""
    c, s = math.cos(yaw), math.sin(yaw)
    tip = (x + c * length, y + s * length)
    segments = [((x, y, LIFT), (tip[0], tip[1], LIFT))]
    for side in (1.0, -1.0):
        back = yaw + math.pi - side * math.radians(28.0)
        end = (tip[0] + math.cos(back) * length * 0.3, tip[1] + math.sin(back) * length * 0.3)
        segments.append(((tip[0], tip[1], LIFT), (end[0], end[1], LIFT)))
    return np.array(segments, np.float32)


def _where(x: float, y: float, yaw: float) -> str:
    return f"x {x:.2f} m, y {y:.2f} m, facing {math.degrees(yaw):.0f}°"


# --- the tools (UI thread) ---
class PoseTools:
    """The 'Navigation' folder's buttons, the clicks on the floor, and what they send."""

    def __init__(
        self,
        gui: viser.GuiApi,
        ui: UiLoop,
        node: Node,
        server: viser.ViserServer,
        frame_pose: Callable[[str], np.ndarray | None],
    ) -> None:
        """``frame_pose(frame)``: that TF frame's 4x4 pose in the Fixed Frame, or None."""
        self._ui = ui
        self._node = node
        self._server = server
        self._frame_pose = frame_pose
        MarkdownView(gui, HELP)
        self._buttons = gui.add_button_group("Tool", [ESTIMATE, GOAL, "Cancel"])
        self.note = MarkdownView(gui)
        self._buttons.on_click(self._on_button)
        self.tool: str | None = None  # armed: waiting for clicks
        self.first: tuple[float, float] | None = None  # the first click's floor point
        self._listening = False
        self._publisher: Any = None
        self._client: ThreadSafeActionClient | None = None
        self._goal_handle: ClientGoalHandle | None = None
        self._goal_seq = 0  # the goal the note follows; answers for older ones are dropped
        self._goal_text = ""
        self._command = ""
        self.sent: list[tuple[str, float, float, float]] = []  # (tool, x, y, yaw), newest last
        self._marks: dict[str, viser.SceneNodeHandle] = {}

    # --- viser's threads: post, nothing else ---
    def _on_button(self, event: viser.GuiEvent) -> None:
        label = str(event.target.value)
        self._ui.post(lambda: self.press(label))

    def _on_scene_click(self, event: viser.SceneClickEvent) -> None:
        origin, direction = tuple(event.ray_origin), tuple(event.ray_direction)
        self._ui.post(lambda: self.clicked(origin, direction))

    # --- UI thread ---
    def press(self, label: str) -> None:
        """A tool's button (or Cancel) was pressed."""
        if label not in (ESTIMATE, GOAL):
            self._cancel()
            return
        self.tool, self.first = label, None
        self._remove_mark("first")
        if label == ESTIMATE and self._publisher is None:
            self._publisher = self._node.create_publisher(
                PoseWithCovarianceStamped, INITIAL_POSE_TOPIC, 10
            )
        if label == GOAL and self._client is None:  # made now: found by the time of the clicks
            self._client = ThreadSafeActionClient(self._node, NavigateToPose, NAVIGATE_ACTION)
        self._listen(True)
        self._show(
            f"**{label}**: click the floor where the robot "
            + ("is." if label == ESTIMATE else "should go.")
            + self._frame_warning()
        )

    def clicked(self, origin: npt.ArrayLike, direction: npt.ArrayLike) -> None:
        """A click in the 3D view while a tool is armed: a point, then a heading."""
        tool = self.tool
        if tool is None:
            return
        point = floor_point(origin, direction, self._frame_pose(MAP_FRAME))
        if point is None:
            self._show(
                f"⚠️ **{tool}**: that click missed the floor of `{MAP_FRAME}` (it points at the "
                "sky or along the floor). Click on the floor, below the horizon."
            )
            return
        if self.first is None:
            self.first = point
            self._mark_first(tool, point)
            self._show(
                f"**{tool}**: at x {point[0]:.2f} m, y {point[1]:.2f} m. Now click in the "
                "direction the robot " + ("faces." if tool == ESTIMATE else "should face.")
            )
            return
        x, y = self.first
        yaw = heading(self.first, point)
        self.tool, self.first = None, None
        self._listen(False)
        self._remove_mark("first")
        self._draw_arrow(tool, x, y, yaw)
        self.sent.append((tool, x, y, yaw))
        if tool == ESTIMATE:
            self._publish_estimate(x, y, yaw)
        else:
            self._send_goal(x, y, yaw)

    def _frame_warning(self) -> str:
        if self._frame_pose(MAP_FRAME) is not None:
            return ""
        return (
            f"\n\n⚠️ Frame `{MAP_FRAME}` is not on TF yet: the view's origin stands for it "
            "(where the Map row draws the map until then)."
        )

    def _publish_estimate(self, x: float, y: float, yaw: float) -> None:
        stamp = self._node.get_clock().now().to_msg()
        self._publisher.publish(initial_pose(x, y, yaw, stamp=stamp))
        self._command = initial_pose_command(x, y, yaw)
        self._show(
            f"✅ Published the robot's pose on `{INITIAL_POSE_TOPIC}` in `{MAP_FRAME}`: "
            f"{_where(x, y, yaw)}; amcl spreads its particles around it." + self._frame_warning()
        )

    def _send_goal(self, x: float, y: float, yaw: float) -> None:
        client = self._client
        self._command = goal_command(x, y, yaw)
        self._goal_seq += 1
        seq = self._goal_seq
        self._goal_handle = None
        if client is None or not client.server_is_ready():
            self._goal_text = (
                f"⚠️ No action server on `{NAVIGATE_ACTION}`: start the launch group "
                "**office_navigation** in the **Nodes** tab (the navigator serves it)."
            )
            self._show(self._goal_text)
            return
        stamp = self._node.get_clock().now().to_msg()
        goal = navigation_goal(x, y, yaw, stamp=stamp)
        where = _where(x, y, yaw)
        self._goal_text = f"🚩 Goal sent ({where}); waiting for the navigator to accept it."
        self._show(self._goal_text)

        def feedback(message: FeedbackMessage) -> None:  # executor thread
            fb: NavigateToPose.Feedback = message.feedback
            distance = float(fb.distance_remaining)
            recoveries = int(fb.number_of_recoveries)
            self._ui.post(lambda: self._on_feedback(seq, where, distance, recoveries))

        future = client.send_goal_async(goal, feedback_callback=feedback)
        future.add_done_callback(lambda f: self._ui.post(lambda: self._on_answer(seq, where, f)))

    def _on_answer(self, seq: int, where: str, future: Future) -> None:
        if seq != self._goal_seq:
            return
        try:
            handle = future.result()
        except Exception as exc:  # the request failed: say so, never raise
            self._goal_text = f"⚠️ The goal could not be sent: {exc}"
            self._show(self._goal_text)
            return
        if handle is None or not handle.accepted:
            self._goal_text = f"❌ The navigator rejected the goal ({where})."
            self._show(self._goal_text)
            return
        self._goal_handle = handle
        if self._goal_text.startswith("🚩 Goal sent"):
            self._goal_text = f"🚩 Goal accepted ({where}): the robot is on its way."
            self._show(self._goal_text)
        result = handle.get_result_async()
        result.add_done_callback(lambda f: self._ui.post(lambda: self._on_result(seq, where, f)))

    def _on_feedback(self, seq: int, where: str, distance: float, recoveries: int) -> None:
        if seq != self._goal_seq or self._goal_text.startswith(("✅", "❌", "⏹")):
            return
        self._goal_text = f"🚩 Navigating ({where}): **{distance:.2f} m** to go" + (
            f", {recoveries} recoveries" if recoveries else ""
        )
        self._show(self._goal_text)

    def _on_result(self, seq: int, where: str, future: Future) -> None:
        if seq != self._goal_seq:
            return
        self._goal_handle = None
        try:
            response: NavigateToPose.Impl.GetResultService.Response = future.result()
        except Exception as exc:
            self._goal_text = f"⚠️ No result came: {exc}"
            self._show(self._goal_text)
            return
        status = STATUS_NAMES.get(response.status, str(response.status))
        result = response.result
        code = int(getattr(result, "error_code", 0))
        detail = f" (error_code {code}: {result.error_msg or 'no message'})" if code else ""
        if response.status == GoalStatus.STATUS_SUCCEEDED:
            self._goal_text = f"✅ Goal reached ({where}): SUCCEEDED."
        elif response.status == GoalStatus.STATUS_CANCELED:
            self._goal_text = f"⏹ Goal canceled ({where}): CANCELED{detail}."
        else:
            self._goal_text = f"❌ Goal not reached ({where}): {status}{detail}."
        self._show(self._goal_text)

    def _cancel(self) -> None:
        was_picking = self.tool is not None
        self.tool, self.first = None, None
        self._listen(False)
        self._remove_mark("first")
        handle = self._goal_handle
        if handle is not None:
            handle.cancel_goal_async()  # the result (CANCELED) arrives as any other
            self._goal_text = "⏹ Canceling the goal..."
            self._show(self._goal_text)
        elif was_picking:
            self._show("Canceled: no pose was sent.")

    def _listen(self, on: bool) -> None:
        """Ask every browser for its clicks on the scene only while a tool is armed."""
        if on == self._listening:
            return
        self._listening = on
        if on:
            self._server.scene.on_click()(self._on_scene_click)
        else:
            self._server.scene.remove_click_callback(self._on_scene_click)

    def _show(self, text: str) -> None:
        command = f"\n\nThe same from a terminal:\n\n{code_block([self._command])}"
        self.note.show(text + (command if self._command else ""))

    # --- the marks on the floor ---
    def _parent(self) -> str:
        return f"{TF_PATH}/frames/{scene_name(MAP_FRAME)}/pose_tools"

    def _mark_first(self, tool: str, point: tuple[float, float]) -> None:
        self._marks["first"] = self._server.scene.add_icosphere(
            f"{self._parent()}/first",
            radius=0.06,
            color=COLOURS[tool],
            position=(point[0], point[1], LIFT),
            cast_shadow=False,
            receive_shadow=False,
        )

    def _draw_arrow(self, tool: str, x: float, y: float, yaw: float) -> None:
        key = "estimate" if tool == ESTIMATE else "goal"
        self._marks[key] = self._server.scene.add_line_segments(
            f"{self._parent()}/{key}",
            pose_arrow(x, y, yaw),
            COLOURS[tool],
            thickness=5.0,
            thickness_units="screen",
        )

    def _remove_mark(self, key: str) -> None:
        handle = self._marks.pop(key, None)
        if handle is not None:
            handle.remove()

    def close(self) -> None:
        self._listen(False)
        for key in list(self._marks):
            self._remove_mark(key)
        if self._client is not None:
            self._client.destroy()
        if self._publisher is not None:
            self._node.destroy_publisher(self._publisher)

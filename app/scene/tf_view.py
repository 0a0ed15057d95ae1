"""TF frames and the robot of /robot_description in the 3D view, as rviz's TF and RobotModel.

Every frame on ``/tf`` and ``/tf_static`` is drawn with its axes and name at
its pose in the Fixed Frame (chosen by the learner; until then the root of
the biggest tree). The robot described on ``/robot_description`` is drawn
link by link from its URDF, each link at its TF frame, so it moves as
robot_state_publisher publishes. A dynamic frame whose publisher falls
silent is shown stale. Bad input (a description that does not parse, a
NaN or zero-length quaternion, a loop of frames) is one line in the status
and in the log; nothing is drawn from it and nothing stops.

Threads: /tf and /tf_static come from the dashboard's one TF reader
(``app.ros.tf_sources``, shared with the TF panel), whose thread only
stores the transforms; the /robot_description callback (executor) drops the
text into a one-slot box; a drawing thread of this layer parses
descriptions and moves scene nodes, at most ``MAX_HZ`` times a second.
"""

from __future__ import annotations

import logging
import threading
import time

import numpy as np
import viser
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from robot_state_publisher.urdf_tree import UrdfError
from std_msgs.msg import String
from tf2_ros._wire import Entry

from app.ros import tf_sources
from app.scene import transforms as tf
from app.scene.qos import SCENE_CALLBACK_GROUP
from app.scene.robot_model import RobotDrawing, SliderJoint, build_drawing
from app.scene.tf_tree import TfStore, TreeView

log = logging.getLogger(__name__)

TF_PATH = "/tf_view"
MAX_HZ = 30.0  # as the other layers; poses that did not change are not resent
AXES_LENGTH = 0.08
DESCRIPTION_QOS = QoSProfile(
    depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE
)


def scene_name(frame: str) -> str:
    """A TF frame name as one scene-path segment (a '/' inside would nest nodes)."""
    return frame.replace("/", "__") or "_"


class TfView:
    def __init__(self, node: Node, server: viser.ViserServer) -> None:
        self._server = server
        self.store = TfStore()
        self.fixed_frame = ""  # "" until the learner picks one: follow the biggest tree
        self.show_names = True  # rviz's TF display: Show Names
        self.show_axes = True  # ...and Show Axes
        self._restyle = False
        self._lock = threading.Lock()
        self._description: str | None = None
        self._robot: RobotDrawing | None = None
        self.robot_joints: tuple[SliderJoint, ...] = ()  # for the joint sliders (UI thread reads)
        self.robot_status = "No robot on /robot_description yet."
        self.robot_error = ""
        self._frames: dict[str, viser.FrameHandle] = {}
        self._labels: dict[str, viser.LabelHandle] = {}  # while names are shown
        self._axes: viser.BatchedAxesHandle | None = None  # every frame's axes, instanced
        self._axes_count = 0
        # frame -> (position, wxyz) last sent
        self._placed: dict[
            str, tuple[tuple[float, float, float], tuple[float, float, float, float]]
        ] = {}
        self._visuals: list[viser.SceneNodeHandle] = []
        self._logged: set[str] = set()
        self._sent: dict[str, tuple[object, ...]] = {}  # scene path -> pose last sent
        self.view: TreeView | None = None
        self._root = server.scene.add_frame(TF_PATH, show_axes=False)
        self._forget: set[str] | None = None  # frames to drop, handed to the drawing thread
        self._forget_robot = False
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._sources = tf_sources.shared(node)
        self._sources.on_transforms(self._on_transforms)
        self._subscriptions = [
            node.create_subscription(
                String,
                "/robot_description",
                self._on_description,
                DESCRIPTION_QOS,
                callback_group=SCENE_CALLBACK_GROUP,
            ),
        ]
        self._node = node
        self._thread = threading.Thread(target=self._run, name="scene-tf", daemon=True)
        self._thread.start()

    # --- the TF reader's thread, then the executor's: store and hand over, nothing else ---
    def _on_transforms(self, entries: list[Entry], static: bool) -> None:
        for frame_id, child, _stamp, t, q in entries:
            self.store.add(frame_id, child, t, q, static=static)
        self._wake.set()

    def _on_description(self, msg: String) -> None:
        with self._lock:
            self._description = msg.data
        self._wake.set()

    # --- drawing thread ---
    def _run(self) -> None:
        last_version = -1
        last_draw = 0.0
        while not self._stop.is_set():
            self._wake.wait(0.25)  # also wakes to notice frames going stale
            self._wake.clear()
            wait = last_draw + 1.0 / MAX_HZ - time.monotonic()
            if wait > 0 and self._stop.wait(wait):
                break
            with self._lock:
                description, self._description = self._description, None
                forget, self._forget = self._forget, None
                forget_robot, self._forget_robot = self._forget_robot, False
            try:
                if forget is not None:
                    self._drop(forget, forget_robot)
                if description is not None:
                    self._load_robot(description)
                version = self.store.version
                last_draw = time.monotonic()
                restyle, self._restyle = self._restyle, False
                self._draw(force=version != last_version or restyle)
                last_version = version
            except Exception:  # a bad frame must not end the view
                log.exception("drawing TF failed")

    def _load_robot(self, description: str) -> None:
        try:
            drawing = build_drawing(description)
        except UrdfError as exc:
            self.robot_error = f"robot_description: {exc}"
            self._log_once(self.robot_error)
            return
        self.robot_error = ""
        for handle in self._visuals:
            handle.remove()
        self._visuals.clear()
        scene = self._server.scene
        with self._server.atomic():
            for link in drawing.links:
                self._frame(link)  # meshes hang under the link's TF frame: one pose moves both
            for i, visual in enumerate(drawing.visuals):
                self._visuals.append(
                    scene.add_mesh_trimesh(
                        f"{TF_PATH}/frames/{scene_name(visual.link)}/visual{i}", visual.mesh
                    )
                )
        self._robot = drawing
        self.robot_joints = drawing.joints
        shown = len({v.link for v in drawing.visuals})
        note = f" ({'; '.join(drawing.warnings)})" if drawing.warnings else ""
        self.robot_status = (
            f"Robot **{drawing.name}**: {len(drawing.links)} links, {shown} with shapes{note}."
        )
        log.info("robot_description: robot %s with %d links", drawing.name, len(drawing.links))

    def _drop(self, frames: set[str], robot: bool) -> None:
        """Take forgotten frames (and a robot whose publisher left) off the scene."""
        self.store.forget(frames)
        gone = set(self._frames) - set(self.store.frames())
        if robot:
            for handle in self._visuals:
                handle.remove()
            self._visuals.clear()
            self._robot = None
            self.robot_joints = ()
            self.robot_status = "No robot on /robot_description yet."
        with self._server.atomic():
            for frame in gone:
                label = self._labels.pop(frame, None)
                if label is not None:
                    label.remove()
                node = self._frames.pop(frame)
                self._sent.pop(node.name, None)
                self._placed.pop(frame, None)
                node.remove()
        self._logged.clear()

    def _log_once(self, line: str) -> None:
        if line not in self._logged:
            self._logged.add(line)
            log.warning("%s", line)

    def _choose_fixed(self) -> str:
        if self.fixed_frame:
            return self.fixed_frame
        roots = self.store.roots()
        return roots[0] if roots else ""

    def _draw(self, *, force: bool) -> None:
        fixed = self._choose_fixed()
        view = self.store.view(fixed)
        changed_stale = self.view is None or view.stale != self.view.stale
        self.view = view
        for line in list(self.store.errors):
            self._log_once(line)
        if not force and not changed_stale:
            return
        with self._server.atomic():
            for frame in sorted(set(view.poses) | set(view.problems) | set(self._frames)):
                node = self._frame(frame)
                self._place(frame, node, view.poses.get(frame))
                self._name(frame, node, f"{frame} (stale)" if frame in view.stale else frame)
            self._draw_axes(view)

    def _name(self, frame: str, node: viser.FrameHandle, text: str) -> None:
        """The frame's name while names are shown; no label node at all otherwise.

        (A hidden label still costs the page work every frame; a robot's 30
        of them, a third of the scene's nodes, showed in its frame time.)
        """
        label = self._labels.get(frame)
        if not self.show_names:
            if label is not None:
                label.remove()
                del self._labels[frame]
            return
        if label is None:
            self._labels[frame] = self._server.scene.add_label(
                f"{node.name}/name", text, font_screen_scale=0.8
            )
        elif label.text != text:
            label.text = text

    def _draw_axes(self, view: TreeView) -> None:
        """Every frame's axes as one instanced node: one draw call, two messages per update.

        (A frame node each with its own axes cost the browser a draw call per
        axis; with a 30-link robot moving, that halved the page's frame rate.)
        """
        shown = sorted(view.poses) if self.show_axes else []
        if not shown:
            if self._axes is not None:
                self._axes.remove()
                self._axes, self._axes_count = None, 0
            return
        placed = [self._placed[frame] for frame in shown]  # as _place sent them
        positions = np.array([p for p, _q in placed], dtype=np.float32)
        wxyzs = np.array([q for _p, q in placed], dtype=np.float32)
        if self._axes is None or self._axes_count != len(shown):
            if self._axes is not None:
                self._axes.remove()
            self._axes = self._server.scene.add_batched_axes(
                f"{TF_PATH}/axes", wxyzs, positions,
                axes_length=AXES_LENGTH, axes_radius=AXES_LENGTH / 20,
            )  # fmt: skip
            self._axes_count = len(shown)
            return
        self._axes.batched_positions = positions
        self._axes.batched_wxyzs = wxyzs

    def _frame(self, frame: str) -> viser.FrameHandle:
        """The node of a TF frame (its robot shapes and name hang under it), made hidden."""
        node = self._frames.get(frame)
        if node is None:
            path = f"{TF_PATH}/frames/{scene_name(frame)}"
            node = self._server.scene.add_frame(path, show_axes=False, visible=False)
            self._sent[path] = ("hidden",)
            self._frames[frame] = node
        return node

    def _place(self, frame: str, handle: viser.FrameHandle, pose: np.ndarray | None) -> None:
        """Show ``handle`` at ``pose`` (hide it for None), sending only what changed."""
        key = ("hidden",) if pose is None else tuple(np.round(pose[:3, :].ravel(), 6).tolist())
        if self._sent.get(handle.name) == key:
            return
        self._sent[handle.name] = key
        handle.visible = pose is not None
        if pose is not None:
            position, wxyz = tf.as_xyz(pose[:3, 3]), tf.matrix_to_quat(pose[:3, :3])
            handle.position = position
            handle.wxyz = wxyz
            self._placed[frame] = (position, wxyz)

    # --- UI thread ---
    def set_display(self, *, names: bool, axes: bool) -> None:
        """Show or hide the frames' names and axes (the robot's shapes stay)."""
        self.show_names, self.show_axes = names, axes
        self._restyle = True
        self._wake.set()

    def forget_unpublished(self, robot_published: bool) -> None:
        """Forget every frame no running node sends now: whose broadcaster left the graph,
        or a moving frame gone silent (a new lesson starts from what is live). The
        robot's shapes go too unless /robot_description is still published."""
        dropped = {
            info.frame
            for info in self._sources.frames()
            if info.parent and (info.stale or not info.publisher_here)
        }
        with self._lock:
            self._forget = dropped
            self._forget_robot = not robot_published
        self._restyle = True
        self._wake.set()

    def frame_names(self) -> list[str]:
        return self.store.frames()

    def status(self) -> str:
        """One short Markdown paragraph: frames, fixed frame, stale ones, the last problem."""
        view = self.view
        lines = []
        if view is None or not (view.poses or view.problems):
            lines.append("No TF frames yet (nothing on /tf or /tf_static).")
        else:
            lines.append(
                f"{len(view.poses)} frames drawn in Fixed Frame **{view.fixed}**"
                + (f"; {len(view.problems)} not connected to it" if view.problems else "")
                + "."
            )
            if view.fixed and view.fixed not in view.poses:
                lines.append(f"⚠️ Fixed Frame [{view.fixed}] does not exist")
            if view.stale:
                lines.append("Stale (publisher silent): " + ", ".join(sorted(view.stale)) + ".")
            loops = sorted({p for p in view.problems.values() if "loop" in p})
            if loops:
                lines.append("⚠️ " + loops[0])
        if self.store.errors:
            lines.append("⚠️ " + self.store.errors[-1])
        lines.append(("⚠️ " + self.robot_error) if self.robot_error else self.robot_status)
        return "\n\n".join(lines)

    @property
    def robot_drawn(self) -> bool:
        """A robot from /robot_description is on screen: one of its links has a pose."""
        robot, view = self._robot, self.view
        return (
            robot is not None
            and view is not None
            and any(link in view.poses for link in robot.links)
        )

    def poses(self) -> dict[str, np.ndarray]:
        view = self.view
        return dict(view.poses) if view is not None else {}

    def close(self) -> None:
        self._stop.set()
        self._wake.set()
        self._thread.join(timeout=2.0)
        self._sources.remove_sink(self._on_transforms)
        tf_sources.release(self._sources)
        for subscription in self._subscriptions:
            self._node.destroy_subscription(subscription)

"""3D view panel: pick what the scene draws, see how much of it arrives, edit the camera pose.

The scene layers (``app/scene``) draw from their own worker threads; this
panel owns the controls and the status text. Its callbacks post intents, so
layers are switched and the pose is changed on the UI thread only.

While a simulated world (``sim_world``) is drawn, the lesson-13 desk at the
origin (its base_link axes, camera and arm model) steps aside: the robot's
own frames are on TF then, and two base_links would confuse.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
import viser
from rclpy.node import Node

from app.panels.joint_sliders import TOPIC as SLIDER_TOPIC
from app.panels.joint_sliders import JointSliders
from app.ros.graph import GraphSnapshot
from app.scene import topic_picker as picker
from app.scene import transforms as tf
from app.scene.arm import ARM_PATH, ArmLayer
from app.scene.camera_params import CameraParamSync
from app.scene.drive import DriveControls, grown_box, outgrown, overview, padded
from app.scene.frames import CameraPose, FrameTree
from app.scene.images import ImageLayer
from app.scene.laser_scan import LaserScanLayer
from app.scene.markers import MarkerLayer
from app.scene.namespaced_robots import NamespacedRobots
from app.scene.nav_path import PathLayer
from app.scene.occupancy_grid import OccupancyGridLayer
from app.scene.particle_cloud import TYPES as PARTICLE_TYPES
from app.scene.particle_cloud import ParticleCloudLayer
from app.scene.plots import JointPlot
from app.scene.pointclouds import PointCloudLayer
from app.scene.pose_tools import PoseTools
from app.scene.sim_world import TOPICS as WORLD_TOPICS
from app.scene.sim_world import WorldLayer
from app.scene.stamped import StampedLayer
from app.scene.tf_camera import TfCamera
from app.scene.tf_view import TfView
from app.ui import MarkdownView, assign, code_block
from app.ui.loop import UiLoop

INTRO = (
    "The **3D view** draws live topics, as rviz does. Drag to orbit, scroll to zoom. "
    "Axes are red = x, green = y, blue = z."
)


AUTO_FIXED = "(root of the tree)"
# Shown in the middle of the view while it draws nothing at all: a first-week learner on
# a 3D step sees an empty grid otherwise, with no word of what should be there.
EMPTY_HINT = (
    "Nothing to draw yet.\nThis view shows what running nodes publish:\n"
    "press the step's Start button in the lesson, and what it starts appears here."
)


class _Offer(NamedTuple):
    """What a topic dropdown offers: topics of ``types``; it picks ``preferred`` ones first."""

    types: tuple[str, ...]
    hint: str
    preferred: tuple[str, ...]
    avoid: tuple[str, ...] = ()  # never followed by itself (the dashboard's own topics)
    latched: bool = False  # published once and kept (a map): silence is not a problem


CLOUDS = _Offer(picker.CLOUD_TYPES, "sensor_msgs/msg/PointCloud2 topics", ("/cam/map_points",))
IMAGES = _Offer(
    picker.IMAGE_TYPES,
    "sensor_msgs/msg/Image topics",
    ("/object_detection/output", "/camera/image_raw", "/cam/feature_ext_viz"),
)
MARKERS = _Offer(
    picker.MARKER_TYPES,
    "visualization_msgs Marker or MarkerArray topics",
    ("/cam/camera_pose",),
    avoid=WORLD_TOPICS,  # the simulated world is drawn by its own layer, at its TF frame
)
SCANS = _Offer(("sensor_msgs/msg/LaserScan",), "sensor_msgs/msg/LaserScan topics", ("/scan",))
MAPS = _Offer(
    ("nav_msgs/msg/OccupancyGrid",),
    "nav_msgs/msg/OccupancyGrid topics (rviz's Map)",
    ("/map",),
    latched=True,
)
PARTICLES = _Offer(
    PARTICLE_TYPES,
    "nav2_msgs/msg/ParticleCloud or geometry_msgs/msg/PoseArray topics (amcl's guesses)",
    ("/particle_cloud",),
)
PATHS = _Offer(
    ("nav_msgs/msg/Path",),
    "nav_msgs/msg/Path topics (the planner's plan)",
    ("/plan",),
    latched=True,  # a plan comes once per goal: silence after it is normal
)
# Where new browsers start: close to the lesson-13 desk, or over the whole simulated world.
DESK_VIEW = ((0.98, -0.98, 0.85), (0.25, 0.0, 0.25))  # the arm and camera fill the stage
MIN_FRAMES_TO_FRAME = 3  # a robot's links with poses, before the cameras go to it
REFRAME_ROOM_M = 1.0  # at most this much room round a robot's way when the cameras frame it
REFRAME_ROOM_FRACTION = 0.5  # ...and at most this share of the robot's (or its way's) size
REFRAME_ROOM_MIN_M = 0.15
JOINTS = _Offer(
    picker.JOINT_TYPES,
    "sensor_msgs/msg/JointState topics",
    ("/joint_states",),
    avoid=(SLIDER_TOPIC,),
)


class _TopicRow:
    """A dropdown offering only topics of some types, plus a liveness note under it.

    Until the learner picks something, the row follows the first suitable topic
    by itself (``preferred`` names first), so starting a node is enough to see it.
    """

    def __init__(self, gui: viser.GuiApi, label: str, offer: _Offer) -> None:
        self.offer = offer
        self.chosen_by_learner = False
        self.automatic = True  # False: the row waits for the learner's pick
        self._select: Callable[[str], None] = lambda _topic: None
        self._options: tuple[str, ...] = (picker.NONE,)
        # The topic the row follows: its options are built around it (app.scene.picker).
        self.current = picker.NONE
        self.dropdown = gui.add_dropdown(
            label, self._options, initial_value=picker.NONE, hint=offer.hint
        )
        self.note = MarkdownView(gui)

    def on_pick(self, ui: UiLoop, select: Callable[[str], None]) -> None:
        """``select(topic)`` follows a topic: the learner's pick, or our own first choice."""
        self._select = select
        self.dropdown.on_update(ui.callback(self._picked_by_learner))

    def _picked_by_learner(self) -> None:
        self.chosen_by_learner = True
        self.current = self.dropdown.value
        self._select(self.current)

    def follow(self, topic: str) -> None:
        """Show and follow ``topic`` by our own choice (``picker.NONE``: nothing)."""
        self.chosen_by_learner = False
        self.current = topic
        assign(self.dropdown, topic)  # posts no intent
        self._select(topic)

    def refresh_options(self, graph: GraphSnapshot) -> None:
        opts = tuple(picker.options(graph, self.offer.types, self.current))
        if opts != self._options:
            self._options = opts
            self.dropdown.options = opts
        if self.chosen_by_learner or not self.automatic:
            return
        if self.current == picker.NONE and len(opts) > 1:
            choice = next((t for t in self.offer.preferred if t in opts), None)
            if choice is None:
                choice = next((t for t in opts[1:] if t not in self.offer.avoid), None)
            if choice is not None:
                self.follow(choice)


class ScenePanel:
    hidden_work = True  # it draws into the 3D scene, which every page shows (app.ui.Panel)

    def __init__(self, server: viser.ViserServer, ui: UiLoop, node: Node) -> None:
        gui, scene = server.gui, server.scene
        self._server = server
        self._ui = ui
        MarkdownView(gui, INTRO)
        # Start close to the robot: the arm, the camera and a table-top cloud fill the view.
        server.initial_camera.position, server.initial_camera.look_at = DESK_VIEW
        self.frames = FrameTree(scene)
        self.clouds = PointCloudLayer(node, server)
        self.markers = MarkerLayer(node, server)
        self.stamped = StampedLayer(node, server)
        self.tf_view = TfView(node, server)
        self.world = WorldLayer(node, server)
        self.more_robots = NamespacedRobots(node, server)
        self._world_shown = False
        # Where a robot that came has been (its frames' box) and the box the cameras show.
        self._robot_box: tuple[np.ndarray, np.ndarray] | None = None
        self._framed_box: tuple[np.ndarray, np.ndarray] | None = None
        self._desk_shown = (True, True)  # (the desk's frames and arm, its frustum)
        self._light = scene.add_light_ambient("/sim_world_light", intensity=0.9, visible=False)
        self._empty_hint = scene.add_label(
            "/empty_scene_hint",
            EMPTY_HINT,
            position=DESK_VIEW[1],
            anchor="center-center",
            font_screen_scale=1.3,
        )

        with gui.add_folder("Simulated world"):
            self._world_info = MarkdownView(gui)
            self.drive = DriveControls(gui, ui, node, server, self._frame_pose)
            self.drive.world_view = self._world_view
        with gui.add_folder("Laser scan"):
            self._scan_row = _TopicRow(gui, "Scan topic", SCANS)
            self.scan = LaserScanLayer(node, server, self._frame_pose)
            self._scan_info = MarkdownView(gui)
        with gui.add_folder("Map"):
            self._map_row = _TopicRow(gui, "Map topic", MAPS)
            self.map = OccupancyGridLayer(
                node, server, frame_known=lambda frame: frame in self.tf_view.frame_names()
            )
            self._map_info = MarkdownView(gui)
        with gui.add_folder("Particles"):
            self._particle_row = _TopicRow(gui, "Particle topic", PARTICLES)
            self.particles = ParticleCloudLayer(node, server, frame_known=self._frame_known)
            self._particle_info = MarkdownView(gui)
        with gui.add_folder("Path"):
            self._path_row = _TopicRow(gui, "Path topic", PATHS)
            self.path = PathLayer(node, server, frame_known=self._frame_known)
            self._path_info = MarkdownView(gui)
        with gui.add_folder("Navigation"):
            self.pose_tools = PoseTools(gui, ui, node, server, self._frame_pose)

        with gui.add_folder("Point cloud"):
            self._cloud_row = _TopicRow(gui, "Cloud topic", CLOUDS)
            self._budget = gui.add_slider(
                "Point budget",
                min=10_000,
                max=1_000_000,
                step=10_000,
                initial_value=self.clouds.budget,
                hint="Bigger clouds are thinned to this many points before they go to the browser",
            )
            self._cloud_status = MarkdownView(gui)
            self._frame_cloud = gui.add_button(
                "Look at the cloud", icon=viser.Icon.FOCUS_2, hint="Move the 3D camera to it"
            )
        with gui.add_folder("Camera image"):
            self._image_row = _TopicRow(gui, "Image topic", IMAGES)
            self.images = ImageLayer(
                node,
                gui,
                self.frames,
                tf_camera=TfCamera(node, server, lambda: self.tf_view.frame_names()),
            )
            self._image_on_frustum = gui.add_checkbox("Image on the 3D camera", False)
            self._image_info = MarkdownView(gui)
        with gui.add_folder("Markers"):
            self._marker_row = _TopicRow(gui, "Marker topic", MARKERS)
            self._marker_info = MarkdownView(gui)
        with gui.add_folder("Robot arm"):
            self._joint_row = _TopicRow(gui, "Joint topic", JOINTS)
            self.plot = JointPlot(gui)
            self.arm = ArmLayer(node, server, on_joints=self.plot.add)
            self._arm_info = MarkdownView(gui)
        with gui.add_folder("Camera ↔ base transform", expand_by_default=False):
            MarkdownView(
                gui,
                "Where the camera sits on the robot. Points seen by the camera are moved "
                "into `base_link` by this 4×4 matrix: **p_base = T · p_camera**.",
            )
            self._gizmo = gui.add_checkbox("Edit with a gizmo in 3D", False)
            pose = self.frames.pose
            self._sliders = {
                "x": gui.add_slider("x (m)", -1.0, 1.0, 0.01, pose.x),
                "y": gui.add_slider("y (m)", -1.0, 1.0, 0.01, pose.y),
                "z": gui.add_slider("z (m)", 0.0, 1.5, 0.01, pose.z),
                "roll": gui.add_slider("roll (°)", -180.0, 180.0, 1.0, math.degrees(pose.roll)),
                "pitch": gui.add_slider("pitch (°)", -90.0, 90.0, 1.0, math.degrees(pose.pitch)),
                "yaw": gui.add_slider("yaw (°)", -180.0, 180.0, 1.0, math.degrees(pose.yaw)),
            }
            self._matrix = MarkdownView(gui)
            self._param_status = MarkdownView(gui)
        self._stamped_info = MarkdownView(gui)
        # The snapshot the texts were last made from: a new one comes with each full pass of
        # the UI loop (once a second idle, every pass after a click).
        self._texts_from: GraphSnapshot | None = None
        with gui.add_folder("TF and robot model"):
            MarkdownView(
                gui,
                "Every frame on `/tf` and `/tf_static` with its axes and name, and the robot "
                "described on `/robot_description` drawn from its URDF, as rviz shows them.",
            )
            self._fixed_options: tuple[str, ...] = (AUTO_FIXED,)
            self._fixed = gui.add_dropdown(
                "Fixed Frame",
                self._fixed_options,
                initial_value=AUTO_FIXED,
                hint="The frame everything is drawn relative to (rviz's Global Options)",
            )
            self._frame_names = gui.add_checkbox("Frame names", True)
            self._frame_axes = gui.add_checkbox("Frame axes", True)
            self._tf_status = MarkdownView(gui)
        self.joint_sliders = JointSliders(gui, ui, node)
        self._rows = (
            self._cloud_row, self._scan_row, self._map_row, self._particle_row,
            self._path_row, self._image_row, self._marker_row, self._joint_row,
        )  # fmt: skip

        self.params = CameraParamSync(node)
        self._wire()
        self._show_matrix(self.frames.pose)

    def _wire(self) -> None:
        ui = self._ui
        self._cloud_row.on_pick(ui, self.clouds.select)
        self._scan_row.on_pick(ui, self.scan.select)
        self._map_row.on_pick(ui, self.map.select)
        self._particle_row.on_pick(ui, self.particles.select)
        self._path_row.on_pick(ui, self.path.select)
        self._image_row.on_pick(ui, self.images.select)
        self._marker_row.on_pick(ui, self.markers.select)
        self._joint_row.on_pick(ui, self._select_joints)
        self._frame_cloud.on_click(ui.callback(self._look_at_cloud))
        self._budget.on_update(ui.callback(self._apply_budget))
        self._fixed.on_update(ui.callback(self._on_fixed_frame))
        self._frame_names.on_update(ui.callback(self._on_frame_display))
        self._frame_axes.on_update(ui.callback(self._on_frame_display))
        self._image_on_frustum.on_update(
            ui.callback(lambda: self.images.show_on_frustum(self._image_on_frustum.value))
        )
        self._gizmo.on_update(ui.callback(lambda: self.frames.show_gizmo(self._gizmo.value)))
        for slider in self._sliders.values():
            slider.on_update(ui.callback(self._on_slider))
        # The gizmo moves on a viser thread: the new pose is applied here.
        self.frames.on_change(
            lambda pose, source: ui.post(lambda: self._on_pose_changed(pose, source))
        )

    def forget_unpublished(self, graph: GraphSnapshot) -> None:
        """A new lesson starts clean: forget everything no running node publishes now.

        Frames whose broadcaster left, a robot nobody describes any more, and
        the clouds, scans, images, markers, joints and stamped points of topics
        without a publisher; each row then follows by itself again, so what the
        new lesson starts shows at once. What is still published stays. The
        cameras go back to the desk view (an earlier lesson may have left them far
        out over a point cloud), unless the simulated world still runs.
        """
        for row in self._rows:
            if row.current != picker.NONE and graph.publishers(row.current) == 0:
                row.follow(picker.NONE)
        self.stamped.forget_unpublished(graph)
        self.tf_view.forget_unpublished(graph.publishers("/robot_description") > 0)
        if not self._world_shown:
            self.drive.move_cameras(*(np.asarray(v, dtype=float) for v in DESK_VIEW))

    def _frame_known(self, frame: str) -> bool:
        """Whether TF has ``frame`` now (any thread)."""
        return frame in self.tf_view.frame_names()

    def _frame_pose(self, frame: str) -> np.ndarray | None:
        """A TF frame's pose in the Fixed Frame, as the TF view last drew it (any thread)."""
        return self.tf_view.poses().get(frame)

    def _world_view(self) -> tuple[np.ndarray, np.ndarray] | None:
        """(camera position, look-at) that show the whole simulated world, or None."""
        bounds = self.world.bounds
        if bounds is None:
            return None
        low, high = bounds
        world = self._frame_pose("world")
        if world is not None:  # the room's box, moved to where TF draws the world frame
            low, high = (tf.apply(world, corner[None, :])[0] for corner in (low, high))
        return overview(low, high)

    def _stage_world(self, shown: bool) -> None:
        """A simulated world came (or went): set the scene for it (or back for the desk).

        An ambient light shows the walls' sides (the dashboard's lights come from
        above); the frames' names and axes go off, so the small robot is not buried
        under twenty labels (the checkboxes bring them back). The desk gives way to
        it (``_follow_desk``).
        """
        self._light.visible = shown
        assign(self._frame_names, not shown)
        assign(self._frame_axes, not shown)
        self._on_frame_display()

    def _follow_desk(self, graph: GraphSnapshot) -> None:
        """The lesson-13 desk shows while a node feeds it, and gives way to what ROS
        describes in its place.

        The desk is the view's own base_link and camera marks (axes, names, the
        frustum) and the arm drawn straight from joint angles; it shows while a
        node publishes joint angles or a stamped point or pose. Once a simulated
        world, or a robot from a running robot_state_publisher (a publisher of
        /robot_description), is drawn, TF draws those frames and links where
        they really are, as rviz would; the desk's copies would only stand on
        top of them (and cost the browser every frame). What hangs under the
        desk's frames (stamped points, clouds, markers) keeps showing. The
        frustum stays while the learner shows the camera image on it.
        """
        robot = self.tf_view.robot_drawn and graph.publishers("/robot_description") > 0
        desk = picker.desk_in_use(graph) and not (self._world_shown or robot)
        frustum = desk or self._image_on_frustum.value is True
        if (desk, frustum) == self._desk_shown:
            return
        if desk != self._desk_shown[0]:
            self._pause_desk_arm(not desk)
            self._server.scene.add_frame(ARM_PATH, show_axes=False, visible=desk)
        self._desk_shown = (desk, frustum)
        self.frames.show_marks(frames=desk, frustum=frustum)

    def _follow_world(self) -> None:
        shown = self.world.shown
        if shown == self._world_shown:
            return
        self._world_shown = shown
        self._stage_world(shown)
        initial = self._server.initial_camera
        view = self._world_view() if shown else None
        if view is None:
            initial.position, initial.look_at = DESK_VIEW
            return
        initial.position, initial.look_at = (tf.as_xyz(v) for v in view)
        self.drive.move_cameras(*view)  # the world has just appeared: show it whole

    def _follow_robot(self, graph: GraphSnapshot) -> None:
        """A robot from a robot_state_publisher came (no simulated world): the cameras go
        to it and the frames around it (at the desk view the lesson-15 arm was 90 px tall
        under a knot of labels). A robot that drives about (the URDF lesson's R2-D2 circles
        2 m round odom) is reframed to all the places it has been, until its whole way is in
        view: then the learner's own camera moves stay theirs."""
        here = (
            not self._world_shown
            and graph.publishers("/robot_description") > 0
            and self.tf_view.robot_drawn
        )
        if not here:
            self._robot_box = self._framed_box = None
            return
        poses = self.tf_view.poses()
        if len(poses) < MIN_FRAMES_TO_FRAME:
            return
        points = np.array([pose[:3, 3] for pose in poses.values()])
        self._robot_box = grown_box(self._robot_box, points)
        if not outgrown(self._framed_box, self._robot_box):
            return
        # Framed with room round it, as much as half its size (up to a metre): an arm that
        # moves its joints stays framed large, and a robot driving about is reframed less
        # and less often as its way grows, not at each step.
        extent = float(np.max(self._robot_box[1][:2] - self._robot_box[0][:2]))
        room = min(max(REFRAME_ROOM_FRACTION * extent, REFRAME_ROOM_MIN_M), REFRAME_ROOM_M)
        self._framed_box = low, high = padded(self._robot_box, room)
        position, look_at = overview(low, high)  # looks at the floor under the frames...
        lift = np.array([0.0, 0.0, (high[2] - low[2]) / 2.0])  # ...and here at their middle
        self.drive.move_cameras(position + lift, look_at + lift)

    def _draws_nothing(self) -> bool:
        """No world, no desk, no frame on TF, nothing received for a 3D layer: only the grid.

        The image row does not count: its picture shows in this panel, not in 3D (on a
        frustum only with a frame on TF, or the desk's, and those count).
        """
        layers = (self.clouds, self.scan, self.map, self.particles, self.path, self.markers)
        return (
            not self._world_shown
            and self._desk_shown == (False, False)
            and not self.tf_view.frame_names()
            and all(layer.worker.stats()[0] == 0 for layer in layers)
        )

    def _pause_desk_arm(self, paused: bool) -> None:
        """The desk arm's joint row stops following /joint_states by itself while the desk
        gives way (robots then move on TF; the hidden desk arm would only cost CPU)."""
        row = self._joint_row
        row.automatic = not paused
        if paused and not row.chosen_by_learner and row.current != picker.NONE:
            row.follow(picker.NONE)

    def _on_frame_display(self) -> None:
        self.tf_view.set_display(
            names=self._frame_names.value is True, axes=self._frame_axes.value is True
        )

    def _on_fixed_frame(self) -> None:
        value = str(self._fixed.value)
        self.tf_view.fixed_frame = "" if value == AUTO_FIXED else value

    def _look_at_cloud(self) -> None:
        self.clouds.frame_in_view(self.frames.to_world)

    def _apply_budget(self) -> None:
        self.clouds.budget = int(self._budget.value)

    def _select_joints(self, topic: str) -> None:
        self.plot.clear()
        self.arm.select(topic)

    def _on_slider(self) -> None:
        v = {k: float(s.value) for k, s in self._sliders.items()}
        pose = CameraPose(
            v["x"],
            v["y"],
            v["z"],
            math.radians(v["roll"]),
            math.radians(v["pitch"]),
            math.radians(v["yaw"]),
        )
        self.frames.set_pose(pose, "sliders")

    def _on_pose_changed(self, pose: CameraPose, source: str) -> None:
        if source == "gizmo":  # keep the sliders in step (our own assignments post nothing)
            for key, slider in self._sliders.items():
                value = getattr(pose, key)
                shown = math.degrees(value) if key in ("roll", "pitch", "yaw") else value
                assign(slider, round(shown, 2))
        self._show_matrix(pose)
        self.params.push(pose)

    def _show_matrix(self, pose: CameraPose) -> None:
        x, y, z, w = tf.wxyz_to_ros(pose.wxyz)
        self._matrix.show(
            "**T** (camera in base_link):\n\n"
            + code_block(tf.format_matrix(pose.matrix()).splitlines())
            + f"\n\nquaternion (ROS order x, y, z, w): ({x:.3f}, {y:.3f}, {z:.3f}, {w:.3f})"
        )

    def refresh(self, graph: GraphSnapshot) -> None:
        # What draws or moves, every pass; what is said about it (the topic rows' options
        # and notes, each layer's text) with each new graph snapshot: once a second while
        # idle, at once after a click (issue 43's idle CPU: most of this view's work).
        self.world.refresh(graph)
        self.more_robots.refresh(graph)
        self.drive.refresh(graph)
        self._follow_world()
        self._follow_robot(graph)
        self._follow_desk(graph)
        empty = self._draws_nothing()
        if self._empty_hint.visible != empty:
            self._empty_hint.visible = empty
        self.plot.flush()
        self.stamped.refresh(graph)
        frames = (AUTO_FIXED, *self.tf_view.frame_names())
        if frames != self._fixed_options:
            if self._fixed.value not in frames:
                frames = (*frames, str(self._fixed.value))  # a picked frame that went away
            self._fixed_options = frames
            self._fixed.options = frames
        self.joint_sliders.show(self.tf_view.robot_joints)
        if graph is not self._texts_from:
            self._texts_from = graph
            self._refresh_texts(graph)

    def _refresh_texts(self, graph: GraphSnapshot) -> None:
        rows = (
            (self._cloud_row, self.clouds.worker, self.clouds.topic),
            (self._scan_row, self.scan.worker, self.scan.topic),
            (self._map_row, self.map.worker, self.map.topic),
            (self._particle_row, self.particles.worker, self.particles.topic),
            (self._path_row, self.path.worker, self.path.topic),
            (self._image_row, self.images.worker, self.images.topic),
            (self._marker_row, self.markers.worker, self.markers.topic),
            (self._joint_row, self.arm.worker, self.arm.topic),
        )
        for row, worker, topic in rows:
            row.refresh_options(graph)
            received, _drawn, rate, since = worker.stats()
            note = picker.liveness_note(graph, topic, received, since, row.offer.latched)
            if not note and rate:
                note = f"{rate:.1f} Hz received"
            row.note.show(note)
        self._world_info.show(
            "\n\n".join(t for t in (self.world.describe(), self.more_robots.describe()) if t)
        )
        self._scan_info.show(self.scan.note)
        self._map_info.show(self.map.describe())
        self._particle_info.show(self.particles.describe())
        self._path_info.show(self.path.describe())
        self._cloud_status.show(self.clouds.describe())
        camera = self.images.tf_camera
        note = camera.note if camera is not None else ""
        self._image_info.show("\n\n".join(t for t in (self.images.info, note) if t))
        self._marker_info.show(self.markers.describe())
        self._arm_info.show(self.arm.describe())
        self._stamped_info.show(self.stamped.describe())
        self._param_status.show(self.params.status)
        self._tf_status.show(self.tf_view.status())

    def close(self) -> None:
        layers = (self.clouds, self.images, self.markers, self.arm, self.stamped, self.params)
        sim = (self.scan, self.map, self.world, self.more_robots, self.drive)
        nav = (self.particles, self.path, self.pose_tools)
        for layer in (*layers, *sim, *nav, self.tf_view, self.joint_sliders):
            layer.close()
        if self.images.tf_camera is not None:
            self.images.tf_camera.close()

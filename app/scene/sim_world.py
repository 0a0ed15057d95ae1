"""The simulated world of ``sim_world`` in the 3D view: its room and its loose objects.

The simulator publishes its world as visualization_msgs/MarkerArray (so rviz
can draw it too), built from the MJCF model its physics steps:
``/sim_world/static_markers`` once (latched: floor, walls, furniture) and
``/sim_world/object_markers`` whenever a loose object moves (the cube the arm
picks up). Each marker hangs under the TF view's node of its frame
(``world``), so the room sits wherever TF puts the world frame in the
learner's Fixed Frame, as rviz would draw it. The robots are not in these
markers: the TF view draws them from their URDFs at their TF frames.

Threads: the subscriptions' callbacks (executor) queue the markers; one
worker applies them at most ``MAX_HZ`` times a second; the UI thread reads
summaries and notices when the simulator has gone.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from functools import partial

import numpy as np
import viser
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from visualization_msgs.msg import Marker, MarkerArray

from app.ros.graph import GraphSnapshot
from app.scene.latest import LatestWorker
from app.scene.markers import MarkerDrawing
from app.scene.qos import SCENE_CALLBACK_GROUP
from app.scene.tf_view import TF_PATH, scene_name

STATIC_TOPIC = "/sim_world/static_markers"
OBJECT_TOPIC = "/sim_world/object_markers"
TOPICS = (STATIC_TOPIC, OBJECT_TOPIC)
MAX_HZ = 15.0
GONE_AFTER_SEC = 3.0  # no publisher this long after the last message: the world is taken away
LATCHED = QoSProfile(
    depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)


def tf_frame_path(frame: str) -> str:
    """The scene node the TF view moves to ``frame``'s pose: children there move with it."""
    return f"{TF_PATH}/frames/{scene_name(frame.strip().lstrip('/'))}"


def marker_bounds(markers: list[Marker]) -> tuple[np.ndarray, np.ndarray] | None:
    """A box (low, high corners) around markers' positions and sizes, in their frame."""
    corners = []
    for marker in markers:
        if marker.action not in (0, 1):  # ADD, MODIFY
            continue
        p, s = marker.pose.position, marker.scale
        centre = np.array([p.x, p.y, p.z])
        half = np.abs(np.array([s.x, s.y, s.z])) / 2.0
        corners += [centre - half, centre + half]
    if not corners:
        return None
    stacked = np.array(corners)
    return stacked.min(axis=0), stacked.max(axis=0)


class WorldLayer:
    def __init__(self, node: Node, server: viser.ViserServer) -> None:
        self._node = node
        self._lock = threading.Lock()
        self._queue: deque[tuple[str, list[Marker]]] = deque(maxlen=64)
        self._clear_pending = False
        self._last_message: float | None = None
        self.static = MarkerDrawing(server, parent_for=tf_frame_path, folder="sim_world")
        self.objects = MarkerDrawing(server, parent_for=tf_frame_path, folder="sim_objects")
        self.bounds: tuple[np.ndarray, np.ndarray] | None = None  # the room, in `world`
        self.worker = LatestWorker("sim-world", self._apply, MAX_HZ)
        self._subscriptions = [
            node.create_subscription(
                MarkerArray,
                topic,
                partial(self._on_markers, which),
                LATCHED,
                callback_group=SCENE_CALLBACK_GROUP,
            )
            for which, topic in (("static", STATIC_TOPIC), ("objects", OBJECT_TOPIC))
        ]

    # --- executor thread ---
    def _on_markers(self, which: str, msg: MarkerArray) -> None:
        with self._lock:
            self._queue.append((which, list(msg.markers)))
            self._last_message = time.monotonic()
        self.worker.offer(True)

    # --- worker thread ---
    def _apply(self, _token: bool) -> None:
        with self._lock:
            batches = list(self._queue)
            self._queue.clear()
            clear, self._clear_pending = self._clear_pending, False
        if clear:
            self.static.clear()
            self.objects.clear()
            self.bounds = None
        for which, markers in batches:
            if which == "static":
                self.bounds = marker_bounds(markers) or self.bounds
                self.static.apply(markers)
            else:
                self.objects.apply(markers)

    # --- UI thread ---
    @property
    def shown(self) -> bool:
        """True while a world is drawn."""
        return len(self.static) > 0

    def refresh(self, graph: GraphSnapshot) -> None:
        """Take the world away once the simulator has gone (its latched topic has no publisher)."""
        with self._lock:
            last = self._last_message
        if not self.shown or graph.publishers(STATIC_TOPIC) > 0 or last is None:
            return
        if time.monotonic() - last > GONE_AFTER_SEC:
            with self._lock:
                self._clear_pending = True
                self._last_message = None
            self.worker.offer(True)

    def describe(self) -> str:
        if not self.shown:
            return ""
        objects = len(self.objects.namespaces())  # one namespace per object body
        skipped = self.static.skipped or self.objects.skipped
        return (
            f"World drawn from `{STATIC_TOPIC}`: {len(self.static)} shapes, "
            f"{objects} loose object{'s' if objects != 1 else ''} from `{OBJECT_TOPIC}`."
            + (f" Not drawn: {skipped}." if skipped else "")
        )

    def close(self) -> None:
        for subscription in self._subscriptions:
            self._node.destroy_subscription(subscription)
        self.worker.stop()

"""Robots described in a namespace (``/arm/robot_description``), drawn from their URDF at TF.

The TF view (``app/scene/tf_view.py``) draws the robot of
``/robot_description``. A launch file that starts two robots gives each its
own robot_state_publisher in a namespace, so the second robot's URDF is on
``/<namespace>/robot_description`` (the sim_drive group's arm is on
``/arm/robot_description``), while both publish their links on the one
``/tf``. This layer follows every such topic on the graph and hangs each
link's shapes under the TF view's node of that link's frame, so they move
with ``/tf`` exactly as the main robot does. A description whose publisher
has gone is taken away.

Threads: ``refresh`` (UI thread) subscribes and unsubscribes; the callbacks
(executor) drop the URDF text into a box; a worker parses it and adds the
meshes (parsing a URDF with meshes can take a while: never on the executor).
"""

from __future__ import annotations

import logging
import threading
from functools import partial

import viser
from rclpy.node import Node
from rclpy.subscription import Subscription
from robot_state_publisher.urdf_tree import UrdfError
from std_msgs.msg import String

from app.ros.graph import GraphSnapshot
from app.scene.latest import LatestWorker
from app.scene.qos import SCENE_CALLBACK_GROUP
from app.scene.robot_model import build_drawing
from app.scene.sim_world import LATCHED, tf_frame_path

log = logging.getLogger(__name__)

SUFFIX = "/robot_description"
MAIN = "/robot_description"  # the TF view's own
STRING_TYPE = "std_msgs/msg/String"
MAX_ROBOTS = 8


def namespaced_descriptions(graph: GraphSnapshot) -> list[str]:
    """``/<ns>/robot_description`` topics with a publisher (not the TF view's own)."""
    return sorted(
        t.name
        for t in graph.topics
        if t.name.endswith(SUFFIX)
        and t.name != MAIN
        and STRING_TYPE in t.types
        and t.publishers > 0
    )[:MAX_ROBOTS]


def tag_of(topic: str) -> str:
    """A scene-name-safe tag for a description topic: /arm/robot_description -> arm."""
    namespace = topic[: -len(SUFFIX)].strip("/")
    return "".join(ch if ch.isalnum() else "_" for ch in namespace) or "ns"


class NamespacedRobots:
    def __init__(self, node: Node, server: viser.ViserServer) -> None:
        self._node = node
        self._server = server
        self._lock = threading.Lock()
        self._subscriptions: dict[str, Subscription] = {}  # the UI thread's
        self._pending: dict[str, str | None] = {}  # topic -> new URDF text, or None: take away
        self._handles: dict[str, list[viser.SceneNodeHandle]] = {}  # the worker's
        self._summaries: dict[str, str] = {}  # the worker writes, the UI thread reads
        self.worker = LatestWorker("namespaced-robots", self._apply, 5.0)

    # --- UI thread ---
    def refresh(self, graph: GraphSnapshot) -> None:
        wanted = set(namespaced_descriptions(graph))
        for topic in sorted(set(self._subscriptions) - wanted):
            self._node.destroy_subscription(self._subscriptions.pop(topic))
            with self._lock:
                self._pending[topic] = None
            self.worker.offer(True)
        for topic in sorted(wanted - set(self._subscriptions)):
            self._subscriptions[topic] = self._node.create_subscription(
                String,
                topic,
                partial(self._on_description, topic),
                LATCHED,
                callback_group=SCENE_CALLBACK_GROUP,
            )

    def describe(self) -> str:
        return "\n\n".join(text for _topic, text in sorted(dict(self._summaries).items()))

    def close(self) -> None:
        for subscription in self._subscriptions.values():
            self._node.destroy_subscription(subscription)
        self._subscriptions.clear()
        self.worker.stop()

    # --- executor thread ---
    def _on_description(self, topic: str, msg: String) -> None:
        with self._lock:
            self._pending[topic] = msg.data
        self.worker.offer(True)

    # --- worker thread ---
    def _apply(self, _token: bool) -> None:
        with self._lock:
            pending, self._pending = self._pending, {}
        for topic, text in pending.items():
            for handle in self._handles.pop(topic, []):
                handle.remove()
            if text is None:
                self._summaries.pop(topic, None)
            else:
                self._draw(topic, text)

    def _draw(self, topic: str, text: str) -> None:
        try:
            drawing = build_drawing(text)
        except UrdfError as exc:
            self._summaries[topic] = f"⚠️ `{topic}`: {exc}"
            log.warning("%s: %s", topic, exc)
            return
        tag = tag_of(topic)
        scene = self._server.scene
        handles = self._handles.setdefault(topic, [])
        with self._server.atomic():
            for i, visual in enumerate(drawing.visuals):
                name = f"{tf_frame_path(visual.link)}/{tag}_visual{i}"
                handles.append(scene.add_mesh_trimesh(name, visual.mesh))
        shown = len({v.link for v in drawing.visuals})
        self._summaries[topic] = (
            f"Robot **{drawing.name}** from `{topic}`: {len(drawing.links)} links, "
            f"{shown} with shapes."
        )

"""Draw a Marker or MarkerArray topic: add, modify, delete and deleteall, as rviz does.

Markers arrive on the executor thread and are queued (all of them: a
MarkerArray's DELETEALL followed by ADDs must not be dropped); the worker
applies the queue at most 15 times a second. A marker that only moved gets
new ``position``/``wxyz`` properties; a changed geometry is re-added under
the same name, which replaces it. :class:`MarkerDrawing` is that bookkeeping,
shared with the simulated world's layer (``app/scene/sim_world.py``).
"""

from __future__ import annotations

import threading
from collections import deque
from collections.abc import Callable, Iterable, Mapping
from typing import TypedDict

import numpy as np
import viser
from rclpy.node import Node
from visualization_msgs.msg import Marker, MarkerArray

from app.scene.follow import OneTopicLayer, TopicFollower
from app.scene.frames import scene_path_for_frame
from app.scene.latest import LatestWorker
from app.scene.marker_plan import Plan, Shape, plan_marker, scene_name
from app.scene.topic_picker import NONE

MAX_HZ = 15.0
MAX_QUEUED = 2000  # markers kept between two draws; older ones are dropped first


class _Pose(TypedDict):
    position: tuple[float, float, float]
    wxyz: tuple[float, float, float, float]


def _same_value(v: object, w: object) -> bool:
    if isinstance(v, np.ndarray) and isinstance(w, np.ndarray):
        return v.shape == w.shape and bool((v == w).all())
    return v == w


def _same_geometry(a: Shape, b: Shape) -> bool:
    if a.kind != b.kind or a.color != b.color or a.frame_id != b.frame_id:
        return False
    mine: Mapping[str, object] = a.args
    theirs: Mapping[str, object] = b.args
    if mine.keys() != theirs.keys():
        return False
    return all(_same_value(v, theirs[k]) for k, v in mine.items())


def legacy_parent(frame_id: str) -> str:
    """The scene node a marker of ``frame_id`` hangs under in the lesson-13 scene."""
    return scene_path_for_frame(frame_id)[0]


class MarkerDrawing:
    """Markers in a viser scene by (ns, id), each under the node ``parent_for(frame_id)``.

    One thread (a layer's worker) calls everything but ``kinds``.
    """

    def __init__(
        self,
        server: viser.ViserServer,
        parent_for: Callable[[str], str] = legacy_parent,
        folder: str = "markers",
    ) -> None:
        self._server = server
        self._scene = server.scene
        self._parent_for = parent_for
        self._folder = folder
        self._drawn: dict[tuple[str, int], tuple[Shape, viser.SceneNodeHandle]] = {}
        self.skipped = ""

    def apply(self, markers: Iterable[Marker]) -> None:
        """Apply Marker messages in order, in one atomic update of the scene."""
        with self._server.atomic():
            for marker in markers:
                self._apply_one(plan_marker(marker))

    def clear(self) -> None:
        for _shape, handle in self._drawn.values():
            handle.remove()
        self._drawn.clear()

    def kinds(self) -> dict[str, int]:
        """How many markers of each kind are drawn (any thread: a snapshot)."""
        kinds: dict[str, int] = {}
        for shape, _h in list(self._drawn.values()):
            kinds[shape.kind] = kinds.get(shape.kind, 0) + 1
        return kinds

    def __len__(self) -> int:
        return len(self._drawn)

    def namespaces(self) -> set[str]:
        """The namespaces drawn (any thread: a snapshot)."""
        return {key[0] for key in list(self._drawn)}

    def _apply_one(self, plan: Plan) -> None:
        if plan.delete_all:
            self.clear()
        elif plan.delete is not None:
            entry = self._drawn.pop(plan.delete, None)
            if entry:
                entry[1].remove()
        elif plan.shape is not None:
            self._draw(plan.shape)
        elif plan.skipped:
            self.skipped = plan.skipped

    def _draw(self, shape: Shape) -> None:
        old = self._drawn.get(shape.key)
        if old is not None and _same_geometry(old[0], shape):
            old[1].position = shape.position
            old[1].wxyz = shape.wxyz
            self._drawn[shape.key] = (shape, old[1])
            return
        if old is not None:
            old[1].remove()
        parent = self._parent_for(shape.frame_id)
        name = f"{parent}/{self._folder}/{scene_name(shape.key)}"
        self._drawn[shape.key] = (shape, self._add(name, shape))

    def _add(self, name: str, shape: Shape) -> viser.SceneNodeHandle:
        a, s, color = shape.args, self._scene, shape.color
        pose = _Pose(position=shape.position, wxyz=shape.wxyz)
        if a["kind"] == "sphere":
            return s.add_icosphere(
                name, a["radius"], color, subdivisions=2, scale=a["scale"], **pose
            )
        if a["kind"] == "box":
            return s.add_box(name, color, a["dimensions"], **pose)
        if a["kind"] == "cylinder":
            return s.add_cylinder(name, a["radius"], a["height"], color, **pose)
        if a["kind"] == "mesh":
            return s.add_mesh_simple(
                name, a["vertices"], a["faces"], color=color, flat_shading=True, side="double",
                **pose,
            )  # fmt: skip
        if a["kind"] == "lines":
            return s.add_line_segments(
                name, a["points"], a["colors"], thickness=a["thickness"], **pose
            )
        if a["kind"] == "arrows":
            return s.add_arrows(
                name,
                a["points"],
                color,
                shaft_radius=a["shaft_radius"],
                head_radius=a["head_radius"],
                head_length=a["head_length"],
                **pose,
            )
        if a["kind"] == "points":
            return s.add_point_cloud(
                name,
                a["points"],
                a["colors"],
                point_size=a["point_size"],
                point_shape=a["point_shape"],
                point_shading="flat",
                **pose,
            )
        return s.add_label(
            name,
            a["text"],
            font_size_mode="scene",
            font_scene_height=a["font_scene_height"],
            **pose,
        )


class MarkerLayer(OneTopicLayer):
    def __init__(self, node: Node, server: viser.ViserServer) -> None:
        self._node = node
        self._lock = threading.Lock()  # the queue: the executor fills it, the worker empties it
        self._queue: deque[Marker] = deque(maxlen=MAX_QUEUED)
        self.drawing = MarkerDrawing(server)
        self._clear_pending = False
        worker = LatestWorker("markers", self._apply, MAX_HZ)
        super().__init__(
            TopicFollower(
                node,
                worker,
                MarkerArray,
                qos=10,
                deliver=self._on_message,
                on_switch=self._forget,
            )
        )

    def select(self, topic: str, type_name: str | None = None) -> None:
        """Follow ``topic`` as a Marker or MarkerArray topic (its advertised type unless given)."""
        if type_name is None and topic not in (NONE, self.topic):
            types = dict(self._node.get_topic_names_and_types()).get(topic, [])
            type_name = types[0] if types else "visualization_msgs/msg/MarkerArray"
        single = type_name is not None and type_name.endswith("/Marker")
        self._follower.select(topic, Marker if single else MarkerArray)

    def _forget(self, _topic: str) -> None:
        with self._lock:
            self._queue.clear()
            self._clear_pending = True  # the worker removes the old topic's markers
        self.worker.poke(True)

    def _on_message(self, msg: Marker | MarkerArray) -> None:
        markers = msg.markers if isinstance(msg, MarkerArray) else [msg]
        with self._lock:
            self._queue.extend(markers)
        self.worker.offer(True)

    def _apply(self, _token: bool) -> None:
        with self._lock:
            batch = list(self._queue)
            self._queue.clear()
            clear, self._clear_pending = self._clear_pending, False
        if clear:
            self.drawing.clear()
        self.drawing.apply(batch)

    def describe(self) -> str:
        if self.topic == NONE:
            return ""
        kinds = self.drawing.kinds()
        listed = ", ".join(f"{n} {k}" for k, n in sorted(kinds.items())) or "none yet"
        skipped = f" · skipped: {self.drawing.skipped}" if self.drawing.skipped else ""
        return f"Markers shown: {listed}{skipped}"

"""Draw a Marker or MarkerArray topic: add, modify, delete and deleteall, as rviz does.

Markers arrive on the executor thread and are queued (all of them: a
MarkerArray's DELETEALL followed by ADDs must not be dropped); the worker
applies the queue at most 15 times a second. A marker that only moved gets
new ``position``/``wxyz`` properties; a changed geometry is re-added under
the same name, which replaces it.
"""

from __future__ import annotations

import threading
from collections import deque
from collections.abc import Mapping
from typing import Any, TypedDict

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


class MarkerLayer(OneTopicLayer):
    def __init__(self, node: Node, server: viser.ViserServer) -> None:
        self._node = node
        self._scene = server.scene
        self._server = server
        self._lock = threading.Lock()  # the queue: the executor fills it, the worker empties it
        self._queue: deque[Any] = deque(maxlen=MAX_QUEUED)
        self._drawn: dict[tuple[str, int], tuple[Shape, viser.SceneNodeHandle]] = {}
        self._skipped = ""
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
        self.worker.offer(True)

    def _on_message(self, msg: Any) -> None:
        markers = msg.markers if isinstance(msg, MarkerArray) else [msg]
        with self._lock:
            self._queue.extend(markers)
        self.worker.offer(True)

    def _apply(self, _token: Any) -> None:
        with self._lock:
            batch = list(self._queue)
            self._queue.clear()
            clear, self._clear_pending = self._clear_pending, False
        if clear:
            self._clear()
        with self._server.atomic():
            for marker in batch:
                self._apply_one(plan_marker(marker))

    def _clear(self) -> None:
        for _shape, handle in self._drawn.values():
            handle.remove()
        self._drawn.clear()

    def _apply_one(self, plan: Plan) -> None:
        if plan.delete_all:
            self._clear()
        elif plan.delete is not None:
            entry = self._drawn.pop(plan.delete, None)
            if entry:
                entry[1].remove()
        elif plan.shape is not None:
            self._draw(plan.shape)
        elif plan.skipped:
            self._skipped = plan.skipped

    def _draw(self, shape: Shape) -> None:
        old = self._drawn.get(shape.key)
        if old is not None and _same_geometry(old[0], shape):
            old[1].position = shape.position
            old[1].wxyz = shape.wxyz
            self._drawn[shape.key] = (shape, old[1])
            return
        if old is not None:
            old[1].remove()
        parent, _known = scene_path_for_frame(shape.frame_id)
        name = f"{parent}/markers/{scene_name(shape.key)}"
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

    def describe(self) -> str:
        if self.topic == NONE:
            return ""
        kinds: dict[str, int] = {}
        for shape, _h in list(self._drawn.values()):
            kinds[shape.kind] = kinds.get(shape.kind, 0) + 1
        listed = ", ".join(f"{n} {k}" for k, n in sorted(kinds.items())) or "none yet"
        skipped = f" · skipped: {self._skipped}" if self._skipped else ""
        return f"Markers shown: {listed}{skipped}"

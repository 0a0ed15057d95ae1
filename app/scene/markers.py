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
from typing import Any

import viser
from rclpy.node import Node
from visualization_msgs.msg import Marker, MarkerArray

from app.scene.frames import scene_path_for_frame
from app.scene.latest import LatestWorker
from app.scene.marker_plan import Plan, Shape, plan_marker, scene_name
from app.scene.qos import SCENE_CALLBACK_GROUP
from app.scene.topic_picker import NONE

MAX_HZ = 15.0
MAX_QUEUED = 2000  # markers kept between two draws; older ones are dropped first


def _same_geometry(a: Shape, b: Shape) -> bool:
    if a.kind != b.kind or a.color != b.color or a.frame_id != b.frame_id:
        return False
    if a.args.keys() != b.args.keys():
        return False
    for k, v in a.args.items():
        w = b.args[k]
        if hasattr(v, "shape"):
            if v.shape != w.shape or not (v == w).all():
                return False
        elif v != w:
            return False
    return True


class MarkerLayer:
    def __init__(self, node: Node, server: viser.ViserServer) -> None:
        self._node = node
        self._scene = server.scene
        self._server = server
        self._lock = threading.Lock()
        self._topic = NONE
        self._subscription: Any = None
        self._queue: deque[Any] = deque(maxlen=MAX_QUEUED)
        self._drawn: dict[tuple[str, int], tuple[Shape, Any]] = {}
        self._skipped = ""
        self._clear_pending = False
        self.worker = LatestWorker("markers", self._apply, MAX_HZ)

    @property
    def topic(self) -> str:
        return self._topic

    def select(self, topic: str, type_name: str | None = None) -> None:
        with self._lock:
            if topic == self._topic:
                return
            old, self._subscription = self._subscription, None
            self._topic = topic
            self._queue.clear()
        if old is not None:
            self._node.destroy_subscription(old)
        self.worker.reset()
        with self._lock:
            self._clear_pending = True  # the worker removes the old topic's markers
        self.worker.offer(True)
        if topic == NONE:
            return
        if type_name is None:
            types = dict(self._node.get_topic_names_and_types()).get(topic, [])
            type_name = types[0] if types else "visualization_msgs/msg/MarkerArray"
        msg_type = Marker if type_name.endswith("/Marker") else MarkerArray
        sub = self._node.create_subscription(
            msg_type, topic, self._on_message, 10, callback_group=SCENE_CALLBACK_GROUP
        )
        with self._lock:
            self._subscription = sub

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
        pose = {"position": shape.position, "wxyz": shape.wxyz}
        a, s = shape.args, self._scene
        if shape.kind == "sphere":
            handle = s.add_icosphere(name, color=shape.color, subdivisions=2, **a, **pose)
        elif shape.kind == "box":
            handle = s.add_box(name, color=shape.color, **a, **pose)
        elif shape.kind == "cylinder":
            handle = s.add_cylinder(name, color=shape.color, **a, **pose)
        elif shape.kind == "arrows":
            handle = s.add_arrows(name, colors=shape.color, **a, **pose)
        elif shape.kind == "lines":
            handle = s.add_line_segments(name, **a, **pose)
        elif shape.kind == "points":
            handle = s.add_point_cloud(name, point_shading="flat", **a, **pose)
        else:
            handle = s.add_label(
                name,
                a["text"],
                font_size_mode="scene",
                font_scene_height=a["font_scene_height"],
                **pose,
            )
        self._drawn[shape.key] = (shape, handle)

    def describe(self) -> str:
        if self._topic == NONE:
            return ""
        kinds: dict[str, int] = {}
        for shape, _h in list(self._drawn.values()):
            kinds[shape.kind] = kinds.get(shape.kind, 0) + 1
        listed = ", ".join(f"{n} {k}" for k, n in sorted(kinds.items())) or "none yet"
        skipped = f" · skipped: {self._skipped}" if self._skipped else ""
        return f"Markers shown: {listed}{skipped}"

    def close(self) -> None:
        self.select(NONE)
        self.worker.stop()

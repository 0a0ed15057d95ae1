"""visualization_msgs/Marker -> a plain description of what to draw (no viser, no rclpy).

rviz's marker types map onto a handful of viser primitives. Keeping the
mapping pure makes every type, scale rule and colour rule unit-testable.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from app.scene.transforms import ros_to_wxyz

# visualization_msgs/Marker type and action constants
ARROW, CUBE, SPHERE, CYLINDER = 0, 1, 2, 3
LINE_STRIP, LINE_LIST, CUBE_LIST, SPHERE_LIST, POINTS, TEXT_VIEW_FACING = 4, 5, 6, 7, 8, 9
MESH_RESOURCE, TRIANGLE_LIST = 10, 11
ADD, MODIFY, DELETE, DELETEALL = 0, 1, 2, 3

TYPE_NAMES = {
    ARROW: "ARROW",
    CUBE: "CUBE",
    SPHERE: "SPHERE",
    CYLINDER: "CYLINDER",
    LINE_STRIP: "LINE_STRIP",
    LINE_LIST: "LINE_LIST",
    CUBE_LIST: "CUBE_LIST",
    SPHERE_LIST: "SPHERE_LIST",
    POINTS: "POINTS",
    TEXT_VIEW_FACING: "TEXT_VIEW_FACING",
    MESH_RESOURCE: "MESH_RESOURCE",
    TRIANGLE_LIST: "TRIANGLE_LIST",
}


@dataclass(frozen=True)
class Shape:
    """One scene primitive: ``kind`` picks the viser call, ``args`` its geometry."""

    key: tuple[str, int]  # (namespace, id): what DELETE and MODIFY refer to
    kind: str  # sphere | box | cylinder | arrows | lines | points | text
    frame_id: str
    position: tuple[float, float, float]
    wxyz: tuple[float, float, float, float]
    color: tuple[int, int, int]
    args: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class Plan:
    """What one Marker asks for: draw ``shape``, delete ``delete``, or clear all."""

    shape: Shape | None = None
    delete: tuple[str, int] | None = None
    delete_all: bool = False
    skipped: str = ""  # why nothing is drawn (unsupported type)


def _rgb(c: Any) -> tuple[int, int, int]:
    return tuple(int(np.clip(round(float(v) * 255), 0, 255)) for v in (c.r, c.g, c.b))


def _points(marker: Any) -> np.ndarray:
    return np.array([[p.x, p.y, p.z] for p in marker.points], dtype=np.float32).reshape(-1, 3)


def _point_colors(marker: Any, n: int) -> np.ndarray:
    if len(marker.colors) == n and n:
        return np.array([_rgb(c) for c in marker.colors], dtype=np.uint8)
    return np.tile(np.array(_rgb(marker.color), dtype=np.uint8), (n, 1))


def _segments(points: np.ndarray, strip: bool) -> np.ndarray:
    if strip:
        if len(points) < 2:
            return np.zeros((0, 2, 3), np.float32)
        return np.stack([points[:-1], points[1:]], axis=1)
    pairs = len(points) // 2
    return points[: 2 * pairs].reshape(pairs, 2, 3)


def plan_marker(marker: Any) -> Plan:
    """Translate one Marker message into a :class:`Plan`."""
    key = (str(marker.ns), int(marker.id))
    if marker.action == DELETEALL:
        return Plan(delete_all=True)
    if marker.action == DELETE:
        return Plan(delete=key)
    p, o, s = marker.pose.position, marker.pose.orientation, marker.scale
    position = (float(p.x), float(p.y), float(p.z))
    wxyz = ros_to_wxyz(o.x, o.y, o.z, o.w)
    color = _rgb(marker.color)
    common = {"key": key, "frame_id": str(marker.header.frame_id), "color": color}
    t = int(marker.type)
    if t == SPHERE:
        args = {"radius": 0.5, "scale": (float(s.x), float(s.y), float(s.z))}
        return Plan(Shape(kind="sphere", position=position, wxyz=wxyz, args=args, **common))
    if t == CUBE:
        args = {"dimensions": (float(s.x), float(s.y), float(s.z))}
        return Plan(Shape(kind="box", position=position, wxyz=wxyz, args=args, **common))
    if t == CYLINDER:
        args = {"radius": float(s.x) / 2, "height": float(s.z)}
        return Plan(Shape(kind="cylinder", position=position, wxyz=wxyz, args=args, **common))
    if t == ARROW:
        pts = _points(marker)
        if len(pts) >= 2:  # start/end form: scale.x shaft diameter, y head diameter, z head length
            seg = pts[None, :2]
            shaft, head = float(s.x) / 2, float(s.y) / 2
            head_len = float(s.z) or 2 * head
        else:  # pose form: along the pose's x axis, scale.x long
            seg = np.array([[[0, 0, 0], [float(s.x), 0, 0]]], dtype=np.float32)
            shaft, head = float(s.y) / 2, float(s.z) / 2
            head_len = min(float(s.x) * 0.3, 4 * head) if head else float(s.x) * 0.3
        args = {
            "points": seg.astype(np.float32),
            "shaft_radius": max(shaft, 1e-4),
            "head_radius": max(head, 1e-4),
            "head_length": max(head_len, 1e-4),
        }
        return Plan(Shape(kind="arrows", position=position, wxyz=wxyz, args=args, **common))
    if t in (LINE_STRIP, LINE_LIST):
        pts = _points(marker)
        segs = _segments(pts, strip=(t == LINE_STRIP))
        per_point = _point_colors(marker, len(pts))
        if t == LINE_STRIP:
            seg_colors = np.stack([per_point[:-1], per_point[1:]], axis=1) if len(pts) > 1 else None
        else:
            seg_colors = per_point[: 2 * len(segs)].reshape(-1, 2, 3)
        if seg_colors is None or len(segs) == 0:
            return Plan(skipped=f"{TYPE_NAMES[t]} with fewer than 2 points")
        args = {"points": segs, "colors": seg_colors, "thickness": max(float(s.x), 1e-3)}
        return Plan(Shape(kind="lines", position=position, wxyz=wxyz, args=args, **common))
    if t in (POINTS, SPHERE_LIST, CUBE_LIST):
        pts = _points(marker)
        args = {
            "points": pts,
            "colors": _point_colors(marker, len(pts)),
            "point_size": max(float(s.x), 1e-3),
            "point_shape": "square" if t == CUBE_LIST else "circle",
        }
        return Plan(Shape(kind="points", position=position, wxyz=wxyz, args=args, **common))
    if t == TEXT_VIEW_FACING:
        args = {"text": str(marker.text), "font_scene_height": max(float(s.z), 0.01)}
        return Plan(Shape(kind="text", position=position, wxyz=wxyz, args=args, **common))
    return Plan(skipped=f"{TYPE_NAMES.get(t, t)} markers are not drawn here")


def scene_name(key: tuple[str, int]) -> str:
    """A scene-tree-safe leaf name for (namespace, id)."""
    ns = "".join(ch if ch.isalnum() or ch in "-_" else "_" for ch in key[0]) or "default"
    return f"{ns}_{key[1]}"

"""visualization_msgs/Marker -> a plain description of what to draw (no viser, no rclpy).

rviz's marker types map onto a handful of viser primitives. Keeping the
mapping pure makes every type, scale rule and colour rule unit-testable.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal, TypedDict

import numpy as np

from app.scene.transforms import ros_to_wxyz

if TYPE_CHECKING:
    from std_msgs.msg import ColorRGBA
    from visualization_msgs.msg import Marker

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


Vec3 = tuple[float, float, float]


# What each kind of primitive needs; ``kind`` picks the viser call, the other
# keys are its geometry, named as viser's arguments are.
class SphereArgs(TypedDict):
    kind: Literal["sphere"]
    radius: float
    scale: Vec3


class BoxArgs(TypedDict):
    kind: Literal["box"]
    dimensions: Vec3


class CylinderArgs(TypedDict):
    kind: Literal["cylinder"]
    radius: float
    height: float


class ArrowsArgs(TypedDict):
    kind: Literal["arrows"]
    points: np.ndarray  # (N, 2, 3) start and end of each arrow
    shaft_radius: float
    head_radius: float
    head_length: float


class LinesArgs(TypedDict):
    kind: Literal["lines"]
    points: np.ndarray  # (N, 2, 3) segment ends
    colors: np.ndarray  # (N, 2, 3) uint8, per end
    thickness: float


class PointsArgs(TypedDict):
    kind: Literal["points"]
    points: np.ndarray  # (N, 3)
    colors: np.ndarray  # (N, 3) uint8
    point_size: float
    point_shape: Literal["square", "circle"]


class TextArgs(TypedDict):
    kind: Literal["text"]
    text: str
    font_scene_height: float


class MeshArgs(TypedDict):
    kind: Literal["mesh"]
    vertices: np.ndarray  # (N, 3) float32, scaled by the marker's scale
    faces: np.ndarray  # (N / 3, 3) uint32: each three consecutive points are a triangle


ShapeArgs = (
    SphereArgs | BoxArgs | CylinderArgs | ArrowsArgs | LinesArgs | PointsArgs | TextArgs | MeshArgs
)


@dataclass(frozen=True)
class Shape:
    """One scene primitive: ``args`` says which (``kind``) and its geometry."""

    key: tuple[str, int]  # (namespace, id): what DELETE and MODIFY refer to
    frame_id: str
    position: Vec3
    wxyz: tuple[float, float, float, float]
    color: tuple[int, int, int]
    args: ShapeArgs

    @property
    def kind(self) -> str:
        """sphere | box | cylinder | arrows | lines | points | text | mesh"""
        return self.args["kind"]


@dataclass(frozen=True)
class Plan:
    """What one Marker asks for: draw ``shape``, delete ``delete``, or clear all."""

    shape: Shape | None = None
    delete: tuple[str, int] | None = None
    delete_all: bool = False
    skipped: str = ""  # why nothing is drawn (unsupported type)


def _byte(v: float) -> int:
    return int(np.clip(round(float(v) * 255), 0, 255))


def _rgb(c: ColorRGBA) -> tuple[int, int, int]:
    return (_byte(c.r), _byte(c.g), _byte(c.b))


def _points(marker: Marker) -> np.ndarray:
    return np.array([[p.x, p.y, p.z] for p in marker.points], dtype=np.float32).reshape(-1, 3)


def _point_colors(marker: Marker, n: int) -> np.ndarray:
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


def plan_marker(marker: Marker) -> Plan:
    """Translate one Marker message into a :class:`Plan`."""
    key = (str(marker.ns), int(marker.id))
    if marker.action == DELETEALL:
        return Plan(delete_all=True)
    if marker.action == DELETE:
        return Plan(delete=key)
    args = _shape_args(marker)
    if isinstance(args, str):
        return Plan(skipped=args)
    p, o = marker.pose.position, marker.pose.orientation
    shape = Shape(
        key=key,
        frame_id=str(marker.header.frame_id),
        position=(float(p.x), float(p.y), float(p.z)),
        wxyz=ros_to_wxyz(o.x, o.y, o.z, o.w),
        color=_rgb(marker.color),
        args=args,
    )
    return Plan(shape)


def _shape_args(marker: Marker) -> ShapeArgs | str:
    """The primitive a Marker's type maps to, or why it is not drawn."""
    s, t = marker.scale, int(marker.type)
    if t == SPHERE:
        return SphereArgs(kind="sphere", radius=0.5, scale=(float(s.x), float(s.y), float(s.z)))
    if t == CUBE:
        return BoxArgs(kind="box", dimensions=(float(s.x), float(s.y), float(s.z)))
    if t == CYLINDER:
        return CylinderArgs(kind="cylinder", radius=float(s.x) / 2, height=float(s.z))
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
        return ArrowsArgs(
            kind="arrows",
            points=seg.astype(np.float32),
            shaft_radius=max(shaft, 1e-4),
            head_radius=max(head, 1e-4),
            head_length=max(head_len, 1e-4),
        )
    if t in (LINE_STRIP, LINE_LIST):
        pts = _points(marker)
        segs = _segments(pts, strip=(t == LINE_STRIP))
        per_point = _point_colors(marker, len(pts))
        if t == LINE_STRIP:
            seg_colors = np.stack([per_point[:-1], per_point[1:]], axis=1) if len(pts) > 1 else None
        else:
            seg_colors = per_point[: 2 * len(segs)].reshape(-1, 2, 3)
        if seg_colors is None or len(segs) == 0:
            return f"{TYPE_NAMES[t]} with fewer than 2 points"
        return LinesArgs(
            kind="lines", points=segs, colors=seg_colors, thickness=max(float(s.x), 1e-3)
        )
    if t in (POINTS, SPHERE_LIST, CUBE_LIST):
        pts = _points(marker)
        return PointsArgs(
            kind="points",
            points=pts,
            colors=_point_colors(marker, len(pts)),
            point_size=max(float(s.x), 1e-3),
            point_shape="square" if t == CUBE_LIST else "circle",
        )
    if t == TEXT_VIEW_FACING:
        return TextArgs(kind="text", text=str(marker.text), font_scene_height=max(float(s.z), 0.01))
    if t == TRIANGLE_LIST:
        pts = _points(marker)
        triangles = len(pts) // 3
        if triangles == 0:
            return "TRIANGLE_LIST with fewer than 3 points"
        vertices = pts[: 3 * triangles] * np.array([s.x, s.y, s.z], dtype=np.float32)
        faces = np.arange(3 * triangles, dtype=np.uint32).reshape(triangles, 3)
        return MeshArgs(kind="mesh", vertices=vertices.astype(np.float32), faces=faces)
    return f"{TYPE_NAMES.get(t, t)} markers are not drawn here"


def scene_name(key: tuple[str, int]) -> str:
    """A scene-tree-safe leaf name for (namespace, id)."""
    ns = "".join(ch if ch.isalnum() or ch in "-_" else "_" for ch in key[0]) or "default"
    return f"{ns}_{key[1]}"

"""What a world looks like, as simple shapes a 3D view (or rviz) can draw: no ROS, no OpenGL.

The simulator's own model is the one source: every visible geom of the
compiled MJCF becomes one or more primitives (box, sphere, cylinder, or a
triangle list for a mesh) with its colour and its pose in the world. Geoms
fall into three sets:

- **static**: on a body welded to the world (floor, walls, furniture): drawn
  once, they never move;
- **objects**: on any other body outside the robots (a cube the arm picks
  up): their poses change, so they are sent again when they move;
- **robots**: the subtrees of the robots' root bodies (``base_link``,
  ``arm_base_link``): left out here, because the robots are drawn from their
  URDF at their TF frames, as rviz draws them.

Geoms in groups 3-5 (which MuJoCo's viewer hides by default) and fully
transparent ones are not drawn.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass

import mujoco
import numpy as np

VISIBLE_GROUPS = (0, 1, 2)  # MuJoCo's viewer shows these by default
PLANE_THICKNESS = 0.01  # m: a plane is drawn as a thin slab...
PLANE_DROP = 0.002  # ...whose top sits this far under the plane (a grid at z=0 stays visible)
INFINITE_PLANE_HALF = 10.0  # m: half the side drawn for a plane of size 0 (infinite)
MAX_MESH_FACES = 20_000  # a bigger mesh is drawn as its bounding box
DEFAULT_GEOM_RGBA = (0.5, 0.5, 0.5, 1.0)  # MuJoCo's default: a material's colour wins over it
MOVED_METRES = 0.001  # an object that moved less than this...
MOVED_RADIANS = 0.005  # ...and turned less than this has not moved (nothing to resend)


@dataclass(frozen=True)
class Primitive:
    """One drawable shape, as a visualization_msgs/Marker describes it.

    ``kind`` is ``cube``, ``sphere``, ``cylinder`` (both along z, scale is the
    full size as Marker's) or ``triangles`` (``triangles`` holds three points
    per triangle in the primitive's frame, scale 1). The pose is in the world.
    """

    ns: str  # the body's name ("world" for the world body's own geoms)
    id: int  # unique within the world, stable while the model is loaded
    kind: str
    scale: tuple[float, float, float]
    position: tuple[float, float, float]
    quat_xyzw: tuple[float, float, float, float]
    rgba: tuple[float, float, float, float]
    triangles: np.ndarray | None = None


def _quat_xyzw(matrix: np.ndarray) -> tuple[float, float, float, float]:
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(matrix, dtype=np.float64).ravel())
    w, x, y, z = quat
    return (float(x), float(y), float(z), float(w))


def _triple(v: Iterable[float]) -> tuple[float, float, float]:
    x, y, z = (float(c) for c in v)
    return (x, y, z)


def subtree(model: mujoco.MjModel, roots: Iterable[int]) -> set[int]:
    """Body ids of ``roots`` and everything attached below them."""
    inside = set(roots)
    for body in range(model.nbody):  # parents come before children in MuJoCo's body order
        if int(model.body_parentid[body]) in inside and body != 0:
            inside.add(body)
    return inside


class WorldGeometry:
    """The drawable geoms of one compiled world, split into static, objects and robots."""

    def __init__(self, model: mujoco.MjModel, robot_roots: Iterable[str] = ()) -> None:
        self.model = model
        roots = [model.body(name).id for name in robot_roots]
        self.robot_bodies = subtree(model, roots)
        self.static_geoms: list[int] = []
        self.object_geoms: list[int] = []
        self.skipped: list[str] = []  # geoms that are visible but cannot be drawn, and why
        for geom in range(model.ngeom):
            body = int(model.geom_bodyid[geom])
            if body in self.robot_bodies or not self._visible(geom):
                continue
            if int(model.body_weldid[body]) == 0:
                self.static_geoms.append(geom)
            else:
                self.object_geoms.append(geom)
        self.object_bodies = sorted({int(model.geom_bodyid[g]) for g in self.object_geoms})
        self._last_object_poses: np.ndarray | None = None

    def _visible(self, geom: int) -> bool:
        if int(self.model.geom_group[geom]) not in VISIBLE_GROUPS:
            return False
        return self.rgba(geom)[3] > 0.0

    def rgba(self, geom: int) -> tuple[float, float, float, float]:
        """The geom's colour as MuJoCo draws it, a texture by its mean colour."""
        model = self.model
        own = tuple(float(c) for c in model.geom_rgba[geom])
        material = int(model.geom_matid[geom])
        if material < 0 or not np.allclose(own, DEFAULT_GEOM_RGBA):
            r, g, b, a = own
            return (r, g, b, a)
        colour = np.array(model.mat_rgba[material], dtype=np.float64)
        texture = int(np.ravel(model.mat_texid[material])[int(mujoco.mjtTextureRole.mjTEXROLE_RGB)])
        if texture >= 0:
            colour[:3] *= self._texture_mean(texture)
        r, g, b, a = (float(c) for c in np.clip(colour, 0.0, 1.0))
        return (r, g, b, a)

    def _texture_mean(self, texture: int) -> np.ndarray:
        model = self.model
        start = int(model.tex_adr[texture])
        channels = int(model.tex_nchannel[texture])
        count = int(model.tex_width[texture]) * int(model.tex_height[texture]) * channels
        pixels = np.asarray(model.tex_data[start : start + count], dtype=np.float64)
        if channels < 3 or pixels.size == 0:
            return np.ones(3)
        return pixels.reshape(-1, channels)[:, :3].mean(axis=0) / 255.0

    # --- primitives ------------------------------------------------------------------
    def primitives(self, data: mujoco.MjData, geoms: Iterable[int]) -> list[Primitive]:
        """The shapes of ``geoms`` at their poses in ``data`` (after mj_kinematics)."""
        shapes: list[Primitive] = []
        for geom in geoms:
            shapes.extend(self._geom_primitives(data, geom))
        return shapes

    def static_primitives(self, data: mujoco.MjData) -> list[Primitive]:
        return self.primitives(data, self.static_geoms)

    def object_primitives(self, data: mujoco.MjData) -> list[Primitive]:
        return self.primitives(data, self.object_geoms)

    def objects_moved(self, data: mujoco.MjData) -> bool:
        """True when an object moved since the last call that returned True (or the first)."""
        if not self.object_bodies:
            return False
        poses = np.hstack([data.xpos[self.object_bodies], data.xquat[self.object_bodies]]).astype(
            np.float64
        )
        last = self._last_object_poses
        if last is not None:
            moved = np.linalg.norm(poses[:, :3] - last[:, :3], axis=1).max()
            dots = np.abs(np.sum(poses[:, 3:] * last[:, 3:], axis=1)).clip(0.0, 1.0)
            turned = (2.0 * np.arccos(dots)).max()
            if moved < MOVED_METRES and turned < MOVED_RADIANS:
                return False
        self._last_object_poses = poses
        return True

    def _geom_primitives(self, data: mujoco.MjData, geom: int) -> list[Primitive]:
        model = self.model
        kind = int(model.geom_type[geom])
        size = np.array(model.geom_size[geom], dtype=np.float64)
        position = np.array(data.geom_xpos[geom], dtype=np.float64)
        rotation = np.array(data.geom_xmat[geom], dtype=np.float64).reshape(3, 3)
        body = int(model.geom_bodyid[geom])
        ns = model.body(body).name or "world"
        rgba = self.rgba(geom)
        base = 16 * geom  # room for a geom's several primitives, ids stay stable

        def shape(
            k: str,
            scale: Iterable[float],
            offset: Iterable[float] = (0.0, 0.0, 0.0),
            n: int = 0,
            triangles: np.ndarray | None = None,
        ) -> Primitive:
            at = position + rotation @ np.asarray(tuple(offset), dtype=np.float64)
            return Primitive(
                ns, base + n, k, _triple(scale), _triple(at), _quat_xyzw(rotation), rgba, triangles
            )

        g = mujoco.mjtGeom
        if kind == g.mjGEOM_PLANE:
            half_x = size[0] if size[0] > 0 else INFINITE_PLANE_HALF
            half_y = size[1] if size[1] > 0 else INFINITE_PLANE_HALF
            depth = -(PLANE_DROP + PLANE_THICKNESS / 2.0)
            return [shape("cube", (2 * half_x, 2 * half_y, PLANE_THICKNESS), (0.0, 0.0, depth))]
        if kind == g.mjGEOM_BOX:
            return [shape("cube", 2.0 * size)]
        if kind == g.mjGEOM_SPHERE:
            return [shape("sphere", (2.0 * size[0],) * 3)]
        if kind == g.mjGEOM_ELLIPSOID:
            return [shape("sphere", 2.0 * size)]
        if kind == g.mjGEOM_CYLINDER:
            return [shape("cylinder", (2.0 * size[0], 2.0 * size[0], 2.0 * size[1]))]
        if kind == g.mjGEOM_CAPSULE:
            radius, half = size[0], size[1]
            return [
                shape("cylinder", (2.0 * radius, 2.0 * radius, 2.0 * half)),
                shape("sphere", (2.0 * radius,) * 3, (0.0, 0.0, half), 1),
                shape("sphere", (2.0 * radius,) * 3, (0.0, 0.0, -half), 2),
            ]
        if kind == g.mjGEOM_MESH:
            return [self._mesh(geom, shape)]
        name = model.geom(geom).name or f"#{geom}"
        reason = f"geom {name}: {mujoco.mjtGeom(kind).name} is not drawn"
        if reason not in self.skipped:
            self.skipped.append(reason)
        return []

    def _mesh(self, geom: int, shape: Callable[..., Primitive]) -> Primitive:
        model = self.model
        mesh = int(model.geom_dataid[geom])
        first_face, faces = int(model.mesh_faceadr[mesh]), int(model.mesh_facenum[mesh])
        first_vert, verts = int(model.mesh_vertadr[mesh]), int(model.mesh_vertnum[mesh])
        vertices = np.array(model.mesh_vert[first_vert : first_vert + verts], dtype=np.float32)
        if faces > MAX_MESH_FACES:  # too big for a marker: its bounding box stands in
            low, high = vertices.min(axis=0), vertices.max(axis=0)
            return shape("cube", high - low, (low + high) / 2.0)
        indices = np.array(model.mesh_face[first_face : first_face + faces], dtype=np.int64)
        return shape("triangles", (1.0, 1.0, 1.0), triangles=vertices[indices.reshape(-1)])

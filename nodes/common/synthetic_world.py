"""A textured 3D room and a camera flying through it along a known loop.

This is the built-in "video" for the SLAM lesson: every frame is rendered
from a camera pose we know exactly, so the estimate of a visual-odometry
pipeline can be scored against the truth.

The world is the inside of a box (x in [-4, 4], y in [-3, 3], z in [0, 3]
metres, z up), its six faces covered with random coloured shapes, which give
plenty of corners to track. Rendering is ray casting: every pixel's viewing
ray leaves a convex box through exactly one face, found with three divisions
per pixel; the face's texture is then sampled with ``cv2.remap``. No occlusion
handling is needed inside a convex room, and nothing is ever behind the
camera, so the image is exact.

Camera frames follow the optical convention (x right, y down, z forward).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from nodes.common.frames import BODY_FROM_OPTICAL, make_transform, rpy_to_matrix

ROOM_MIN = np.array([-4.0, -3.0, 0.0])
ROOM_MAX = np.array([4.0, 3.0, 3.0])


@dataclass(frozen=True)
class Intrinsics:
    """Pinhole camera: focal lengths and principal point in pixels."""

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float

    @classmethod
    def default(cls, width: int = 640, height: int = 480) -> Intrinsics:
        focal = 0.82 * width  # about 63 degrees horizontal field of view
        return cls(width, height, focal, focal, (width - 1) / 2.0, (height - 1) / 2.0)

    def matrix(self) -> np.ndarray:
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])


def make_texture(seed: int, size: int = 1024) -> np.ndarray:
    """A busy BGR texture: many random rectangles and triangles (sharp corners), some discs."""
    rng = np.random.default_rng(seed)
    texture = np.empty((size, size, 3), np.uint8)
    texture[:] = rng.integers(40, 200, 3)
    for _ in range(size * 3 // 4):
        color = tuple(int(c) for c in rng.integers(0, 256, 3))
        kind = rng.choice(3, p=(0.45, 0.4, 0.15))
        cx, cy = (int(v) for v in rng.integers(0, size, 2))
        extent = int(rng.integers(size // 100, size // 14))
        if kind == 0:
            cv2.rectangle(texture, (cx, cy), (cx + extent, cy + extent // 2 + 2), color, -1)
        elif kind == 1:
            corners = rng.integers(-extent, extent, (3, 2)) + (cx, cy)
            cv2.fillPoly(texture, [corners.astype(np.int32)], color, cv2.LINE_AA)
        else:
            cv2.circle(texture, (cx, cy), extent // 2 + 1, color, -1, cv2.LINE_AA)
    return cv2.GaussianBlur(texture, (3, 3), 0)


class Room:
    """The textured box; :meth:`render` draws it from a camera pose."""

    def __init__(self, seed: int = 7, texture_size: int = 1024) -> None:
        self.texture_size = texture_size
        # One atlas, faces stacked vertically: -x, +x, -y, +y, -z (floor), +z (ceiling).
        self.atlas = np.concatenate(
            [make_texture(seed * 10 + face, texture_size) for face in range(6)], axis=0
        )
        self._rays: dict[Intrinsics, np.ndarray] = {}

    def _camera_rays(self, intr: Intrinsics) -> np.ndarray:
        rays = self._rays.get(intr)
        if rays is None:
            u, v = np.meshgrid(
                np.arange(intr.width, dtype=np.float32), np.arange(intr.height, dtype=np.float32)
            )
            rays = np.stack(
                [(u - intr.cx) / intr.fx, (v - intr.cy) / intr.fy, np.ones_like(u)], axis=-1
            ).reshape(-1, 3)
            self._rays[intr] = rays
        return rays

    def render(self, T_world_cam: np.ndarray, intr: Intrinsics) -> np.ndarray:
        """BGR image seen by a camera at ``T_world_cam`` (optical frame) inside the room."""
        origin = T_world_cam[:3, 3].astype(np.float32)
        if np.any(origin <= ROOM_MIN) or np.any(origin >= ROOM_MAX):
            raise ValueError("the camera must be inside the room")
        dirs = self._camera_rays(intr) @ T_world_cam[:3, :3].T.astype(np.float32)
        # Distance along each ray to the wall it meets on each axis; the nearest one wins.
        dist = []
        for i in range(3):
            d = dirs[:, i]
            with np.errstate(divide="ignore", invalid="ignore"):
                wall = np.where(d > 0, np.float32(ROOM_MAX[i]), np.float32(ROOM_MIN[i]))
                t = (wall - origin[i]) / d
            t[~(t > 0)] = np.inf  # parallel rays (d == 0) never meet that wall
            dist.append(t)
        nearest = np.minimum(np.minimum(dist[0], dist[1]), dist[2])
        axis = np.where(nearest == dist[0], 0, np.where(nearest == dist[1], 1, 2))
        positive = np.choose(axis, (dirs[:, 0], dirs[:, 1], dirs[:, 2])) > 0
        face = axis * 2 + positive
        # Where the ray hits, as fractions 0..1 of the room along each axis.
        rel = [
            (origin[i] + dirs[:, i] * nearest - np.float32(ROOM_MIN[i]))
            / np.float32(ROOM_MAX[i] - ROOM_MIN[i])
            for i in range(3)
        ]
        tex_u = np.where(axis == 0, rel[1], rel[0])  # x walls use y; others use x
        tex_v = np.where(axis == 2, rel[1], rel[2])  # floor/ceiling use y; walls use z
        size = self.texture_size
        map_x = np.clip(tex_u, 0.0, 1.0) * (size - 1)
        map_y = face * size + np.clip(1.0 - tex_v, 0.0, 1.0) * (size - 1)
        shape = (intr.height, intr.width)
        return cv2.remap(
            self.atlas,
            map_x.reshape(shape).astype(np.float32),
            map_y.reshape(shape).astype(np.float32),
            cv2.INTER_LINEAR,
            borderMode=cv2.BORDER_REPLICATE,
        )


def loop_pose(phase: float) -> np.ndarray:
    """Camera pose ``T_world_cam`` at ``phase`` in [0, 1) of a closed loop.

    The camera circles an ellipse (1.6 m x 1.0 m) at about 1.4 m height,
    looking 45 degrees to the right of its direction of travel (towards the
    walls: sideways motion gives monocular vision good parallax), with a gentle
    nod and sway. The loop is periodic, so a looping video has no jump.
    """
    theta = 2.0 * math.pi * phase
    position = (1.6 * math.cos(theta), 1.0 * math.sin(theta), 1.4 + 0.15 * math.sin(2 * theta))
    heading = math.atan2(1.0 * math.cos(theta), -1.6 * math.sin(theta))
    yaw = heading - math.radians(45.0)
    pitch = 0.08 * math.sin(3 * theta)
    roll = 0.04 * math.sin(2 * theta)
    body = rpy_to_matrix(roll, pitch, yaw)
    return make_transform(body @ BODY_FROM_OPTICAL, position)


class SyntheticSequence:
    """``length`` frames of the loop, with their true poses."""

    def __init__(
        self,
        length: int = 300,
        width: int = 640,
        height: int = 480,
        seed: int = 7,
        texture_size: int = 1024,
    ) -> None:
        self.length = length
        self.intrinsics = Intrinsics.default(width, height)
        self.room = Room(seed, texture_size)

    def pose(self, index: int) -> np.ndarray:
        return loop_pose((index % self.length) / self.length)

    def frame(self, index: int) -> np.ndarray:
        return self.room.render(self.pose(index), self.intrinsics)

    def __len__(self) -> int:
        return self.length

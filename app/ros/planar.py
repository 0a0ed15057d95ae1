"""Shapes seen from above: the one home of a floor plan's rectangle.

The simulated world's obstacles (``app.lessons.checks._world_map``, from its
MJCF file) and a recording's room (``app.bags.replay``, from the world's
markers) are both rectangles turned about z; every reader measures and draws
the same ``Box``; a robot seen from above is a ``Pose``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Pose:
    """A planar pose with the time it was taken at (simulation time, or a recording's)."""

    t: float
    x: float
    y: float
    yaw: float

    def text(self) -> str:
        return f"({self.x:.2f}, {self.y:.2f}, {self.yaw:.2f} rad)"


@dataclass(frozen=True)
class Box:
    """A rectangle: centre, half sizes along its own axes, and its turn about z."""

    name: str
    x: float
    y: float
    half_x: float
    half_y: float
    yaw: float = 0.0

    def corners(self) -> list[tuple[float, float]]:
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return [
            (self.x + c * dx - s * dy, self.y + s * dx + c * dy)
            for dx, dy in (
                (self.half_x, self.half_y),
                (-self.half_x, self.half_y),
                (-self.half_x, -self.half_y),
                (self.half_x, -self.half_y),
            )
        ]

    def local(self, px: float, py: float) -> tuple[float, float]:
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        dx, dy = px - self.x, py - self.y
        return c * dx + s * dy, -s * dx + c * dy

    def distance(self, px: float, py: float) -> float:
        """Signed distance from a point to the rectangle (negative inside)."""
        lx, ly = self.local(px, py)
        qx, qy = abs(lx) - self.half_x, abs(ly) - self.half_y
        outside = math.hypot(max(qx, 0.0), max(qy, 0.0))
        return outside + min(max(qx, qy), 0.0)

    def ray(self, px: float, py: float, angle: float) -> float:
        """Distance along a ray from a point to the rectangle's outline (inf: missed)."""
        lx, ly = self.local(px, py)
        direction = angle - self.yaw
        dx, dy = math.cos(direction), math.sin(direction)
        near, far = -math.inf, math.inf
        for origin, d, half in ((lx, dx, self.half_x), (ly, dy, self.half_y)):
            if abs(d) < 1e-12:
                if abs(origin) > half:
                    return math.inf
                continue
            t1, t2 = (-half - origin) / d, (half - origin) / d
            near, far = max(near, min(t1, t2)), min(far, max(t1, t2))
        if near > far or far < 0:
            return math.inf
        return max(near, 0.0)

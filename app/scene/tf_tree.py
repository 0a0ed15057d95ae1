"""The newest transform of every TF frame, and each frame's pose in a chosen fixed frame.

What a 3D view needs of tf2, without a time cache: for each child frame its
parent, the newest transform, whether it came on ``/tf_static``, when it
arrived and how often. Transforms that tf2 refuses (a NaN anywhere, a
quaternion of length zero) are refused here too, with tf2's reason, and the
frame keeps its previous transform. Poses relative to the fixed frame are
composed along the tree; frames not connected to it, or caught in a loop
(a -> b -> a), get no pose and a reason instead. Plain Python and numpy:
the ROS side only calls :meth:`TfStore.add`, under the store's lock.
"""

from __future__ import annotations

import math
import threading
import time
from collections import deque
from dataclasses import dataclass, field

import numpy as np

from app.ros.tf_sources import is_stale

QUATERNION_TOLERANCE = 10e-3  # tf2 ignores a rotation whose squared length is further from 1


@dataclass
class FrameRecord:
    parent: str
    matrix: np.ndarray  # parent -> child, 4x4
    static: bool
    received: float  # time.monotonic() of the newest transform
    arrivals: deque[float] = field(default_factory=lambda: deque(maxlen=20))

    def rate(self) -> float | None:
        if len(self.arrivals) < 2 or self.arrivals[-1] <= self.arrivals[0]:
            return None
        return (len(self.arrivals) - 1) / (self.arrivals[-1] - self.arrivals[0])

    def stale(self, now: float) -> bool:
        return is_stale(self.static, self.rate(), self.received, now)


def transform_matrix(
    translation: tuple[float, float, float], rotation_xyzw: tuple[float, float, float, float]
) -> np.ndarray:
    """4x4 of a ROS transform; raises ValueError with tf2's reason for what tf2 ignores."""
    values = (*translation, *rotation_xyzw)
    if not all(math.isfinite(v) for v in values):
        raise ValueError("because of a nan value in the transform")
    x, y, z, w = rotation_xyzw
    squared = x * x + y * y + z * z + w * w
    if abs(squared - 1.0) >= QUATERNION_TOLERANCE:  # tf2's test: zero-length ones fail it too
        raise ValueError(f"because of an invalid quaternion in the transform ({x} {y} {z} {w})")
    norm = math.sqrt(squared)
    x, y, z, w = x / norm, y / norm, z / norm, w / norm
    m = np.eye(4)
    m[:3, :3] = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]
    m[:3, 3] = translation
    return m


@dataclass(frozen=True)
class TreeView:
    """Poses of every frame in the fixed frame (those that have one) and why others do not."""

    fixed: str
    poses: dict[str, np.ndarray]
    problems: dict[str, str]
    stale: frozenset[str]
    parents: dict[str, str]


class TfStore:
    """Thread-safe: ``add`` from the ROS executor, ``view`` from a drawing thread."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._frames: dict[str, FrameRecord] = {}
        self.errors: deque[str] = deque(maxlen=20)  # newest refusals, one line each
        self.version = 0

    def add(
        self,
        parent: str,
        child: str,
        translation: tuple[float, float, float],
        rotation_xyzw: tuple[float, float, float, float],
        *,
        static: bool,
        authority: str = "",
        now: float | None = None,
    ) -> bool:
        """Store one transform; False (and an error line) when tf2 would ignore it."""
        parent, child = parent.strip().lstrip("/"), child.strip().lstrip("/")
        now = time.monotonic() if now is None else now
        who = f' from authority "{authority}"' if authority else ""
        if not parent or not child:
            return self._refuse(
                f'Ignoring transform with an empty frame id ("{parent}" -> "{child}")'
            )
        if parent == child:
            return self._refuse(
                f'Ignoring transform for child_frame_id "{child}"{who} because frame_id and '
                "child_frame_id are the same"
            )
        try:
            matrix = transform_matrix(translation, rotation_xyzw)
        except ValueError as exc:
            code = "TF_NAN_INPUT" if "nan" in str(exc) else "TF_DENORMALIZED_QUATERNION"
            return self._refuse(
                f'{code}: Ignoring transform for child_frame_id "{child}"{who} {exc}'
            )
        with self._lock:
            record = self._frames.get(child)
            if record is None:
                record = FrameRecord(parent, matrix, static, now)
                self._frames[child] = record
            record.parent, record.matrix, record.static, record.received = (
                parent,
                matrix,
                static,
                now,
            )
            record.arrivals.append(now)
            self.version += 1
        return True

    def _refuse(self, line: str) -> bool:
        with self._lock:
            if not self.errors or self.errors[-1] != line:
                self.errors.append(line)
            self.version += 1
        return False

    def frames(self) -> list[str]:
        """Every frame named so far (children and parents), sorted."""
        with self._lock:
            names = set(self._frames) | {r.parent for r in self._frames.values()}
        return sorted(names)

    def roots(self) -> list[str]:
        """Frames with no parent: candidates for the fixed frame, biggest tree first."""
        with self._lock:
            parents = {child: r.parent for child, r in self._frames.items()}
        roots = sorted({p for p in parents.values() if p not in parents})
        size = {r: 0 for r in roots}
        for child in parents:
            top = _top(child, parents)
            if top in size:
                size[top] += 1
        return sorted(roots, key=lambda r: -size[r])

    def view(self, fixed: str, now: float | None = None) -> TreeView:
        """Pose of each frame in ``fixed``: up to the common root, then down.

        Each frame's pose in its root is its parent's times its own transform,
        computed once per frame (a robot's 30-link chain costs 30 products,
        not one chain walk per frame).
        """
        now = time.monotonic() if now is None else now
        with self._lock:
            records = {
                child: (r.parent, r.matrix, r.stale(now)) for child, r in self._frames.items()
            }
        parents = {child: rec[0] for child, rec in records.items()}
        stale = frozenset(child for child, rec in records.items() if rec[2])
        to_root: dict[str, np.ndarray] = {}  # root <- frame
        root_of: dict[str, str] = {}
        problems: dict[str, str] = {}
        for frame in set(parents) | set(parents.values()):
            chain: list[str] = []
            seen: set[str] = set()
            current = frame
            while current in parents and current not in to_root and current not in seen:
                if current in problems:  # leads into a loop found before
                    break
                seen.add(current)
                chain.append(current)
                current = parents[current]
            if current in seen or current in problems:
                looped = seen | ({current} if current in problems else set())
                for link in chain:
                    problems[link] = (
                        f"frames {', '.join(sorted(looped))} form a loop: TF must be a tree"
                    )
                continue
            if current not in to_root:  # a root
                to_root[current], root_of[current] = np.eye(4), current
            matrix, top = to_root[current], root_of[current]
            for link in reversed(chain):
                matrix = matrix @ records[link][1]
                to_root[link], root_of[link] = matrix, top
        poses: dict[str, np.ndarray] = {}
        if fixed not in to_root:
            for frame in to_root:
                problems.setdefault(frame, f"Fixed Frame [{fixed}] does not exist")
            return TreeView(fixed, poses, problems, stale, parents)
        fixed_root = root_of[fixed]
        inverse_fixed = np.linalg.inv(to_root[fixed])
        for frame, matrix in to_root.items():
            if root_of[frame] == fixed_root:
                poses[frame] = inverse_fixed @ matrix
            else:
                problems[frame] = f"No transform from [{frame}] to [{fixed}]"
        return TreeView(fixed, poses, problems, stale, parents)

    def clear(self) -> None:
        with self._lock:
            self._frames.clear()
            self.errors.clear()
            self.version += 1

    def forget(self, children: set[str]) -> None:
        """Drop these frames' transforms (a new lesson: their broadcasters are gone)."""
        with self._lock:
            for child in children:
                self._frames.pop(child, None)
            self.errors.clear()
            self.version += 1


def _top(frame: str, parents: dict[str, str]) -> str:
    seen = set()
    while frame in parents and frame not in seen:
        seen.add(frame)
        frame = parents[frame]
    return frame

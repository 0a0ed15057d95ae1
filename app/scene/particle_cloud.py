"""AMCL's particles (nav2_msgs/ParticleCloud, or a geometry_msgs/PoseArray) as arrows on the floor.

As Nav2's rviz ParticleCloud display: each particle is a small flat arrow at
its pose, pointing where that guess of the robot faces; a heavier particle
has a longer arrow. A spread-out cloud means the filter is unsure where the
robot is; a tight bundle means it has converged. A PoseArray draws the same
arrows, all of one length (its poses have no weights).

Thousands of particles travel as one batched primitive (line segments: a
shaft and two barbs an arrow), never a scene node each. The arrows hang
under the TF view's node of the message's frame (``header.frame_id``,
usually ``map``), as the Map row's picture does, so they sit on the map
wherever TF puts it. A frame not on TF yet: drawn at the Fixed Frame's
origin, and ``describe()`` says so.

amcl publishes best effort; the subscription matches whoever publishes. The
messages arrive as bytes and are read with numpy on the worker (a cloud is a
header and then eight float64 a particle): rclpy would otherwise build 2000
Python objects per cloud on the executor thread, 10-20 ms each time.

Threads: the executor hands the newest cloud to a worker (a few a second);
the worker converts and draws; the UI thread picks the topic.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable

import numpy as np
import viser
from geometry_msgs.msg import PoseArray
from nav2_msgs.msg import ParticleCloud
from rclpy.node import Node
from rclpy.serialization import deserialize_message
from rclpy.subscription import Subscription

from app.ros.qos import matching_qos
from app.scene.framed_layer import FramedLayer, frame_of
from app.scene.qos import SCENE_CALLBACK_GROUP

MAX_HZ = 4.0
TYPES = ("nav2_msgs/msg/ParticleCloud", "geometry_msgs/msg/PoseArray")
NODE_NAME = "particle_cloud"
LIFT = 0.03  # m above the frame's floor: over the map's picture (0.02)
MIN_LENGTH, MAX_LENGTH = 0.05, 0.15  # m: the lightest and the heaviest particle's arrow
BARB = 0.35  # the arrowhead's barbs, as a share of the arrow's length
BARB_ANGLE = math.radians(28.0)
SEGMENTS_PER_PARTICLE = 3  # shaft, left barb, right barb
COLOUR = (0, 170, 0)  # Nav2's rviz config draws the particles green
THICKNESS = 1.5  # screen pixels: thin enough for thousands, seen from any distance


def yaws_of(qx: np.ndarray, qy: np.ndarray, qz: np.ndarray, qw: np.ndarray) -> np.ndarray:
    """Each quaternion's turn about z (rad)."""
    return np.arctan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))


def arrow_lengths(weights: np.ndarray | None, count: int) -> np.ndarray:
    """Arrow lengths (m): the heaviest particle's ``MAX_LENGTH``, the others in proportion
    (never under ``MIN_LENGTH``); equal weights, or none, all ``MAX_LENGTH``."""
    if weights is None or count == 0:
        return np.full(count, MAX_LENGTH)
    w = np.where(np.isfinite(weights) & (weights > 0.0), weights, 0.0)
    top = float(w.max())
    if top <= 0.0:
        return np.full(count, MAX_LENGTH)
    return MIN_LENGTH + (MAX_LENGTH - MIN_LENGTH) * w / top


def arrow_segments(
    x: np.ndarray, y: np.ndarray, yaw: np.ndarray, length: np.ndarray, lift: float = LIFT
) -> np.ndarray:
    """(N * 3, 2, 3) float32 line segments: per pose a shaft along its heading and two barbs
    back from its tip, flat at height ``lift``. Segment 3i is pose i's shaft."""
    n = len(x)
    c, s = np.cos(yaw), np.sin(yaw)
    tip_x, tip_y = x + c * length, y + s * length
    segments = np.empty((n, SEGMENTS_PER_PARTICLE, 2, 3), np.float32)
    segments[:, :, :, 2] = lift
    segments[:, 0, 0, 0], segments[:, 0, 0, 1] = x, y
    for k, side in enumerate((1.0, -1.0), start=1):
        back = yaw + math.pi - side * BARB_ANGLE
        segments[:, k, 0, 0], segments[:, k, 0, 1] = tip_x, tip_y
        segments[:, k, 1, 0] = tip_x + np.cos(back) * length * BARB
        segments[:, k, 1, 1] = tip_y + np.sin(back) * length * BARB
    segments[:, 0, 1, 0], segments[:, 0, 1, 1] = tip_x, tip_y
    return segments.reshape(n * SEGMENTS_PER_PARTICLE, 2, 3)


def spread(x: np.ndarray, y: np.ndarray, weights: np.ndarray | None = None) -> float:
    """How scattered the guesses are (m): the weighted RMS distance from their mean."""
    if len(x) == 0:
        return 0.0
    w = np.ones(len(x)) if weights is None else np.where(np.isfinite(weights), weights, 0.0)
    w = np.clip(w, 0.0, None)
    if float(w.sum()) <= 0.0:
        w = np.ones(len(x))
    w = w / w.sum()
    mx, my = float((w * x).sum()), float((w * y).sum())
    return math.sqrt(float((w * ((x - mx) ** 2 + (y - my) ** 2)).sum()))


def decode_poses(data: bytes, weighted: bool) -> tuple[str, np.ndarray] | None:
    """(frame, (N, 8 or 7) float64 rows) of a serialized ParticleCloud (``weighted``) or
    PoseArray, read straight from its CDR bytes; None if they are not what we expect
    (then rclpy reads them). Per row: position x, y, z, orientation x, y, z, w (, weight)."""
    if len(data) < 16 or data[0] != 0 or data[1] not in (0, 1):
        return None
    endian = "<" if data[1] == 1 else ">"
    origin = 4  # alignment counts from after the encapsulation header
    _sec, _nanosec, size = struct.unpack_from(endian + "iII", data, origin)
    at = origin + 12
    if size < 1 or at + size > len(data):
        return None
    frame = data[at : at + size - 1].decode("utf-8", "replace")
    at += size
    at += -(at - origin) % 4
    if at + 4 > len(data):
        return None
    (count,) = struct.unpack_from(endian + "I", data, at)
    at += 4
    columns = 8 if weighted else 7
    if count == 0:
        return frame, np.zeros((0, columns))
    at += -(at - origin) % 8
    if at + count * columns * 8 != len(data):
        return None
    rows = np.frombuffer(data, endian + "f8", count * columns, at).reshape(count, columns)
    return frame, rows.astype(np.float64)


def poses_of(msg: ParticleCloud | PoseArray) -> tuple[np.ndarray, np.ndarray | None]:
    """((N, 7) x, y, z, qx, qy, qz, qw, the weights or None) of a ParticleCloud or PoseArray."""
    if isinstance(msg, ParticleCloud):
        poses = [p.pose for p in msg.particles]
        weights: np.ndarray | None = np.array([p.weight for p in msg.particles], np.float64)
    else:
        poses, weights = list(msg.poses), None
    table = np.array(
        [
            (
                p.position.x,
                p.position.y,
                p.position.z,
                p.orientation.x,
                p.orientation.y,
                p.orientation.z,
                p.orientation.w,
            )  # fmt: skip
            for p in poses
        ],
        np.float64,
    ).reshape(-1, 7)
    return table, weights


class ParticleCloudLayer(FramedLayer):
    """Draws the ParticleCloud or PoseArray topic picked (``select``) under its TF frame.

    ``frame_known(frame)`` says whether TF has that frame now (the note warns
    when not); by default every frame counts as known.
    """

    NODE_NAME = NODE_NAME
    LATCHED = False  # amcl publishes a new cloud with each update, best effort

    def __init__(
        self,
        node: Node,
        server: viser.ViserServer,
        frame_known: Callable[[str], bool] | None = None,
    ) -> None:
        super().__init__(node, server, "particle-cloud", MAX_HZ, frame_known)
        self.particles_shown = 0

    def forget(self) -> None:
        super().forget()
        self.particles_shown = 0

    def subscribe(self, topic: str) -> Subscription:
        """The topic's serialized bytes (read with numpy on the worker), of its advertised type."""
        types = dict(self._node.get_topic_names_and_types()).get(topic, [])
        msg_type = PoseArray if (types[0] if types else TYPES[0]) == TYPES[1] else ParticleCloud
        qos = matching_qos(self._node, topic, depth=1, latched=False)
        return self._node.create_subscription(
            msg_type,
            topic,
            lambda data: self.worker.offer((msg_type, data)),
            qos,
            callback_group=SCENE_CALLBACK_GROUP,
            raw=True,
        )

    # --- worker thread ---
    def draw(self, msg: ParticleCloud | PoseArray | tuple[type, bytes]) -> None:
        """Draw a cloud: a message, or (its type, its serialized bytes) as they arrive."""
        if isinstance(msg, tuple):
            msg_type, data = msg
            decoded = decode_poses(data, weighted=msg_type is ParticleCloud)
            if decoded is None:
                msg = deserialize_message(data, msg_type)
            else:
                frame, rows = decoded
                weights = rows[:, 7].copy() if msg_type is ParticleCloud else None
                kind = "particles" if msg_type is ParticleCloud else "poses"
                self._draw_rows(frame_of(frame), rows[:, :7], weights, kind)
                return
        assert not isinstance(msg, tuple)
        kind = "particles" if isinstance(msg, ParticleCloud) else "poses"
        table, weights = poses_of(msg)
        self._draw_rows(frame_of(msg.header.frame_id), table, weights, kind)

    def _draw_rows(
        self, frame: str, table: np.ndarray, weights: np.ndarray | None, kind: str
    ) -> None:
        finite = np.isfinite(table).all(axis=1)
        bad = int((~finite).sum())
        table = table[finite]
        if weights is not None:
            weights = weights[finite]
        n = len(table)
        if n == 0:
            self.particles_shown = 0
            self.nothing_drawn(
                f"no {kind} in the last message" + (f" ({bad} not finite)" if bad else "")
            )
            return
        x, y = table[:, 0], table[:, 1]
        yaw = yaws_of(table[:, 3], table[:, 4], table[:, 5], table[:, 6])
        self.show_segments(frame, arrow_segments(x, y, yaw, arrow_lengths(weights, n)), COLOUR,
                           THICKNESS)  # fmt: skip
        self.particles_shown = n
        self.drawn(
            frame,
            f"{n} {kind}, spread {spread(x, y, weights):.2f} m"
            + (f" ({bad} with a NaN or inf left out)" if bad else ""),
        )

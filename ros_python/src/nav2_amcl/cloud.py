"""/particle_cloud written straight from the filter's arrays into its CDR bytes.

A nav2_msgs/ParticleCloud of 2000 particles is 2000 ``Particle`` objects (each
with its ``Pose``, ``Point`` and ``Quaternion``) when built with rclpy's
message classes: 10-20 ms to make them here and 4-5 ms more for rclpy to
convert them back to C to publish, as long as the filter's whole update.
Nav2's C++ amcl fills a vector of structs instead. On the wire the message is
a header and then, per particle, eight float64 in a row (position x, y, z,
orientation x, y, z, w, weight): exactly a (N, 8) numpy array. So it is
written here as such, and published as bytes (``Publisher.publish`` takes a
serialized message). Subscribers receive the same message; the unit test
checks the bytes against rclpy's own serializer.

CDR (little endian, the encapsulation rmw_fastrtps writes): a 4-byte
encapsulation header, then each field aligned to its own size counted from
the first byte after that header.
"""

from __future__ import annotations

import struct

import numpy as np

ENCAPSULATION = b"\x00\x01\x00\x00"  # CDR, little endian
_ORIGIN = len(ENCAPSULATION)  # alignment counts from here


def _pad(buffer: bytearray, alignment: int) -> None:
    buffer += bytes(-(len(buffer) - _ORIGIN) % alignment)


def particle_cloud_cdr(
    sec: int, nanosec: int, frame_id: str, poses: np.ndarray, weights: np.ndarray
) -> bytes:
    """The serialized ParticleCloud of ``poses`` (N, 3: x, y, yaw) and ``weights`` (N,)."""
    count = len(poses)
    name = frame_id.encode("utf-8") + b"\0"
    out = bytearray(ENCAPSULATION)
    out += struct.pack("<iII", sec, nanosec, len(name))  # header.stamp, frame_id's length
    out += name
    _pad(out, 4)
    out += struct.pack("<I", count)  # the particles' sequence length
    if count == 0:
        return bytes(out)
    _pad(out, 8)
    rows = np.zeros((count, 8), "<f8")
    rows[:, 0] = poses[:, 0]  # pose.position.x
    rows[:, 1] = poses[:, 1]  # pose.position.y
    half = poses[:, 2] / 2.0
    rows[:, 5] = np.sin(half)  # pose.orientation.z
    rows[:, 6] = np.cos(half)  # pose.orientation.w
    rows[:, 7] = weights  # weight
    return bytes(out) + rows.tobytes()

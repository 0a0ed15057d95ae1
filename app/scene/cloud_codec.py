"""sensor_msgs/PointCloud2 <-> numpy, in bulk (no Python loop over points).

A PointCloud2 is a byte blob plus a list of fields (name, byte offset, type)
repeated every ``point_step`` bytes. We build one strided numpy view per field
straight over the message's buffer, so decoding 100k points costs a few
milliseconds. Decimation happens on the view (a larger stride) before any
copy. Works on the rclpy message or any object with the same attributes.

The perception nodes' ``nodes/common/pointcloud.py`` reads whole clouds and
builds them (``xyz_to_pointcloud2``); this module adds what drawing needs:
decimation before any copy, and colouring by rgb, intensity or height.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from nodes.common.pointcloud import POINTFIELD_DTYPES

if TYPE_CHECKING:
    from sensor_msgs.msg import PointCloud2, PointField

# A small perceptual colour ramp (dark blue -> teal -> yellow) for intensity
# and height; 5 stops interpolated in numpy.
_RAMP = np.array(
    [[48, 18, 59], [40, 120, 200], [30, 190, 140], [160, 220, 50], [250, 230, 40]],
    dtype=np.float32,
)


class CloudFormatError(ValueError):
    """The message cannot be drawn (no x/y/z, or fields outside the point)."""


@dataclass(frozen=True)
class DecodedCloud:
    points: np.ndarray  # (N, 3) float32, finite only
    colors: np.ndarray  # (N, 3) uint8
    total: int  # points in the message
    colour_source: str  # "rgb", "rgba", "intensity" or "height"

    @property
    def shown(self) -> int:
        return int(self.points.shape[0])


def _pointfield_dtype(datatype: int) -> np.dtype | None:
    """The numpy dtype of a PointField datatype code; None for an unknown code."""
    dtype = POINTFIELD_DTYPES.get(datatype)
    return dtype if isinstance(dtype, np.dtype) else None


def _field_view(
    buf: np.ndarray, n: int, step: int, field: PointField, big_endian: bool
) -> np.ndarray:
    dtype = _pointfield_dtype(int(field.datatype))
    if dtype is None:
        raise CloudFormatError(f"field {field.name!r} has unknown datatype {field.datatype}")
    if big_endian:
        dtype = dtype.newbyteorder(">")
    if n and field.offset + dtype.itemsize > step:
        raise CloudFormatError(f"field {field.name!r} does not fit in point_step {step}")
    return np.ndarray(
        shape=(n,), dtype=dtype, buffer=buf, offset=int(field.offset), strides=(step,)
    )


def colour_ramp(values: np.ndarray) -> np.ndarray:
    """Map values to the ramp by their own min..max (NaN-safe), as uint8 RGB."""
    v = np.asarray(values, dtype=np.float32)
    if v.size == 0:
        return np.zeros((0, 3), np.uint8)
    lo, hi = float(np.nanmin(v)), float(np.nanmax(v))
    scaled = np.zeros_like(v) if not hi > lo else (v - lo) * ((len(_RAMP) - 1) / (hi - lo))
    scaled = np.nan_to_num(scaled, nan=0.0)
    idx = np.clip(scaled.astype(np.int32), 0, len(_RAMP) - 2)
    frac = (scaled - idx)[:, None]
    return (_RAMP[idx] * (1 - frac) + _RAMP[idx + 1] * frac).astype(np.uint8)


def decode_cloud(msg: PointCloud2, budget: int | None = None) -> DecodedCloud:
    """Points and colours of a PointCloud2, at most ``budget`` points (even stride)."""
    fields = {f.name: f for f in msg.fields}
    if not all(axis in fields for axis in "xyz"):
        raise CloudFormatError("the cloud has no x, y, z fields")
    step = int(msg.point_step)
    total = int(msg.width) * int(msg.height)
    raw = np.frombuffer(msg.data, dtype=np.uint8)
    row_step = int(msg.row_step) or int(msg.width) * step
    if int(msg.height) > 1 and row_step != int(msg.width) * step:
        # padded rows: drop the padding once, then treat as one long row
        rows = raw[: row_step * int(msg.height)].reshape(int(msg.height), row_step)
        raw = np.ascontiguousarray(rows[:, : int(msg.width) * step]).reshape(-1)
    total = min(total, raw.size // step if step else 0)
    stride = 1 if not budget or total <= budget else math.ceil(total / budget)
    n = (total + stride - 1) // stride
    view_step = step * stride
    if n == 0:  # an empty cloud (a SLAM map before its first points): nothing to view into
        return DecodedCloud(np.empty((0, 3), np.float32), np.empty((0, 3), np.uint8), 0, "height")

    def column(name: str) -> np.ndarray:
        return _field_view(raw, n, view_step, fields[name], bool(msg.is_bigendian))

    def packed_colour(name: str) -> np.ndarray | None:
        """The 4 bytes of a packed rgb(a) field read as one integer, whatever its declared type."""
        field = fields[name]
        declared = _pointfield_dtype(int(field.datatype))
        size = declared.itemsize if declared is not None else 1
        if size != 4 or field.offset + 4 > step:
            return None
        dtype = np.dtype(">u4" if msg.is_bigendian else "<u4")
        return np.ndarray(
            shape=(n,), dtype=dtype, buffer=raw, offset=int(field.offset), strides=(view_step,)
        )

    points = np.empty((n, 3), dtype=np.float32)
    for i, axis in enumerate("xyz"):
        points[:, i] = column(axis)

    colour_source = "height"
    colors: np.ndarray | None = None
    for name in ("rgb", "rgba"):
        packed = packed_colour(name) if name in fields else None
        if packed is not None:
            colors = np.empty((n, 3), dtype=np.uint8)
            colors[:, 0] = (packed >> 16) & 0xFF
            colors[:, 1] = (packed >> 8) & 0xFF
            colors[:, 2] = packed & 0xFF
            colour_source = name
            break
    if colors is None and "intensity" in fields:
        colors = colour_ramp(column("intensity"))
        colour_source = "intensity"

    finite = np.isfinite(points).all(axis=1)
    if not finite.all():
        points = points[finite]
        colors = colors[finite] if colors is not None else None
    if colors is None:
        colors = colour_ramp(points[:, 2])
    return DecodedCloud(points, colors, total, colour_source)

"""sensor_msgs/PointCloud2 <-> numpy, in bulk (what sensor_msgs_py would do).

A PointCloud2 is a table: ``width * height`` points, each ``point_step``
bytes long, rows ``row_step`` bytes long. ``fields`` say where each column
lives inside a point (name, byte offset, datatype, count). Reading a cloud is
therefore one numpy *structured dtype* built from the fields and one
``np.frombuffer``: no Python loop per point.

Colours follow the PCL convention: a field named ``rgb`` (or ``rgba``) holding
0x00RRGGBB in a 32-bit word, often declared as FLOAT32. Separate ``r``, ``g``,
``b`` uint8 fields are read too.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

# sensor_msgs/PointField datatype constants -> numpy
POINTFIELD_DTYPES: dict[int, np.dtype] = {
    1: np.dtype(np.int8),
    2: np.dtype(np.uint8),
    3: np.dtype(np.int16),
    4: np.dtype(np.uint16),
    5: np.dtype(np.int32),
    6: np.dtype(np.uint32),
    7: np.dtype(np.float32),
    8: np.dtype(np.float64),
}
FLOAT32 = 7
UINT32 = 6


def fields_to_dtype(fields, point_step: int, is_bigendian: bool = False) -> np.dtype:
    """A structured dtype that lays the fields out exactly as in one point."""
    order: Literal[">", "<"] = ">" if is_bigendian else "<"
    names, formats, offsets = [], [], []
    for field in fields:
        base = POINTFIELD_DTYPES.get(int(field.datatype))
        if base is None:
            raise ValueError(f"field {field.name!r} has unknown datatype {field.datatype}")
        count = max(1, int(field.count))
        names.append(field.name)
        formats.append(
            (base.newbyteorder(order), (count,)) if count > 1 else base.newbyteorder(order)
        )
        offsets.append(int(field.offset))
    return np.dtype(
        {"names": names, "formats": formats, "offsets": offsets, "itemsize": point_step}
    )


def cloud_to_structured(msg) -> np.ndarray:
    """All points as a 1-D structured array (row padding skipped)."""
    dtype = fields_to_dtype(msg.fields, msg.point_step, bool(msg.is_bigendian))
    count = int(msg.width) * int(msg.height)
    buffer = np.frombuffer(msg.data, dtype=np.uint8)
    row_bytes = int(msg.width) * int(msg.point_step)
    if int(msg.height) > 1 and int(msg.row_step) != row_bytes:
        rows = buffer[: int(msg.height) * int(msg.row_step)].reshape(int(msg.height), -1)
        buffer = np.ascontiguousarray(rows[:, :row_bytes]).reshape(-1)
    if buffer.size < count * int(msg.point_step):
        raise ValueError("PointCloud2 data is shorter than width * height * point_step")
    return np.frombuffer(buffer[: count * int(msg.point_step)].tobytes(), dtype=dtype)


def field_names(msg) -> list[str]:
    return [field.name for field in msg.fields]


def unpack_rgb(packed: np.ndarray) -> np.ndarray:
    """0x00RRGGBB words (uint32, or float32 bit patterns) -> (N, 3) uint8 RGB."""
    words = np.ascontiguousarray(packed).view(np.uint32) if packed.dtype.itemsize == 4 else packed
    words = words.astype(np.uint32)
    return np.stack([(words >> 16) & 0xFF, (words >> 8) & 0xFF, words & 0xFF], axis=1).astype(
        np.uint8
    )


def pack_rgb(colors: np.ndarray) -> np.ndarray:
    """(N, 3) uint8 RGB -> uint32 words 0x00RRGGBB."""
    c = np.asarray(colors, dtype=np.uint32)
    return (c[:, 0] << 16) | (c[:, 1] << 8) | c[:, 2]


def _native(column: np.ndarray) -> np.ndarray:
    return column.astype(column.dtype.newbyteorder("="), copy=False)


def pointcloud2_to_xyz_rgb(msg, *, skip_nans: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
    """Points as (N, 3) float32 and colours as (N, 3) uint8 RGB (None without colour).

    x, y, z may be float32 or float64 (converted to float32). With
    ``skip_nans`` points with a non-finite coordinate are dropped.
    """
    cloud = cloud_to_structured(msg)
    names = set(cloud.dtype.names or ())
    missing = {"x", "y", "z"} - names
    if missing:
        raise ValueError(f"PointCloud2 has no {', '.join(sorted(missing))} field")
    xyz = np.empty((cloud.shape[0], 3), dtype=np.float32)
    for column, name in enumerate("xyz"):
        xyz[:, column] = _native(cloud[name])
    colors = None
    for name in ("rgb", "rgba"):
        if name in names:
            colors = unpack_rgb(_native(cloud[name]))
            break
    else:
        if {"r", "g", "b"} <= names:
            colors = np.stack([_native(cloud[c]) for c in "rgb"], axis=1).astype(np.uint8)
    if skip_nans:
        keep = np.isfinite(xyz).all(axis=1)
        if not keep.all():
            xyz = xyz[keep]
            colors = colors[keep] if colors is not None else None
    return xyz, colors


def pointcloud2_field(msg, name: str, *, dtype=np.float32) -> np.ndarray:
    """One column (for example ``intensity``) as a 1-D array of ``dtype``."""
    cloud = cloud_to_structured(msg)
    if name not in (cloud.dtype.names or ()):
        raise KeyError(f"PointCloud2 has no field {name!r}; fields: {field_names(msg)}")
    return _native(cloud[name]).astype(dtype)


def pack_xyz_rgb(points: np.ndarray, colors: np.ndarray | None = None) -> tuple[bytes, int]:
    """Bytes of an unordered cloud: x y z float32, plus rgb (0x00RRGGBB) when given.

    Returns ``(data, point_step)``.
    """
    pts = np.asarray(points, dtype=np.float32).reshape(-1, 3)
    if colors is None:
        return np.ascontiguousarray(pts).tobytes(), 12
    cols = np.asarray(colors).reshape(-1, 3)
    if cols.shape[0] != pts.shape[0]:
        raise ValueError(f"{pts.shape[0]} points but {cols.shape[0]} colours")
    table = np.empty(pts.shape[0], dtype=[("xyz", "<f4", (3,)), ("rgb", "<u4")])
    table["xyz"] = pts
    table["rgb"] = pack_rgb(cols)
    return table.tobytes(), 16


def xyz_to_pointcloud2(points, colors=None, *, frame_id: str = "map", stamp=None):
    """An unordered sensor_msgs/PointCloud2 (height 1) from (N, 3) points and optional RGB."""
    from sensor_msgs.msg import PointCloud2, PointField

    data, point_step = pack_xyz_rgb(points, colors)
    fields = [
        PointField(name=name, offset=4 * i, datatype=FLOAT32, count=1)
        for i, name in enumerate("xyz")
    ]
    if colors is not None:
        fields.append(PointField(name="rgb", offset=12, datatype=FLOAT32, count=1))
    count = len(data) // point_step
    msg = PointCloud2(
        height=1,
        width=count,
        fields=fields,
        is_bigendian=False,
        point_step=point_step,
        row_step=point_step * count,
        is_dense=True,
    )
    msg.data = data
    msg.header.frame_id = frame_id
    if stamp is not None:
        msg.header.stamp = stamp
    return msg

"""PointCloud2 packing and decoding in bulk (no ROS graph)."""

from __future__ import annotations

import numpy as np
import pytest
from sensor_msgs.msg import PointCloud2, PointField

from nodes.common.pointcloud import (
    pack_rgb,
    pointcloud2_field,
    pointcloud2_to_xyz_rgb,
    unpack_rgb,
    xyz_to_pointcloud2,
)

rng = np.random.default_rng(4)


def test_xyz_only_cloud_layout_and_round_trip():
    points = rng.normal(size=(1000, 3)).astype(np.float32)
    msg = xyz_to_pointcloud2(points, frame_id="map")
    assert isinstance(msg, PointCloud2)
    assert [(f.name, f.offset, f.datatype, f.count) for f in msg.fields] == [
        ("x", 0, PointField.FLOAT32, 1),
        ("y", 4, PointField.FLOAT32, 1),
        ("z", 8, PointField.FLOAT32, 1),
    ]
    assert (msg.height, msg.width, msg.point_step, msg.row_step) == (1, 1000, 12, 12000)
    assert msg.header.frame_id == "map" and not msg.is_bigendian
    # Byte for byte: three little-endian float32 per point.
    np.testing.assert_array_equal(np.frombuffer(bytes(msg.data), "<f4").reshape(-1, 3), points)
    xyz, colors = pointcloud2_to_xyz_rgb(msg)
    np.testing.assert_array_equal(xyz, points)
    assert colors is None


def test_colour_is_packed_the_pcl_way():
    points = rng.normal(size=(50, 3))
    colors = rng.integers(0, 256, (50, 3), dtype=np.uint8)
    msg = xyz_to_pointcloud2(points, colors)
    assert msg.point_step == 16 and msg.fields[3].name == "rgb" and msg.fields[3].offset == 12
    words = np.frombuffer(bytes(msg.data), np.uint32).reshape(-1, 4)[:, 3]
    assert words[0] == (int(colors[0, 0]) << 16) | (int(colors[0, 1]) << 8) | int(colors[0, 2])
    xyz, rgb = pointcloud2_to_xyz_rgb(msg)
    np.testing.assert_allclose(xyz, points.astype(np.float32))
    np.testing.assert_array_equal(rgb, colors)
    np.testing.assert_array_equal(unpack_rgb(pack_rgb(colors)), colors)


def _cloud(table: np.ndarray, fields, *, height=1, row_step=None, bigendian=False) -> PointCloud2:
    count = table.shape[0]
    width = count // height
    msg = PointCloud2(
        height=height,
        width=width,
        fields=[PointField(name=n, offset=o, datatype=d, count=1) for n, o, d in fields],
        is_bigendian=bigendian,
        point_step=table.dtype.itemsize,
        row_step=row_step or table.dtype.itemsize * width,
        is_dense=False,
    )
    return msg


def test_float64_xyz_with_intensity_and_padding():
    # x y z float64, intensity float32, 4 bytes of padding: point_step 32.
    dtype = np.dtype(
        {
            "names": ["x", "y", "z", "intensity"],
            "formats": ["<f8"] * 3 + ["<f4"],
            "offsets": [0, 8, 16, 24],
            "itemsize": 32,
        }
    )
    table = np.zeros(6, dtype)
    coords = rng.normal(size=(6, 3))
    for i, name in enumerate("xyz"):
        table[name] = coords[:, i]
    table["intensity"] = np.arange(6) * 10.0
    msg = _cloud(table, [("x", 0, 8), ("y", 8, 8), ("z", 16, 8), ("intensity", 24, 7)])
    msg.data = table.tobytes()
    xyz, colors = pointcloud2_to_xyz_rgb(msg)
    assert xyz.dtype == np.float32 and colors is None
    np.testing.assert_allclose(xyz, coords.astype(np.float32))
    np.testing.assert_array_equal(pointcloud2_field(msg, "intensity"), np.arange(6) * 10.0)
    with pytest.raises(KeyError):
        pointcloud2_field(msg, "ring")


def test_organised_cloud_with_row_padding_big_endian_and_nans():
    dtype = np.dtype([("x", ">f4"), ("y", ">f4"), ("z", ">f4")])
    table = np.zeros(6, dtype)
    coords = rng.normal(size=(6, 3)).astype(np.float32)
    coords[4] = np.nan  # an organised cloud marks missing returns with NaN
    for i, name in enumerate("xyz"):
        table[name] = coords[:, i]
    rows = table.reshape(2, 3)
    data = b"".join(row.tobytes() + b"\xff" * 8 for row in rows)  # 8 padding bytes per row
    msg = _cloud(
        table, [("x", 0, 7), ("y", 4, 7), ("z", 8, 7)], height=2, row_step=44, bigendian=True
    )
    msg.data = data
    xyz, _ = pointcloud2_to_xyz_rgb(msg)
    np.testing.assert_array_equal(xyz, np.delete(coords, 4, axis=0))
    everything, _ = pointcloud2_to_xyz_rgb(msg, skip_nans=False)
    assert everything.shape == (6, 3) and np.isnan(everything[4]).all()


def test_separate_rgb_bytes_are_read():
    dtype = np.dtype(
        {
            "names": list("xyzrgb"),
            "formats": ["<f4"] * 3 + ["u1"] * 3,
            "offsets": [0, 4, 8, 12, 13, 14],
            "itemsize": 16,
        }
    )
    table = np.zeros(3, dtype)
    table["r"], table["g"], table["b"] = [1, 2, 3], [4, 5, 6], [7, 8, 9]
    fields = [("x", 0, 7), ("y", 4, 7), ("z", 8, 7), ("r", 12, 2), ("g", 13, 2), ("b", 14, 2)]
    msg = _cloud(table, fields)
    msg.data = table.tobytes()
    _, colors = pointcloud2_to_xyz_rgb(msg)
    np.testing.assert_array_equal(colors, [[1, 4, 7], [2, 5, 8], [3, 6, 9]])


def test_missing_coordinates_are_an_error():
    table = np.zeros(2, [("x", "<f4"), ("y", "<f4")])
    msg = _cloud(table, [("x", 0, 7), ("y", 4, 7)])
    msg.data = table.tobytes()
    with pytest.raises(ValueError, match="no z field"):
        pointcloud2_to_xyz_rgb(msg)


def test_a_large_cloud_packs_fast_enough_to_mean_no_python_loop():
    import time

    points = rng.normal(size=(300_000, 3)).astype(np.float32)
    colors = rng.integers(0, 256, (300_000, 3), dtype=np.uint8)
    start = time.perf_counter()
    msg = xyz_to_pointcloud2(points, colors)
    xyz, rgb = pointcloud2_to_xyz_rgb(msg)
    assert time.perf_counter() - start < 5.0  # a per-point loop would take far longer
    assert xyz.shape == (300_000, 3) and rgb.shape == (300_000, 3)

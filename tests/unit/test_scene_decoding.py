"""Pure decoding for the 3D view: PointCloud2 and Image messages to numpy, no ROS graph."""

from __future__ import annotations

import array

import numpy as np
import pytest
from sensor_msgs.msg import PointCloud2, PointField

from app.scene.cloud_codec import CloudFormatError, decode_cloud
from app.scene.image_codec import ImageFormatError, image_to_rgb, rgb_to_image_msg
from nodes.common.pointcloud import xyz_to_pointcloud2
from nodes.common.pointcloud import xyz_to_pointcloud2 as encode_cloud


def test_xyz_and_packed_rgb_round_trip():
    rng = np.random.default_rng(1)
    pts = rng.normal(size=(1000, 3)).astype(np.float32)
    cols = rng.integers(0, 256, size=(1000, 3), dtype=np.uint8)
    cloud = decode_cloud(encode_cloud(pts, cols))
    np.testing.assert_array_equal(cloud.points, pts)
    np.testing.assert_array_equal(cloud.colors, cols)
    assert cloud.colour_source == "rgb" and cloud.total == 1000 and cloud.shown == 1000


def test_reads_clouds_written_by_the_perception_nodes_helper():
    pts = np.array([[1, 2, 3], [4, 5, 6]], dtype=np.float32)
    cols = np.array([[255, 0, 0], [0, 0, 255]], dtype=np.uint8)
    cloud = decode_cloud(xyz_to_pointcloud2(pts, cols, frame_id="map"))
    np.testing.assert_array_equal(cloud.points, pts)
    np.testing.assert_array_equal(cloud.colors, cols)


def _cloud(fields: list[tuple[str, int, int]], step: int, data: bytes, n: int, big=False):
    msg = PointCloud2()
    msg.fields = [PointField(name=a, offset=o, datatype=t, count=1) for a, o, t in fields]
    msg.point_step, msg.width, msg.height = step, n, 1
    msg.row_step = step * n
    msg.is_bigendian = big
    msg.data = array.array("B", data)
    return msg


def test_float64_xyz_with_padding_and_intensity_colouring():
    dtype = np.dtype(
        {
            "names": ["x", "y", "z", "i"],
            "formats": ["<f8"] * 3 + ["<f4"],
            "offsets": [0, 8, 16, 28],
            "itemsize": 32,
        }
    )
    table = np.zeros(3, dtype=dtype)
    table["x"], table["y"], table["z"] = [0.5, 1.5, 2.5], [1, 2, 3], [-1, -2, -3]
    table["i"] = [0.0, 50.0, 100.0]
    msg = _cloud(
        [("x", 0, 8), ("y", 8, 8), ("z", 16, 8), ("intensity", 28, 7)], 32, table.tobytes(), 3
    )
    cloud = decode_cloud(msg)
    np.testing.assert_allclose(cloud.points[:, 0], [0.5, 1.5, 2.5])
    assert cloud.colour_source == "intensity"
    # low and high intensity get different ends of the ramp
    assert not np.array_equal(cloud.colors[0], cloud.colors[2])


def test_big_endian_float32():
    pts = np.array([[1.0, -2.0, 3.5]], dtype=">f4")
    msg = _cloud([("x", 0, 7), ("y", 4, 7), ("z", 8, 7)], 12, pts.tobytes(), 1, big=True)
    np.testing.assert_array_equal(decode_cloud(msg).points, [[1.0, -2.0, 3.5]])


def test_budget_decimates_evenly_and_reports_the_total():
    pts = np.arange(300_000, dtype=np.float32).reshape(-1, 3)
    cloud = decode_cloud(encode_cloud(pts), budget=25_000)
    assert cloud.total == 100_000
    assert cloud.shown == 25_000
    np.testing.assert_array_equal(cloud.points[1], pts[4])  # every 4th point


def test_non_finite_points_are_dropped_with_their_colours():
    pts = np.array([[0, 0, 0], [np.nan, 0, 0], [1, 1, 1]], dtype=np.float32)
    cols = np.array([[1, 2, 3], [4, 5, 6], [7, 8, 9]], dtype=np.uint8)
    cloud = decode_cloud(encode_cloud(pts, cols))
    assert cloud.shown == 2
    np.testing.assert_array_equal(cloud.colors, [[1, 2, 3], [7, 8, 9]])


@pytest.mark.parametrize("budget", [None, 5])
def test_an_empty_cloud_decodes_to_no_points(budget):
    """A SLAM map before its first points, with and without a stored byte: nothing to draw."""
    empty = encode_cloud(np.empty((0, 3), np.float32), np.empty((0, 3), np.uint8))
    padded = _cloud([("x", 0, 7), ("y", 4, 7), ("z", 8, 7)], 16, b"", 0)
    for msg in (empty, padded):
        cloud = decode_cloud(msg, budget=budget)
        assert (cloud.total, cloud.shown, cloud.colors.shape) == (0, 0, (0, 3))


def test_cloud_without_xyz_is_refused():
    msg = _cloud([("intensity", 0, 7)], 4, b"\0" * 8, 2)
    with pytest.raises(CloudFormatError):
        decode_cloud(msg)


@pytest.mark.parametrize("encoding", ["rgb8", "bgr8"])
def test_colour_images_come_out_rgb(encoding):
    rgb = np.zeros((4, 6, 3), np.uint8)
    rgb[..., 0] = 200  # red
    out = image_to_rgb(rgb_to_image_msg(rgb, encoding))
    assert out.shape == (4, 6, 3)
    np.testing.assert_array_equal(out[0, 0], [200, 0, 0])


def test_mono8_with_row_padding():
    msg = rgb_to_image_msg(np.zeros((2, 3), np.uint8), "mono8")
    msg.step = 4  # one byte of padding per row
    msg.data = array.array("B", bytes([10, 20, 30, 0, 40, 50, 60, 0]))
    out = image_to_rgb(msg)
    np.testing.assert_array_equal(out[1, :, 1], [40, 50, 60])


def test_unknown_image_encoding_is_explained():
    msg = rgb_to_image_msg(np.zeros((2, 2, 3), np.uint8))
    msg.encoding = "yuv422"
    with pytest.raises(ImageFormatError, match="bgr8"):
        image_to_rgb(msg)


def test_latest_worker_draws_the_newest_and_skips_the_backlog():
    import threading
    import time

    from app.scene.latest import LatestWorker

    drawn: list[int] = []
    gate, drawing = threading.Event(), threading.Event()

    def draw(msg: int) -> None:
        drawing.set()
        gate.wait(2.0)  # a slow browser update
        drawn.append(msg)

    worker = LatestWorker("test", draw, max_hz=1000.0)
    try:
        worker.offer(0)
        assert drawing.wait(10)  # the worker holds 0, however busy the machine
        for i in range(1, 50):  # arrive while 0 is still being drawn
            worker.offer(i)
        gate.set()
        deadline = time.monotonic() + 10.0
        while (not drawn or drawn[-1] != 49) and time.monotonic() < deadline:
            time.sleep(0.01)
        assert drawn == [0, 49]
        received, count, _rate, since = worker.stats()
        assert received == 50 and count == 2 and since is not None
    finally:
        worker.stop()

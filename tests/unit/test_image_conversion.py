"""sensor_msgs/Image <-> numpy for bgr8, rgb8, mono8 (and 16-bit / float), no ROS graph."""

from __future__ import annotations

import numpy as np
import pytest
from sensor_msgs.msg import Image

from nodes.common.image_conversion import (
    UnsupportedEncoding,
    array_to_bytes,
    array_to_image,
    bytes_to_array,
    image_to_array,
    to_bgr8,
)

rng = np.random.default_rng(9)


@pytest.mark.parametrize(
    ("encoding", "shape"), [("bgr8", (4, 5, 3)), ("rgb8", (4, 5, 3)), ("mono8", (4, 5))]
)
def test_round_trip_through_a_message(encoding, shape):
    pixels = rng.integers(0, 256, shape, dtype=np.uint8)
    msg = array_to_image(pixels, encoding)
    assert isinstance(msg, Image)
    assert (msg.height, msg.width, msg.encoding) == (4, 5, encoding)
    assert msg.step == 5 * (3 if len(shape) == 3 else 1)
    assert len(msg.data) == msg.step * msg.height
    np.testing.assert_array_equal(image_to_array(msg), pixels)


def test_bgr8_byte_layout_is_blue_green_red():
    pixel = np.array([[[10, 20, 30]]], np.uint8)  # B, G, R
    data, height, width, step = array_to_bytes(pixel, "bgr8")
    assert data == bytes([10, 20, 30]) and (height, width, step) == (1, 1, 3)
    # The same colour written as rgb8 reads back as the same BGR triple.
    rgb = bytes_to_array(bytes([30, 20, 10]), 1, 1, "rgb8", 3)
    np.testing.assert_array_equal(to_bgr8(rgb, "rgb8"), pixel)


@pytest.mark.parametrize(("encoding", "channels"), [("bgr8", 3), ("rgb8", 3), ("mono8", 1)])
def test_row_padding_is_skipped(encoding, channels):
    height, width, pad = 3, 5, 7
    pixels = rng.integers(0, 256, (height, width * channels), dtype=np.uint8)
    padded = np.concatenate([pixels, np.full((height, pad), 0xEE, np.uint8)], axis=1)
    step = width * channels + pad
    out = bytes_to_array(padded.tobytes(), height, width, encoding, step)
    expected = pixels.reshape(height, width, channels) if channels > 1 else pixels
    np.testing.assert_array_equal(out, expected)


def test_mono8_to_bgr8_copies_the_grey_level():
    grey = np.array([[0, 128, 255]], np.uint8)
    np.testing.assert_array_equal(to_bgr8(grey, "mono8")[0, :, 0], grey[0])
    np.testing.assert_array_equal(to_bgr8(grey, "mono8")[0, :, 2], grey[0])


@pytest.mark.parametrize("bigendian", [False, True])
def test_sixteen_bit_images_honour_is_bigendian(bigendian):
    values = np.array([[1, 256, 65535]], np.uint16)
    raw = values.astype(">u2" if bigendian else "<u2").tobytes()
    out = bytes_to_array(raw, 1, 3, "mono16", 6, is_bigendian=bigendian)
    np.testing.assert_array_equal(out, values)
    assert out.dtype.isnative


def test_float_depth_image_big_endian_with_padding():
    depth = np.array([[0.5, 1.25], [2.0, np.inf]], np.float32)
    rows = [depth[r].astype(">f4").tobytes() + b"\x00\x00\x00\x00" for r in range(2)]
    out = bytes_to_array(b"".join(rows), 2, 2, "32FC1", 12, is_bigendian=True)
    np.testing.assert_array_equal(out, depth)


def test_message_fields_are_read_not_assumed():
    msg = Image(height=2, width=2, encoding="mono8", step=4, is_bigendian=0)
    msg.data = bytes([1, 2, 99, 99, 3, 4, 99, 99])
    np.testing.assert_array_equal(image_to_array(msg), [[1, 2], [3, 4]])


def test_errors_are_explicit():
    with pytest.raises(UnsupportedEncoding):
        bytes_to_array(b"\x00" * 4, 1, 1, "yuv422", 4)
    with pytest.raises(ValueError, match="smaller than one row"):
        bytes_to_array(b"\x00" * 12, 2, 2, "bgr8", 3)
    with pytest.raises(ValueError, match="buffer holds"):
        bytes_to_array(b"\x00" * 3, 2, 2, "mono8", 2)
    with pytest.raises(ValueError, match="dtype"):
        array_to_bytes(np.zeros((2, 2, 3), np.float32), "bgr8")
    with pytest.raises(ValueError, match="array"):
        array_to_bytes(np.zeros((2, 2), np.uint8), "rgb8")

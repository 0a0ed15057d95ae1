"""sensor_msgs/Image <-> numpy, written out (what cv_bridge would do).

An Image message is a flat byte buffer plus the facts needed to read it:

- ``height`` rows of ``step`` bytes each. ``step`` may be larger than
  ``width * channels * bytes_per_channel``: the extra bytes at the end of each
  row are padding and must be skipped;
- ``encoding`` names the pixel layout (``bgr8``, ``rgb8``, ``mono8``, ...);
- ``is_bigendian`` matters for pixels wider than one byte (``mono16``,
  ``32FC1``): it says in which byte order each value was written.

The numpy core (:func:`bytes_to_array`, :func:`array_to_bytes`) needs no ROS;
:func:`image_to_array` and :func:`array_to_image` wrap it for the message.
"""

from __future__ import annotations

import sys
from typing import Literal

import numpy as np

# encoding -> (numpy dtype of one channel, number of channels)
ENCODINGS: dict[str, tuple[np.dtype, int]] = {
    "mono8": (np.dtype(np.uint8), 1),
    "8UC1": (np.dtype(np.uint8), 1),
    "bgr8": (np.dtype(np.uint8), 3),
    "rgb8": (np.dtype(np.uint8), 3),
    "8UC3": (np.dtype(np.uint8), 3),
    "bgra8": (np.dtype(np.uint8), 4),
    "rgba8": (np.dtype(np.uint8), 4),
    "mono16": (np.dtype(np.uint16), 1),
    "16UC1": (np.dtype(np.uint16), 1),
    "32FC1": (np.dtype(np.float32), 1),
}

HOST_IS_BIGENDIAN = sys.byteorder == "big"


class UnsupportedEncoding(ValueError):
    pass


def _layout(encoding: str) -> tuple[np.dtype, int]:
    try:
        return ENCODINGS[encoding]
    except KeyError:
        known = ", ".join(ENCODINGS)
        raise UnsupportedEncoding(f"encoding {encoding!r} is not supported ({known})") from None


def bytes_to_array(
    data, height: int, width: int, encoding: str, step: int, is_bigendian: bool = False
) -> np.ndarray:
    """The pixels of an image buffer as an array (H, W) or (H, W, C), native byte order.

    The result is a view of ``data`` when no copy is needed (read-only then).
    """
    dtype, channels = _layout(encoding)
    row_bytes = width * channels * dtype.itemsize
    if step < row_bytes:
        raise ValueError(f"step {step} is smaller than one row of pixels ({row_bytes} bytes)")
    buffer = np.frombuffer(data, dtype=np.uint8)
    if buffer.size < height * step:
        raise ValueError(f"buffer holds {buffer.size} bytes, expected {height} rows x {step}")
    rows = buffer[: height * step].reshape(height, step)[:, :row_bytes]
    if dtype.itemsize > 1:
        rows = np.ascontiguousarray(rows)  # a padded view cannot be re-typed in place
    order: Literal[">", "<"] = ">" if is_bigendian else "<"
    pixels = rows.view(dtype.newbyteorder(order)).reshape(height, width, channels)
    if dtype.itemsize > 1 and bool(is_bigendian) != HOST_IS_BIGENDIAN:
        pixels = pixels.astype(dtype)  # to native order
    return pixels[:, :, 0] if channels == 1 else pixels


def array_to_bytes(array: np.ndarray, encoding: str) -> tuple[bytes, int, int, int]:
    """Pack an array for an Image: returns ``(data, height, width, step)``, no padding.

    The bytes are in the host's order (report ``is_bigendian`` accordingly).
    """
    dtype, channels = _layout(encoding)
    pixels = np.asarray(array)
    if channels == 1 and pixels.ndim == 3 and pixels.shape[2] == 1:
        pixels = pixels[:, :, 0]
    expected_ndim = 2 if channels == 1 else 3
    if pixels.ndim != expected_ndim or (channels > 1 and pixels.shape[2] != channels):
        raise ValueError(
            f"{encoding} needs an (H, W{'' if channels == 1 else f', {channels}'}) array, "
            f"got shape {pixels.shape}"
        )
    if pixels.dtype != dtype:
        raise ValueError(f"{encoding} needs dtype {dtype}, got {pixels.dtype}")
    height, width = pixels.shape[:2]
    data = np.ascontiguousarray(pixels).tobytes()
    return data, height, width, width * channels * dtype.itemsize


def to_bgr8(array: np.ndarray, encoding: str) -> np.ndarray:
    """Any supported image as a bgr8 array for OpenCV drawing and display."""
    import cv2

    if encoding in ("bgr8", "8UC3"):
        return np.asarray(array)
    if encoding == "rgb8":
        return np.ascontiguousarray(array[:, :, ::-1])
    if encoding == "bgra8":
        return cv2.cvtColor(array, cv2.COLOR_BGRA2BGR)
    if encoding == "rgba8":
        return cv2.cvtColor(array, cv2.COLOR_RGBA2BGR)
    if encoding in ("mono8", "8UC1"):
        return cv2.cvtColor(array, cv2.COLOR_GRAY2BGR)
    # 16-bit and float images: stretch to 0..255 for viewing.
    values = np.nan_to_num(array.astype(np.float32))
    low, high = float(values.min()), float(values.max())
    scaled = ((values - low) * (255.0 / (high - low)) if high > low else values * 0).astype(
        np.uint8
    )
    return cv2.cvtColor(scaled, cv2.COLOR_GRAY2BGR)


def image_to_array(msg) -> np.ndarray:
    """A sensor_msgs/Image (or anything with its fields) as a numpy array."""
    return bytes_to_array(
        msg.data, msg.height, msg.width, msg.encoding, msg.step, bool(msg.is_bigendian)
    )


def array_to_image(array: np.ndarray, encoding: str = "bgr8", header=None):
    """A numpy array as a new sensor_msgs/Image."""
    from sensor_msgs.msg import Image

    data, height, width, step = array_to_bytes(array, encoding)
    msg = Image(
        height=height,
        width=width,
        encoding=encoding,
        is_bigendian=int(HOST_IS_BIGENDIAN),
        step=step,
    )
    msg.data = data
    if header is not None:
        msg.header = header
    return msg


def image_to_bgr8(msg, logger) -> np.ndarray | None:
    """A received Image as a bgr8 array, or None after a warning (throttled) saying why.

    A subscriber cannot refuse a message: a frame it cannot read is skipped, never fatal.
    """
    try:
        return to_bgr8(image_to_array(msg), msg.encoding)
    except ValueError as exc:
        logger.warning(f"cannot read image: {exc}", throttle_duration_sec=5.0)
        return None

"""sensor_msgs/Image -> an RGB numpy array (bgr8, rgb8, mono8, and a few cousins).

One reshape over the message buffer, honouring ``step`` (row padding); no
per-pixel Python.
"""

from __future__ import annotations

import array
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from sensor_msgs.msg import Image

_CHANNELS = {"rgb8": 3, "bgr8": 3, "rgba8": 4, "bgra8": 4, "mono8": 1, "8UC1": 1, "8UC3": 3}


class ImageFormatError(ValueError):
    """An encoding the panel does not draw."""


def image_to_rgb(msg: Image) -> np.ndarray:
    """(H, W, 3) uint8 RGB view or copy of the image in ``msg``."""
    enc = msg.encoding
    if enc == "mono16" or enc == "16UC1":
        raw = np.frombuffer(msg.data, dtype=">u2" if msg.is_bigendian else "<u2")
        rows = raw[: msg.height * (msg.step // 2)].reshape(msg.height, msg.step // 2)
        gray = rows[:, : msg.width].astype(np.float32)
        top = float(gray.max()) or 1.0
        mono = (gray * (255.0 / top)).astype(np.uint8)
        return np.repeat(mono[:, :, None], 3, axis=2)
    channels = _CHANNELS.get(enc)
    if channels is None:
        raise ImageFormatError(f"encoding {enc!r} is not drawn (use bgr8, rgb8 or mono8)")
    raw = np.frombuffer(msg.data, dtype=np.uint8)
    rows = raw[: msg.height * msg.step].reshape(msg.height, msg.step)
    pixels = rows[:, : msg.width * channels].reshape(msg.height, msg.width, channels)
    if channels == 1:
        return np.repeat(pixels, 3, axis=2)
    if enc.startswith("bgr") or enc == "8UC3":  # OpenCV's default order
        return pixels[:, :, 2::-1]
    return pixels[:, :, :3]


def downscale(rgb: np.ndarray, max_width: int) -> np.ndarray:
    """Integer-stride shrink so a big camera image stays a small jpeg."""
    step = max(1, -(-rgb.shape[1] // max_width))
    return rgb[::step, ::step] if step > 1 else rgb


def rgb_to_image_msg(rgb: np.ndarray, encoding: str = "rgb8", frame_id: str = "camera") -> Image:
    """An Image message from an (H, W, 3) or (H, W) uint8 array; for tests and demos."""
    from sensor_msgs.msg import Image

    arr = np.ascontiguousarray(rgb, dtype=np.uint8)
    msg = Image()
    msg.header.frame_id = frame_id
    msg.height, msg.width = int(arr.shape[0]), int(arr.shape[1])
    channels = 1 if arr.ndim == 2 else int(arr.shape[2])
    if encoding == "bgr8":
        arr = np.ascontiguousarray(arr[:, :, ::-1])
    msg.encoding = encoding
    msg.is_bigendian = 0
    msg.step = msg.width * channels
    msg.data = array.array("B", arr.tobytes())
    return msg

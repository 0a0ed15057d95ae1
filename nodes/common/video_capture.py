"""Frames from an OpenCV ``VideoCapture`` (a file or a webcam) at a fixed size."""

from __future__ import annotations

import cv2
import numpy as np


def read_frame(capture: cv2.VideoCapture, loop: bool, width: int, height: int) -> np.ndarray | None:
    """The next frame as bgr8, resized to width x height; None once a file ends.

    With ``loop`` a file starts again from its first frame instead of ending.
    """
    ok, frame = capture.read()
    if not ok and loop:
        capture.set(cv2.CAP_PROP_POS_FRAMES, 0)
        ok, frame = capture.read()
    if not ok:
        return None
    if frame.shape[1] != width or frame.shape[0] != height:
        frame = cv2.resize(frame, (width, height), interpolation=cv2.INTER_AREA)
    return frame

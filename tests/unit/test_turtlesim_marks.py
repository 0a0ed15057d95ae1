"""Turtlesim's window draws other TF frames (the tf2 lesson's carrot) as orange marks, and
two windows side by side in one picture (multisim)."""

from __future__ import annotations

import time
from types import SimpleNamespace

import numpy as np

from app.panels.turtlesim_view import MARK, SideBySide, TurtlesimView, to_pixel
from nodes.common.turtlesim_world import PIXELS


def _wait_for(frames: list[np.ndarray], test, timeout: float = 5.0) -> np.ndarray:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if frames and test(frames[-1]):
            return frames[-1]
        time.sleep(0.05)
    raise AssertionError("no such frame was drawn")


def test_a_frame_in_world_is_drawn_where_it_is_and_forgotten_when_gone():
    frames: list[np.ndarray] = []
    view = TurtlesimView(None, lambda: None, show=frames.append)  # type: ignore[arg-type]
    try:
        x, y = (int(round(v)) for v in to_pixel(3.0, 8.0))
        orange = lambda f: tuple(f[y, x]) == MARK  # noqa: E731
        view.set_marks({"carrot1": (3.0, 8.0)})
        _wait_for(frames, orange)
        view.set_marks({"carrot1": (30.0, 8.0)})  # outside the window: nothing drawn, no error
        frame = _wait_for(frames, lambda f: not orange(f))
        assert not (frame == np.array(MARK, np.uint8)).all(axis=2).any()
    finally:
        view.close()


def test_two_windows_share_one_picture_side_by_side():
    handle = SimpleNamespace(image=None, visible=True)
    gui = SimpleNamespace(add_image=lambda image, **_: handle)
    pair = SideBySide(gui)  # type: ignore[arg-type]
    left = np.zeros((PIXELS, PIXELS, 3), np.uint8)
    right = np.full((PIXELS, PIXELS, 3), 7, np.uint8)
    pair.left(left)
    pair.right(right)
    image = handle.image
    assert image.shape == (PIXELS, 2 * PIXELS + SideBySide.GAP_PX, 3)
    assert (image[:, :PIXELS] == 0).all() and (image[:, -PIXELS:] == 7).all()

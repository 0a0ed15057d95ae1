"""The 3D view's map layer: the picture it lays on the floor, and where (no browser, no DDS)."""

from __future__ import annotations

import array
import math
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
from nav_msgs.msg import OccupancyGrid

from app.scene.occupancy_grid import (
    FREE_RGBA,
    OCCUPIED_RGBA,
    UNKNOWN_RGBA,
    OccupancyGridLayer,
    grid_image,
    placement,
)


class FakeScene:
    def __init__(self) -> None:
        self.images: dict[str, dict[str, Any]] = {}

    def add_image(self, name: str, image: np.ndarray, **props: Any) -> Any:
        self.images[name] = {"image": image, **props}
        return SimpleNamespace(remove=lambda: self.images.pop(name, None))


def grid_msg(width=3, height=2, data=(0, 100, -1, 50, 0, 0), frame="map", yaw=0.0) -> OccupancyGrid:
    msg = OccupancyGrid()
    msg.header.frame_id = frame
    msg.info.width, msg.info.height, msg.info.resolution = width, height, 0.5
    msg.info.origin.position.x, msg.info.origin.position.y = -1.0, 2.0
    msg.info.origin.orientation.z = math.sin(yaw / 2)
    msg.info.origin.orientation.w = math.cos(yaw / 2)
    msg.data = array.array("b", data)
    return msg


def test_free_occupied_and_unknown_cells_look_different():
    image = grid_image([0, 100, -1, 50, 0, 0], 3, 2)
    assert image.shape == (2, 3, 4)
    assert tuple(image[0, 0]) == FREE_RGBA and tuple(image[0, 1]) == OCCUPIED_RGBA
    assert tuple(image[0, 2]) == UNKNOWN_RGBA
    assert OCCUPIED_RGBA[0] < image[1, 0, 0] < FREE_RGBA[0]  # 50: a grey between
    assert image[0, 2, 3] < image[0, 0, 3] < image[0, 1, 3]  # unknown is the most see-through


def test_the_picture_sits_on_the_map_with_its_origin_at_the_corner():
    (x, y, z), wxyz = placement(grid_msg())
    assert (x, y) == pytest.approx((-1.0 + 0.75, 2.0 + 0.5)) and 0 < z < 0.05
    assert wxyz == pytest.approx((1.0, 0.0, 0.0, 0.0))
    (x, y, _z), wxyz = placement(grid_msg(yaw=math.pi / 2))  # turned: the corner stays put
    assert (x, y) == pytest.approx((-1.0 - 0.5, 2.0 + 0.75))
    assert wxyz == pytest.approx((math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4)))


def test_the_layer_hangs_the_map_under_its_tf_frame_and_says_what_it_drew():
    scene = FakeScene()
    layer = OccupancyGridLayer(node=None, server=SimpleNamespace(scene=scene))  # type: ignore[arg-type]
    try:
        layer.draw(grid_msg())
        (name,) = scene.images
        assert name == "/tf_view/frames/map/occupancy_grid"
        drawn = scene.images[name]
        assert drawn["render_width"] == pytest.approx(1.5)
        assert drawn["render_height"] == pytest.approx(1.0)
        assert drawn["format"] == "png" and drawn["image"].shape == (2, 3, 4)
        assert "3 x 2 cells" in layer.note and "83 % known" in layer.note
        assert "in `map`" in layer.describe()
        layer.draw(grid_msg(frame="odom"))  # another frame: the old picture goes
        assert list(scene.images) == ["/tf_view/frames/odom/occupancy_grid"]
        layer.draw(grid_msg(data=(0, 0)))  # 2 cells for 3 x 2: refused, said why
        assert "not drawn" in layer.note and layer.describe() == layer.note
    finally:
        layer.worker.stop()


def test_a_frame_missing_from_tf_is_reported():
    scene = FakeScene()
    layer = OccupancyGridLayer(
        node=None,  # type: ignore[arg-type]
        server=SimpleNamespace(scene=scene),  # type: ignore[arg-type]
        frame_known=lambda frame: frame == "world",
    )
    try:
        layer.draw(grid_msg())
        assert "not on TF" in layer.describe()
    finally:
        layer.worker.stop()

"""bench/cloud_to_browser.py: each frame's stamp travels in its points' colours, so the page
can tell which frame's points it was sent (no ROS, no browser)."""

from __future__ import annotations

import math
import struct

import numpy as np
import pytest

from app.scene.cloud_codec import decode_cloud
from bench.cloud_to_browser import stamp_in_colours
from nodes.common.pointcloud import xyz_to_pointcloud2


@pytest.mark.parametrize(("size", "budget"), [(1_000, 2_000), (1_000, 200), (999, 100)])
def test_the_stamp_is_in_the_first_colours_a_viewer_under_its_budget_keeps(size, budget):
    rng = np.random.default_rng(3)
    colours = rng.integers(0, 255, size=(size, 3), dtype=np.uint8)
    msg = xyz_to_pointcloud2(rng.uniform(-1, 1, (size, 3)).astype(np.float32), colours)
    msg.header.stamp.sec, msg.header.stamp.nanosec = 1_765_152_000, 987_654_321
    stamp_in_colours(msg, math.ceil(size / budget))
    kept = decode_cloud(msg, budget).colors  # what the dashboard sends the page
    assert struct.unpack("<II", kept.reshape(-1)[:8].tobytes()) == (1_765_152_000, 987_654_321)
    stride = math.ceil(size / budget)
    assert np.array_equal(kept[3:], colours[::stride][3:])  # the rest as published

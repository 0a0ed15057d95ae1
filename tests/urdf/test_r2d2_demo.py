"""urdf_tutorial_r2d2's demo.launch.py as the catalog group: R2-D2 walks its circle on /tf."""

from __future__ import annotations

import math
import threading

import pytest
from tf2_msgs.msg import TFMessage

from app.catalog import lookup_group
from tests.conftest import wait_until

pytestmark = pytest.mark.ros


def test_r2d2_circles_and_its_joints_reach_tf(supervisor, probe) -> None:
    lock = threading.Lock()
    seen: dict[str, list] = {}

    def on_tf(msg: TFMessage) -> None:
        with lock:
            for t in msg.transforms:
                seen.setdefault(t.child_frame_id, []).append(t)

    probe.node.create_subscription(TFMessage, "/tf", on_tf, 100)
    for member in lookup_group("urdf_tutorial_r2d2_demo").members:
        supervisor.start(member)
    wait_until(
        lambda: all(len(seen.get(f, [])) > 20 for f in ("axis", "body", "head", "rod")),
        30,
        what="odom -> axis and R2-D2's moving joints on /tf",
    )
    with lock:
        axes = list(seen["axis"])
        rods = list(seen["rod"])
    assert all(t.header.frame_id == "odom" for t in axes)
    for t in axes:  # on a circle of 2 m at 0.7 m height
        v = t.transform.translation
        assert math.hypot(v.x, v.y) == pytest.approx(2.0, abs=1e-6) and v.z == pytest.approx(0.7)
    assert axes[-1].transform.translation.x != axes[0].transform.translation.x  # it walks
    heights = [t.transform.translation.z for t in rods]
    assert max(heights) > min(heights)  # the periscope moves (head -> rod)

"""The cloud layer keeps up with a 100k-point cloud at 20 Hz (no browser involved)."""

from __future__ import annotations

import time

import numpy as np
import pytest
from rclpy.qos import QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import PointCloud2

from app.access import make_server
from app.ros.runtime import RosRuntime
from app.scene.pointclouds import PointCloudLayer
from nodes.common.pointcloud import xyz_to_pointcloud2 as encode_cloud
from tests.conftest import free_port, wait_until

pytestmark = [pytest.mark.ros]


def test_cloud_layer_receives_most_frames_of_a_fast_cloud(probe):
    server, _ = make_server("127.0.0.1", free_port(), None)  # as the dashboard makes its own
    dash = RosRuntime("scene_rate_dashboard")
    pub = probe.node.create_publisher(
        PointCloud2, "/rate/cloud", QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE)
    )
    layer = PointCloudLayer(dash.node, server)
    try:
        wait_until(
            lambda: dash.node.get_publishers_info_by_topic("/rate/cloud"), 20, what="discovery"
        )
        layer.select("/rate/cloud")
        wait_until(lambda: pub.get_subscription_count(), 20, what="the layer to subscribe")
        msg = encode_cloud(np.random.default_rng(0).random((100_000, 3)), frame_id="base_link")
        start = time.monotonic()
        sent = 0
        while time.monotonic() - start < 5.0:
            pub.publish(msg)
            sent += 1
            time.sleep(0.05)
        received, drawn, rate, _ = layer.worker.stats()
        print(f"sent {sent} received {received} drawn {drawn} rate {rate}")
        assert received >= 0.7 * sent
        assert layer.status.shown == 100_000
    finally:
        layer.close()
        dash.shutdown()
        server.stop()

"""The stage's TF tree on real DDS, read through the dashboard's one TF reader.

A static frame sent before the stage is shown is in its tree at once (the
shared reader heard the latched message, a fresh subscription would hear it
again), a broadcaster started while it is shown joins the tree with its rate,
and a static frame whose broadcaster has left is not drawn on a later look.
"""

from __future__ import annotations

import pytest
from geometry_msgs.msg import TransformStamped
from tf2_ros import StaticTransformBroadcaster

from app.access import make_server
from app.ros import tf_sources
from app.ros.runtime import RosRuntime
from app.stage.tf_stage import STATIC_RATE, TfStage
from tests.conftest import free_port, wait_until
from tests.integration.core_helpers import DISCOVERY_TIMEOUT

pytestmark = pytest.mark.ros


def _static(parent: str, child: str) -> TransformStamped:
    t = TransformStamped()
    t.header.frame_id, t.child_frame_id = parent, child
    t.transform.rotation.w = 1.0
    return t


def test_the_tree_has_latched_frames_new_broadcasters_and_forgets_gone_ones(probe, supervisor):
    server, _ = make_server("127.0.0.1", free_port(), None)  # as the dashboard makes its own
    dash = RosRuntime("tf_stage_dashboard")
    sender: RosRuntime | None = RosRuntime("tf_stage_static_sender")
    shared = tf_sources.shared(dash.node)  # the TF tool's reader, open before the stage
    stage = TfStage(server.gui, dash.node)
    try:
        assert sender is not None
        StaticTransformBroadcaster(sender.node).sendTransform(_static("world", "lamp"))
        wait_until(
            lambda: any(f.frame == "lamp" and f.publisher_here for f in shared.frames()),
            timeout=DISCOVERY_TIMEOUT,
            what="the shared reader to hear the latched lamp frame",
        )
        stage.set_active(True)
        frames = stage.recorder.view_frames()
        assert frames.get("lamp", {}).get("parent") == "world", frames
        assert frames["lamp"]["rate"] == STATIC_RATE

        supervisor.start("fixed_frame_tf2_broadcaster")  # turtle1 -> carrot1, 10 Hz
        wait_until(
            lambda: stage.recorder.view_frames().get("carrot1", {}).get("rate", 0) > 5,
            timeout=DISCOVERY_TIMEOUT,
            what=lambda: f"carrot1 on the stage with a rate: {stage.recorder.view_frames()}",
        )
        assert stage.recorder.view_frames()["carrot1"]["parent"] == "turtle1"

        # The lamp's broadcaster leaves; a later look draws only what is still sent.
        stage.set_active(False)
        assert stage.recorder.view_frames() == {}
        sender.shutdown()
        sender = None
        wait_until(
            lambda: not any(f.frame == "lamp" and f.publisher_here for f in shared.frames()),
            timeout=DISCOVERY_TIMEOUT,
            what="the lamp's broadcaster to leave the graph",
        )
        stage.set_active(True)
        wait_until(
            lambda: "carrot1" in stage.recorder.view_frames(),
            timeout=DISCOVERY_TIMEOUT,
            what="carrot1 again on the later look",
        )
        assert "lamp" not in stage.recorder.view_frames()
    finally:
        stage.close()
        tf_sources.release(shared)
        if sender is not None:
            sender.shutdown()
        dash.shutdown()
        server.stop()

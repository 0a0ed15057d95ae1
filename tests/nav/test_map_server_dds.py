"""Nav2's map_server over real DDS: a hand-made map file served, bad files refused, never a crash.

The map files are written here as Nav2's documentation describes them; the
node is driven as a lifecycle manager (or ``ros2 lifecycle set``) drives it,
through its ``change_state`` service, and asked for maps through
``map_server/map`` (nav_msgs/GetMap) and ``map_server/load_map``
(nav2_msgs/LoadMap).
"""

from __future__ import annotations

import dataclasses
import threading
from pathlib import Path
from typing import Any

import pytest
from lifecycle_msgs.msg import State, Transition
from lifecycle_msgs.srv import ChangeState, GetState
from nav2_msgs.srv import LoadMap
from nav_msgs.msg import OccupancyGrid
from nav_msgs.srv import GetMap
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from app.catalog import lookup
from tests.conftest import wait_until
from tests.integration.core_helpers import wait_for_output

pytestmark = [pytest.mark.ros, pytest.mark.timeout(120)]

LATCHED = QoSProfile(
    depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)
# 3 x 2 pixels, top row first: occupied, free, unknown / free, free, occupied.
IMAGE = b"P5\n3 2\n255\n" + bytes([0, 254, 205, 254, 254, 0])
DATA = [0, 0, 100, 100, 0, -1]  # bottom row first
YAML = """image: {image}
mode: trinary
resolution: {resolution}
origin: [-2.000, 1.500, 0]
negate: 0
occupied_thresh: 0.65
free_thresh: 0.196
"""


def write_map(folder: Path, name: str, resolution: str = "0.050", image: str = "") -> str:
    (folder / f"{name}.pgm").write_bytes(IMAGE)
    path = folder / f"{name}.yaml"
    path.write_text(YAML.format(image=image or f"{name}.pgm", resolution=resolution))
    return str(path)


def call(node: Any, srv_type: Any, name: str, request: Any, timeout: float = 30.0) -> Any:
    client = node.create_client(srv_type, name)
    try:
        assert client.wait_for_service(timeout_sec=timeout), f"no service {name}"
        done = threading.Event()
        future = client.call_async(request)
        future.add_done_callback(lambda _f: done.set())
        assert done.wait(timeout), f"{name} did not answer"
        return future.result()
    finally:
        node.destroy_client(client)


def transition(node: Any, server: str, transition_id: int) -> bool:
    request = ChangeState.Request(transition=Transition(id=transition_id))
    return bool(call(node, ChangeState, f"{server}/change_state", request).success)


def state(node: Any, server: str) -> int:
    return int(call(node, GetState, f"{server}/get_state", GetState.Request()).current_state.id)


def test_map_server_serves_a_hand_made_map_and_answers_bad_files_with_result_codes(
    probe, supervisor, tmp_path
):
    node = probe.node
    maps: list[OccupancyGrid] = []
    node.create_subscription(OccupancyGrid, "/map", maps.append, LATCHED)
    good = write_map(tmp_path, "office")
    supervisor.start_program(lookup("map_server"), ("-p", f"yaml_filename:={good}"))

    # Unconfigured at first; an impossible transition is refused, the node lives on.
    assert state(node, "/map_server") == State.PRIMARY_STATE_UNCONFIGURED
    assert not transition(node, "/map_server", Transition.TRANSITION_ACTIVATE)
    assert transition(node, "/map_server", Transition.TRANSITION_CONFIGURE)
    assert transition(node, "/map_server", Transition.TRANSITION_ACTIVATE)
    wait_until(lambda: maps, timeout=20, what="the latched /map after activate")
    first = maps[-1]
    assert list(first.data) == DATA and (first.info.width, first.info.height) == (3, 2)
    assert first.header.frame_id == "map"
    assert (first.info.origin.position.x, first.info.origin.position.y) == (-2.0, 1.5)
    served = call(node, GetMap, "/map_server/map", GetMap.Request())
    assert list(served.map.data) == DATA

    # load_map: each bad file gets Nav2's result code, and the map stays as it was.
    broken = tmp_path / "broken.yaml"
    broken.write_text("image: office.pgm\nresolution: [0.05\n")
    cases = {
        "": LoadMap.Response.RESULT_MAP_DOES_NOT_EXIST,
        str(broken): LoadMap.Response.RESULT_INVALID_MAP_METADATA,
        write_map(tmp_path, "flat", resolution="0"): LoadMap.Response.RESULT_INVALID_MAP_METADATA,
        write_map(tmp_path, "lost", image="nowhere.pgm"): LoadMap.Response.RESULT_INVALID_MAP_DATA,
    }
    for url, code in cases.items():
        answer = call(node, LoadMap, "/map_server/load_map", LoadMap.Request(map_url=url))
        assert answer.result == code, (url, answer.result)
    assert list(call(node, GetMap, "/map_server/map", GetMap.Request()).map.data) == DATA

    # A good second map (as a file:// URL) is loaded, answered and published.
    second = tmp_path / "second"
    second.mkdir()
    url = write_map(second, "hall", resolution="0.1")
    answer = call(node, LoadMap, "/map_server/load_map", LoadMap.Request(map_url=f"file://{url}"))
    assert answer.result == LoadMap.Response.RESULT_SUCCESS
    assert answer.map.info.resolution == pytest.approx(0.1)
    wait_until(lambda: maps[-1].info.resolution == pytest.approx(0.1), what="the new /map")
    assert supervisor.status("map_server").active
    wait_for_output(supervisor, "map_server", "no such file")
    log = "\n".join(supervisor.output("map_server"))
    assert "Traceback" not in log
    assert "nowhere.pgm" in log and "no such file" in log


def test_a_map_server_whose_file_is_malformed_stays_unconfigured_and_running(
    probe, supervisor, tmp_path
):
    bad = tmp_path / "bad.yaml"
    bad.write_text("image: bad.pgm\nresolution: -0.05\norigin: [0, 0, 0]\nnegate: 0\n"
                   "occupied_thresh: 0.65\nfree_thresh: 0.196\n")  # fmt: skip
    entry = dataclasses.replace(lookup("map_server"), name="bad_map_server", node_name="/bad_map")
    supervisor.start_program(entry, ("-r", "__node:=bad_map", "-p", f"yaml_filename:={bad}"))
    node = probe.node
    assert not transition(node, "/bad_map", Transition.TRANSITION_CONFIGURE)
    assert state(node, "/bad_map") == State.PRIMARY_STATE_UNCONFIGURED
    # Logged before the answer, but read from the node's pipe a moment later.
    wait_for_output(supervisor, "bad_map_server", "positive number")
    log = "\n".join(supervisor.output("bad_map_server"))
    assert "Failed to load map yaml file" in log, log
    assert "Traceback" not in log
    # Fixed: the same node configures now.
    write_map(tmp_path, "bad")
    assert transition(node, "/bad_map", Transition.TRANSITION_CONFIGURE)
    assert state(node, "/bad_map") == State.PRIMARY_STATE_INACTIVE
    assert supervisor.status("bad_map_server").active

"""``ros2 launch nav2_bringup bringup_launch.py map:=... params_file:=...`` over DDS.

A copy of the package's params file with a few values changed (amcl's
max_particles, the global costmap's inflation_radius, the controller's
desired_linear_vel) and a key no node knows: the stack comes up to active
(both lifecycle managers' is_active), every node holds every parameter of its
section with the file's value (as ``ros2 param get`` reads it), the unknown key
is ignored as rclpy ignores it, and amcl's particle count follows the file.
"""

from __future__ import annotations

import sys
import threading
import time
from pathlib import Path
from typing import Any

import pytest
import yaml
from nav2_bringup import params_file
from nav2_msgs.msg import ParticleCloud
from rcl_interfaces.srv import GetParameters, ListParameters
from rclpy.parameter import parameter_value_to_python
from rclpy.qos import qos_profile_sensor_data
from std_srvs.srv import Empty, Trigger

from app import PROJECT_ROOT
from app.launch_prefix import PREFIX_ENV, ROS2LAUNCH_MAIN, launch_env
from app.ros.calls import call_service
from app.ros.context import CallContext, Limits
from app.supervisor import LearnerProgram
from tests.conftest import wait_until
from tests.nav.bringup_helpers import bringup_prefix, load, node_sections

pytestmark = [pytest.mark.ros, pytest.mark.timeout(150)]

MAP_YAML = PROJECT_ROOT / "nodes/worlds/office/map.yaml"
CHANGED = {
    ("amcl", "max_particles"): 800,
    ("amcl", "min_particles"): 300,
    ("controller_server", "FollowPath", "desired_linear_vel"): 0.3,
    ("global_costmap", "global_costmap", "inflation_layer", "inflation_radius"): 0.4,
}
UNKNOWN = "not_a_parameter_of_amcl"
MANAGERS = ("/lifecycle_manager_localization", "/lifecycle_manager_navigation")


def changed_copy(folder: Path) -> Path:
    document = load(params_file())
    for path, value in CHANGED.items():
        node, *rest = path
        table = document[node] if node not in ("global_costmap",) else document[node][rest.pop(0)]
        table = table["ros__parameters"]
        for key in rest[:-1]:
            table = table[key]
        table[rest[-1]] = value
    document["amcl"]["ros__parameters"][UNKNOWN] = 42
    out = folder / "my_nav2_params.yaml"
    out.write_text(yaml.safe_dump(document, sort_keys=False), encoding="utf-8")
    return out


def call(node: Any, srv_type: Any, name: str, request: Any, timeout: float = 20.0) -> Any:
    """One answer, as the dashboard asks: these requests are safe to repeat, so one that
    got no answer goes out once more (``call_service``'s ``resend_unanswered``: Fast DDS
    drops a reply when the server has not yet matched a new client's reader, which a
    loaded machine's discovery can take longer than its 100 ms wait for)."""
    ctx = CallContext(node, limits=Limits(service_timeout=timeout))
    return call_service(ctx, name, srv_type, request, resend_unanswered=True)


def test_bringup_launch_brings_the_stack_up_with_the_params_file(probe, supervisor, tmp_path):
    started = time.monotonic()
    node = probe.node
    prefix = bringup_prefix(tmp_path / "install")
    params = changed_copy(tmp_path)
    env = launch_env()
    env[PREFIX_ENV] = f"{prefix}:{env[PREFIX_ENV]}"
    words = ["nav2_bringup", "bringup_launch.py", f"map:={MAP_YAML}", f"params_file:={params}"]
    program = LearnerProgram(
        "nav2_bringup",
        "/lifecycle_manager_navigation",
        (sys.executable, str(ROS2LAUNCH_MAIN), *words),
        PROJECT_ROOT,
        env=env,
    )
    supervisor.start_program(program)
    clouds: list[ParticleCloud] = []
    node.create_subscription(
        ParticleCloud, "/particle_cloud", clouds.append, qos_profile_sensor_data
    )

    def logs() -> str:
        return "\n".join(supervisor.output("nav2_bringup", last=60))

    def active(manager: str) -> bool:
        client = node.create_client(Trigger, f"{manager}/is_active")
        try:
            if not client.wait_for_service(timeout_sec=1.0):
                return False
            done = threading.Event()
            future = client.call_async(Trigger.Request())
            future.add_done_callback(lambda _f: done.set())
            return done.wait(5.0) and bool(future.result().success)
        finally:
            node.destroy_client(client)

    for manager in MANAGERS:
        wait_until(lambda m=manager: active(m), timeout=90, what=lambda m=manager: f"{m}\n{logs()}")
    up = time.monotonic() - started

    # Every parameter of every section, as `ros2 param get` reads it.
    expected = node_sections(load(params))
    checked = 0
    for fqn, values in expected.items():
        names = sorted(n for n in values if n != UNKNOWN)
        listed = call(node, ListParameters, f"{fqn}/list_parameters", ListParameters.Request())
        missing = set(names) - set(listed.result.names)
        assert not missing, f"{fqn} does not declare {sorted(missing)}"
        answer = call(
            node, GetParameters, f"{fqn}/get_parameters", GetParameters.Request(names=names)
        )
        for name, value in zip(names, answer.values, strict=True):
            got = parameter_value_to_python(value) if value.type else None
            if fqn == "/map_server" and name == "yaml_filename":
                assert got == str(MAP_YAML), got  # the launch file's map argument
            else:
                assert got == value_of(values[name]), f"{fqn} {name}: {got!r} != {values[name]!r}"
            checked += 1
    listed = call(node, ListParameters, "/amcl/list_parameters", ListParameters.Request())
    assert UNKNOWN not in listed.result.names and "max_particles" in listed.result.names

    # amcl's filter has the file's particle count: a global spread is max_particles.
    call(node, Empty, "/reinitialize_global_localization", Empty.Request())
    wait_until(lambda: any(len(c.particles) == 800 for c in clouds), timeout=20,
               what=lambda: f"clouds of {[len(c.particles) for c in clouds]}")  # fmt: skip
    print(f"\nnav2_bringup: active in {up:.1f} s; {checked} parameters of {len(expected)} nodes")
    assert "Traceback" not in logs(), logs()


def value_of(value: Any) -> Any:
    return list(value) if isinstance(value, (list, tuple)) else value

"""Launch groups as launch-file text, and `ros2-classroom launch` argument errors."""

from __future__ import annotations

import sys
import types

import pytest

from app import catalog
from app.catalog import CatalogEntry
from app.launch import launch_file_text, node_spec
from tests.conftest import run_cli


def evaluate_launch_file(text: str, monkeypatch: pytest.MonkeyPatch) -> list[dict]:
    """Run the generated file against stand-ins for launch/launch_ros; return each Node's kwargs."""
    launch_mod = types.ModuleType("launch")
    launch_mod.LaunchDescription = lambda actions: list(actions)
    actions_mod = types.ModuleType("launch_ros.actions")
    actions_mod.Node = lambda **kwargs: kwargs
    launch_ros = types.ModuleType("launch_ros")
    launch_ros.actions = actions_mod
    for name, module in (
        ("launch", launch_mod),
        ("launch_ros", launch_ros),
        ("launch_ros.actions", actions_mod),
    ):
        monkeypatch.setitem(sys.modules, name, module)
    namespace: dict = {}
    exec(compile(text, "<launch file>", "exec"), namespace)
    return namespace["generate_launch_description"]()


def test_every_group_gives_a_valid_launch_file(monkeypatch):
    for group in catalog.GROUPS:
        nodes = evaluate_launch_file(launch_file_text(group), monkeypatch)
        assert [n["name"] for n in nodes] == [
            catalog.lookup(m).node_name.rsplit("/", 1)[1] for m in group.members
        ]
        assert all(n["package"] == "tutorial_nodes" for n in nodes)


def test_launch_file_carries_arguments_parameters_and_renames(monkeypatch):
    server, client = evaluate_launch_file(launch_file_text("add_two_ints"), monkeypatch)
    assert server == {
        "package": "tutorial_nodes",
        "executable": "add_two_ints_server",
        "name": "add_two_ints_server",
        "output": "screen",
    }
    assert client["executable"] == "add_two_ints_client" and client["arguments"] == ["2", "3"]

    talker, listener = evaluate_launch_file(launch_file_text("qos_mismatch"), monkeypatch)
    assert talker["executable"] == "qos_talker" and talker["name"] == "qos_talker_best_effort"
    assert talker["parameters"] == [{"reliability": "best_effort"}]
    assert "remappings" not in talker  # the rename is expressed by name=, not a remap
    assert listener["name"] == "qos_listener" and "parameters" not in listener

    *_, listener2 = evaluate_launch_file(launch_file_text("chatter_demo"), monkeypatch)
    assert listener2["executable"] == "listener" and listener2["name"] == "listener2"


def test_node_spec_translates_ros_args():
    entry = CatalogEntry(
        "x",
        "talker",
        "/robot1/fast_talker",
        "test entry",
        ros_args=(
            "-r",
            "chatter:=news",
            "-p",
            "rate:=5",
            "-p",
            "loud:=true",
            "-p",
            "ratio:=0.5",
            "-p",
            "label:=hi there",
            "--log-level",
            "debug",
        ),
        args=("7",),
    )
    spec = node_spec(entry)
    assert (spec.name, spec.namespace, spec.executable) == ("fast_talker", "/robot1", "talker")
    assert spec.remappings == [("chatter", "news")]
    assert spec.parameters == {"rate": 5, "loud": True, "ratio": 0.5, "label": "hi there"}
    assert spec.arguments == ["7"]
    assert spec.ros_arguments == ["--log-level", "debug"]


def test_launch_unknown_group_is_a_clear_error():
    result = run_cli("launch", "no_such_group")
    assert result.returncode == 2
    assert "no launch group named 'no_such_group'" in result.stderr
    assert "add_two_ints" in result.stderr  # the known groups are listed
    assert "Traceback" not in result.stderr


def test_launch_print_shows_the_launch_file():
    result = run_cli("launch", "fibonacci", "--print")
    assert result.returncode == 0, result.stderr
    assert result.stdout == launch_file_text("fibonacci")
    assert 'executable="fibonacci_action_client"' in result.stdout


def test_catalog_turtlesim_is_found_before_the_wheels_turtlesim(monkeypatch):
    """Once something set AMENT_PREFIX_PATH to the venv (as `ros2 interface` does),
    the wheels' turtlesim (interfaces only) must not hide the catalog's launch files."""
    import sys

    from app.launch_prefix import find_launch_file

    monkeypatch.setenv("AMENT_PREFIX_PATH", sys.prefix)
    found = find_launch_file("turtlesim", "multisim.launch.py")
    assert found.name == "multisim.launch.py" and found.is_file()

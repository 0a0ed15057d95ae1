"""Our robot_state_publisher judged from outside by a program written for the real one.

``rsp_client.py`` imports only rclpy, message packages and numpy, runs with
``python -I`` from a folder outside the project, starts ``python -m
robot_state_publisher`` itself and reports what came back; each test judges
one part against upstream's behaviour and an independent computation.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from app.dds import configure_dds_env
from tests.conftest import _domain_ids, in_private_netns

pytestmark = pytest.mark.ros

CLIENT = Path(__file__).with_name("rsp_client.py")
MACROED = Path(__file__).parents[2] / "ros_python/src/urdf_tutorial/urdf/08-macroed.urdf.xacro"


@pytest.fixture(scope="module")
def report(tmp_path_factory) -> dict:
    if not in_private_netns():
        pytest.fail("DDS tests must run inside a private network namespace (tests/run.py)")
    env = dict(os.environ)
    configure_dds_env(env, domain_id=next(_domain_ids) % 100 + 1, network=False)
    clean = {k: v for k, v in env.items() if k not in ("PYTHONPATH", "PYTHONSTARTUP")}
    done = subprocess.run(
        [sys.executable, "-I", str(CLIENT), str(MACROED)],
        cwd=tmp_path_factory.mktemp("outside"),
        env={**clean, "PYTHONUNBUFFERED": "1"},
        capture_output=True,
        text=True,
        timeout=150,
        check=False,
    )
    lines = [line for line in done.stdout.splitlines() if line.startswith("REPORT ")]
    assert lines, f"the client printed no report:\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}"
    return json.loads(lines[-1][len("REPORT ") :])


def _same_transform(got, want) -> bool:
    (t_got, q_got), (t_want, q_want) = got, want
    q_got, q_want = np.array(q_got), np.array(q_want)
    same_rotation = min(np.abs(q_got - q_want).max(), np.abs(q_got + q_want).max()) < 1e-6
    return bool(np.allclose(t_got, t_want, atol=1e-6) and same_rotation)


def test_late_joiner_gets_description_and_static_frames(report) -> None:
    assert report["initialized"]
    assert report["description_matches"]
    camera = report["static"]["camera"]
    assert camera["parent"] == "slider"
    assert _same_transform(camera["got"], report["static_expected"]["camera"])


def test_moving_joints_match_an_independent_computation(report) -> None:
    dynamic, expected = report["dynamic"], report["dynamic_expected"]
    assert set(dynamic) == set(expected)  # every movable joint, mimic included; nothing unknown
    parents = {"pan": "base_link", "tilt": "pan", "slider": "tilt", "wheel": "base_link"}
    for child, want in expected.items():
        assert dynamic[child]["parent"] == parents.get(child, "pan")
        assert _same_transform(dynamic[child]["got"], want), child


def test_publish_frequency_limits_each_joint(report) -> None:
    assert 10 <= report["pan_rate"] <= 21  # 100 states/s in, at most 20 transforms/s out


def test_bad_input_is_refused_and_the_node_lives(report) -> None:
    assert report["invalid_logged"]
    assert report["bad_set"]["successful"] is False
    assert "not valid XML" in report["bad_set"]["reason"]
    assert report["good_set"] and report["new_static"]
    assert report["main_alive"]
    assert report["main_exit"] == 0


def test_xacro_output_as_a_command_line_parameter(report) -> None:
    assert report["xacro_initialized"] and report["xacro_exit"] == 0


def test_urdf_file_argument_and_missing_description(report) -> None:
    assert report["file_initialized"]
    assert any("Assuming argument is name of URDF file" in line for line in report["file_log"])
    assert report["file_exit"] == 0
    assert any(
        "[WARN]" in line and "[kdl_parser]: The root link base_link has an inertia" in line
        for line in report["file_log"]
    )
    assert report["prefixed_parent"] == "r2/slider"  # frame_prefix on both ends
    assert report["empty_exit"] == 1
    assert any(
        "[FATAL]" in line and "robot_description parameter must not be empty" in line
        for line in report["empty_log"]
    )

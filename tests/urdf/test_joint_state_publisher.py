"""joint_state_publisher: start values, mimic arithmetic, and the node on the wire."""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import threading

import pytest
from joint_state_publisher.joint_state_publisher import (
    FreeJoint,
    mimic_chain,
    start_position,
    sweep,
)
from robot_state_publisher.urdf_tree import UrdfError, parse_urdf
from sensor_msgs.msg import JointState
from urdf_tutorial import share_directory

from tests.conftest import wait_until

FLEXIBLE = share_directory() / "urdf" / "06-flexible.urdf"


def test_start_position_is_zero_or_the_middle_of_the_limits() -> None:
    assert start_position(-1.0, 2.0) == 0.0
    assert start_position(0.2, 0.6) == pytest.approx(0.4)
    assert start_position(-0.6, -0.2) == pytest.approx(-0.4)
    assert start_position(0.2, 0.6, zero=0.3) == 0.3


def test_mimic_chains_compose_and_loops_are_refused() -> None:
    chain = parse_urdf(
        '<robot name="m"><link name="a"/><link name="b"/><link name="c"/><link name="d"/>'
        '<joint name="j1" type="continuous"><parent link="a"/><child link="b"/></joint>'
        '<joint name="j2" type="continuous"><parent link="b"/><child link="c"/>'
        '<mimic joint="j1" multiplier="2" offset="0.5"/></joint>'
        '<joint name="j3" type="continuous"><parent link="c"/><child link="d"/>'
        '<mimic joint="j2" multiplier="-1" offset="0.1"/></joint></robot>'
    )
    leader, factor, offset = mimic_chain(chain, "j3")
    assert leader == "j1"
    # j3 = -(2 * j1 + 0.5) + 0.1
    assert (factor, offset) == pytest.approx((-2.0, 0.1 - 0.5))
    loop = parse_urdf(
        '<robot name="m"><link name="a"/><link name="b"/><link name="c"/>'
        '<joint name="j1" type="continuous"><parent link="a"/><child link="b"/>'
        '<mimic joint="j2"/></joint>'
        '<joint name="j2" type="continuous"><parent link="b"/><child link="c"/>'
        '<mimic joint="j1"/></joint></robot>'
    )
    with pytest.raises(UrdfError, match="infinite recursive mimic chain"):
        mimic_chain(loop, "j1")


def test_sweep_bounces_between_limits_and_wraps_continuous() -> None:
    joint = FreeJoint(-0.1, 0.1, 0.05)
    sweep(joint, 0.1)
    assert (joint.position, joint.forward) == (0.1, False)
    wheel = FreeJoint(-math.pi, math.pi, 3.1, continuous=True)
    sweep(wheel, 0.1)
    assert wheel.position == -math.pi and wheel.forward


@pytest.mark.ros
def test_publishes_every_movable_joint_and_takes_source_values(probe) -> None:
    lock = threading.Lock()
    states: list[JointState] = []

    def on_state(msg: JointState) -> None:
        with lock:
            states.append(msg)

    probe.node.create_subscription(JointState, "/joint_states", on_state, 10)
    sliders = probe.node.create_publisher(JointState, "/sliders", 10)
    proc = subprocess.Popen(
        [sys.executable, "-m", "joint_state_publisher", str(FLEXIBLE), "--ros-args",
         "-p", "rate:=20", "-p", "zeros.head_swivel:=0.5", "-p", "source_list:=['/sliders']"],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True,
    )  # fmt: skip
    try:
        wait_until(lambda: states, 20, what="/joint_states")
        with lock:
            first = states[-1]
        expected = [j.name for j in parse_urdf(FLEXIBLE.read_text()).movable_joints()]
        assert list(first.name) == expected
        positions = dict(zip(first.name, first.position, strict=True))
        assert positions["head_swivel"] == pytest.approx(0.5)
        assert positions["gripper_extension"] == 0.0
        slider = JointState(name=["left_gripper_joint", "no_such_joint"], position=[0.42, 9.0])

        def moved() -> bool:
            sliders.publish(slider)
            with lock:
                latest = dict(zip(states[-1].name, states[-1].position, strict=True))
            return latest["left_gripper_joint"] == pytest.approx(0.42)

        wait_until(moved, 15, interval=0.2, what="the slider's value in /joint_states")
        with lock:
            assert "no_such_joint" not in states[-1].name
    finally:
        os.killpg(proc.pid, signal.SIGINT)
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(timeout=5)
    output = proc.stdout.read() if proc.stdout else ""
    assert proc.returncode == 0, output

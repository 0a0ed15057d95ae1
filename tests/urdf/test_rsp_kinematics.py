"""robot_state_publisher's maths and URDF checks, without ROS.

Transforms are checked against yourdfpy's forward kinematics (an independent
implementation) and scipy's rotations; each malformed description must be
refused with one line that names the problem.
"""

from __future__ import annotations

import io
import math

import numpy as np
import pytest
import yourdfpy
from robot_state_publisher.kinematics import (
    joint_transform,
    matrix_to_quaternion,
    mimic_position,
    origin_matrix,
    rpy_to_matrix,
)
from robot_state_publisher.urdf_tree import UrdfError, parse_urdf
from scipy.spatial.transform import Rotation

ARM = """<?xml version="1.0"?>
<robot name="tester">
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="a"/><link name="b"/><link name="c"/><link name="d"/><link name="e"/>
  <joint name="yaw" type="continuous"><parent link="base"/><child link="a"/>
    <origin xyz="0.1 -0.2 0.3" rpy="0.3 -0.5 1.1"/><axis xyz="0 0 1"/></joint>
  <joint name="tilt" type="revolute"><parent link="a"/><child link="b"/>
    <origin xyz="0 0 0.4" rpy="1.2 0.1 -0.7"/><axis xyz="1 1 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="slide" type="prismatic"><parent link="b"/><child link="c"/>
    <origin xyz="0.05 0 0" rpy="0 0 0.2"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.5" effort="1" velocity="1"/></joint>
  <joint name="twin" type="revolute"><parent link="b"/><child link="d"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/>
    <mimic joint="tilt" multiplier="-2" offset="0.25"/></joint>
  <joint name="mount" type="fixed"><parent link="c"/><child link="e"/>
    <origin xyz="0 0 0.02" rpy="3.0 0 0"/></joint>
</robot>
"""


def test_rpy_matches_fixed_axis_xyz_euler() -> None:
    for rpy in [(0.3, -0.5, 1.1), (1.2, 0.1, -0.7), (-2.0, 1.4, 3.0)]:
        expected = Rotation.from_euler("xyz", rpy).as_matrix()  # lower case: extrinsic axes
        assert np.allclose(rpy_to_matrix(*rpy), expected, atol=1e-12)


def test_quaternion_round_trip_and_ros_order() -> None:
    rng = np.random.default_rng(7)
    for _ in range(200):
        rotation = Rotation.random(random_state=rng)
        x, y, z, w = matrix_to_quaternion(rotation.as_matrix())
        assert w >= 0.0
        assert math.isclose(x * x + y * y + z * z + w * w, 1.0, rel_tol=1e-12)
        assert np.allclose(Rotation.from_quat([x, y, z, w]).as_matrix(), rotation.as_matrix())


def test_joint_transforms_match_yourdfpy() -> None:
    model = parse_urdf(ARM)
    reference = yourdfpy.URDF.load(
        io.BytesIO(ARM.encode()), build_scene_graph=True, load_meshes=False
    )
    rng = np.random.default_rng(3)
    for _ in range(20):
        q = {"yaw": rng.uniform(-3, 3), "tilt": rng.uniform(-1, 1), "slide": rng.uniform(0, 0.5)}
        reference.update_cfg(q)  # yourdfpy applies the mimic joint itself
        positions = dict(q, twin=mimic_position(q["tilt"], -2.0, 0.25), mount=0.0)
        for joint in model.joints.values():
            ours = joint_transform(joint.origin, joint.type, joint.axis, positions[joint.name])
            theirs = reference.get_transform(joint.child, joint.parent)
            assert np.allclose(ours, theirs, atol=1e-9), joint.name


def test_model_facts() -> None:
    model = parse_urdf(ARM)
    assert model.name == "tester" and model.root == "base" and model.root_has_inertia
    assert [j.name for j in model.movable_joints()] == ["yaw", "tilt", "slide", "twin"]
    assert np.allclose(model.joints["tilt"].axis, (0.5**0.5, 0.5**0.5, 0.0))  # unit, as in KDL
    assert model.joints["tilt"].lower == -1.0 and model.joints["yaw"].upper is None
    assert model.joints["twin"].mimic is not None and model.joints["twin"].mimic.multiplier == -2.0
    assert np.allclose(origin_matrix((0, 0, 0.02), (3.0, 0, 0)), model.joints["mount"].origin)


def _robot(body: str) -> str:
    return f'<robot name="r">{body}</robot>'


LINKS = '<link name="a"/><link name="b"/>'


def _joint(name: str, parent: str, child: str, extra: str = "", kind: str = "fixed") -> str:
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/>'
        f'<child link="{child}"/>{extra}</joint>'
    )


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "must not be empty"),
        ("<robot name='r'><link name='a'>", "not valid XML"),
        ("<model/>", "Could not find the 'robot' element"),
        (_robot(""), "No link elements"),
        (_robot(LINKS + _joint("j", "zz", "b")), "parent link [zz] of joint [j] not found"),
        (_robot(LINKS + _joint("j", "a", "zz")), "child link [zz] of joint [j] not found"),
        (_robot(LINKS), "Two root links found: [a] and [b]"),
        (_robot(LINKS + _joint("j", "a", "b") + _joint("k", "b", "a")), "No root link found"),
        (
            _robot(LINKS + '<link name="c"/>' + _joint("j", "a", "b") + _joint("k", "c", "b")),
            "link [b] has two parents",
        ),
        (
            _robot(
                '<link name="r0"/><link name="a"/><link name="b"/><link name="c"/>'
                + _joint("j0", "r0", "c")
                + _joint("j", "a", "b")
                + _joint("k", "b", "a")
            ),
            "links [a, b] form a loop",
        ),
        (_robot(LINKS + _joint("j", "a", "b", '<origin xyz="nan 0 0"/>')), "not a finite number"),
        (_robot(LINKS + _joint("j", "a", "b", '<origin rpy="0 0"/>')), "is not 3 numbers"),
        (_robot(LINKS + _joint("j", "a", "b", "", "revolute")), "does not specify limits"),
        (
            _robot(LINKS + _joint("j", "a", "b", '<axis xyz="0 0 0"/>', "continuous")),
            "axis of length zero",
        ),
        (_robot(LINKS + _joint("j", "a", "b", "", "ball")), "has no known type [ball]"),
        (
            _robot(LINKS + _joint("j", "a", "b", '<mimic joint="ghost"/>', "continuous")),
            "mimics an unknown joint [ghost]",
        ),
    ],
)
def test_bad_descriptions_are_refused_with_one_line(text: str, message: str) -> None:
    with pytest.raises(UrdfError) as caught:
        parse_urdf(text)
    assert message in str(caught.value)
    assert "\n" not in str(caught.value)


def test_ten_megabyte_description_parses_or_fails_cleanly() -> None:
    padding = "<!--" + "x" * (10 * 1024 * 1024) + "-->"
    model = parse_urdf(_robot(padding + LINKS + _joint("j", "a", "b")))
    assert model.root == "a"


def test_robotic_arm_urdf_agrees_with_arm_kinematics() -> None:
    """The unit-13 arm's URDF gives the fingertip pose forward_kinematics computes."""
    from app import PROJECT_ROOT
    from nodes.common.arm_kinematics import JOINT_LIMITS, JOINT_NAMES, forward_kinematics

    model = parse_urdf((PROJECT_ROOT / "nodes/robots/robotic_arm/robot.urdf").read_text())
    assert [j.name for j in model.movable_joints()] == list(JOINT_NAMES)
    for joint, (lower, upper) in zip(model.movable_joints(), JOINT_LIMITS, strict=True):
        assert math.isclose(joint.lower or 0.0, lower, abs_tol=1e-6), joint.name
        assert math.isclose(joint.upper or 0.0, upper, abs_tol=1e-6), joint.name
    rng = np.random.default_rng(11)
    for _ in range(50):
        q = [rng.uniform(lo, hi) for lo, hi in JOINT_LIMITS]
        pose = np.eye(4)
        frame = model.root
        positions = dict(zip(JOINT_NAMES, q, strict=True))
        while frame != "tool0":
            joint = next(j for j in model.joints.values() if j.parent == frame)
            pose = pose @ joint_transform(
                joint.origin, joint.type, joint.axis, positions.get(joint.name, 0.0)
            )
            frame = joint.child
        expected = forward_kinematics(q)
        assert np.allclose(pose[:3, 3], expected.position, atol=1e-9)
        assert np.allclose(pose[:3, :3], expected.rotation, atol=1e-9)


def test_tutorial_models_parse() -> None:
    import subprocess
    import sys
    from pathlib import Path

    from urdf_tutorial import share_directory

    folder = share_directory() / "urdf"
    movable = {}
    for path in sorted(folder.glob("*.urdf")):
        movable[path.name] = len(parse_urdf(path.read_text()).movable_joints())
    assert movable == {
        "01-myfirst.urdf": 0,
        "02-multipleshapes.urdf": 0,
        "03-origins.urdf": 0,
        "04-materials.urdf": 0,
        "05-visual.urdf": 0,
        "06-flexible.urdf": 8,
    }
    xacro = subprocess.run(
        [str(Path(sys.executable).with_name("xacro")), str(folder / "08-macroed.urdf.xacro")],
        capture_output=True,
        text=True,
        check=True,
    )
    model = parse_urdf(xacro.stdout)
    assert len(model.links) == 14 and len(model.movable_joints()) == 8

"""Read a URDF into the kinematic tree robot_state_publisher walks, or say why not.

Upstream parses with urdfdom and builds a KDL tree; both refuse a description
that is not a tree, with messages a learner then searches for ("Two root
links found: [a] and [b]"). We parse with the standard library's XML reader
because the kinematics needs only names, types, origins, axes, limits and
mimic tags, and because we must refuse what urdfdom refuses: yourdfpy (which
the 3D view uses for geometry) recovers from broken XML and accepts unknown
parent links, loops and NaN origins silently. Every refusal is one
:class:`UrdfError` whose message names the offending element.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np

from robot_state_publisher.kinematics import MOVABLE, origin_matrix

JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")
NEEDS_LIMITS = ("revolute", "prismatic")


class UrdfError(ValueError):
    """The robot description cannot be used; the message says why in one line."""


@dataclass(frozen=True)
class Mimic:
    joint: str
    multiplier: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True)
class Joint:
    name: str
    type: str
    parent: str
    child: str
    origin: np.ndarray  # 4x4, parent link -> joint frame
    axis: tuple[float, float, float]  # unit vector in the joint frame
    lower: float | None = None
    upper: float | None = None
    mimic: Mimic | None = None

    @property
    def movable(self) -> bool:
        return self.type in MOVABLE


@dataclass(frozen=True)
class RobotModel:
    name: str
    root: str
    links: tuple[str, ...]
    joints: dict[str, Joint]  # in document order
    root_has_inertia: bool

    def movable_joints(self) -> list[Joint]:
        return [j for j in self.joints.values() if j.movable]


def _floats(
    text: str | None, count: int, what: str, default: tuple[float, ...]
) -> tuple[float, ...]:
    if text is None:
        return default
    words = text.split()
    try:
        values = tuple(float(w) for w in words)
    except ValueError:
        raise UrdfError(f"{what} '{text}' is not {count} numbers") from None
    if len(values) != count:
        raise UrdfError(f"{what} '{text}' is not {count} numbers")
    if not all(math.isfinite(v) for v in values):
        raise UrdfError(f"{what} '{text}' has a value that is not a finite number")
    return values


def _float_attr(element: ET.Element, name: str, what: str, default: float | None) -> float | None:
    text = element.get(name)
    if text is None:
        return default
    return _floats(text, 1, f"{what} {name}", ())[0]


def _parse_joint(element: ET.Element) -> Joint:
    name = element.get("name")
    if not name:
        raise UrdfError("a joint has no name")
    joint_type = element.get("type", "")
    if joint_type not in JOINT_TYPES:
        raise UrdfError(f"Joint [{name}] has no known type [{joint_type}]")
    parent, child = element.find("parent"), element.find("child")
    parent_link = parent.get("link") if parent is not None else None
    child_link = child.get("link") if child is not None else None
    if not parent_link or not child_link:
        raise UrdfError(f"Joint [{name}] is missing a parent and/or child link specification.")
    origin = element.find("origin")
    xyz = _floats(
        origin.get("xyz") if origin is not None else None,
        3,
        f"Joint [{name}] origin xyz",
        (0.0,) * 3,
    )
    rpy = _floats(
        origin.get("rpy") if origin is not None else None,
        3,
        f"Joint [{name}] origin rpy",
        (0.0,) * 3,
    )
    axis_element = element.find("axis")
    axis = _floats(
        axis_element.get("xyz") if axis_element is not None else None,
        3,
        f"Joint [{name}] axis",
        (1.0, 0.0, 0.0),
    )
    length = math.sqrt(sum(v * v for v in axis))
    if joint_type in MOVABLE and length < 1e-12:
        raise UrdfError(f"Joint [{name}] has an axis of length zero")
    unit = tuple(v / length for v in axis) if length > 0 else (1.0, 0.0, 0.0)
    limit = element.find("limit")
    if joint_type in NEEDS_LIMITS and limit is None:
        raise UrdfError(
            f"Joint [{name}] is of type {joint_type.upper()} but it does not specify limits"
        )
    what = f"Joint [{name}] limit"
    lower = _float_attr(limit, "lower", what, 0.0) if limit is not None else None
    upper = _float_attr(limit, "upper", what, 0.0) if limit is not None else None
    if joint_type == "continuous":
        lower = upper = None
    mimic = None
    mimic_element = element.find("mimic")
    if mimic_element is not None:
        leader = mimic_element.get("joint")
        if not leader:
            raise UrdfError(f"Joint [{name}] has a mimic tag without a joint to follow")
        mimic = Mimic(
            leader,
            _float_attr(mimic_element, "multiplier", f"Joint [{name}] mimic", 1.0) or 0.0,
            _float_attr(mimic_element, "offset", f"Joint [{name}] mimic", 0.0) or 0.0,
        )
    return Joint(
        name,
        joint_type,
        parent_link,
        child_link,
        origin_matrix(xyz, rpy),
        (float(unit[0]), float(unit[1]), float(unit[2])),
        lower,
        upper,
        mimic,
    )


def parse_urdf(text: str) -> RobotModel:
    """The kinematic tree of a URDF document, checked as urdfdom and KDL check it."""
    if not text or not text.strip():
        raise UrdfError("robot_description parameter must not be empty")
    try:
        robot = ET.fromstring(text)
    except ET.ParseError as exc:
        raise UrdfError(f"the robot description is not valid XML: {exc}") from None
    if robot.tag != "robot":
        raise UrdfError(f"Could not find the 'robot' element in the xml (found <{robot.tag}>)")
    name = robot.get("name")
    if not name:
        raise UrdfError("No name given for the robot.")
    links: list[str] = []
    inertial: dict[str, bool] = {}
    for link in robot.findall("link"):
        link_name = link.get("name")
        if not link_name:
            raise UrdfError("No name given for the link.")
        if link_name in inertial:
            raise UrdfError(f"link '{link_name}' is not unique.")
        links.append(link_name)
        inertial[link_name] = link.find("inertial") is not None
    if not links:
        raise UrdfError("No link elements found in urdf file")
    joints: dict[str, Joint] = {}
    parent_of: dict[str, Joint] = {}
    for element in robot.findall("joint"):
        joint = _parse_joint(element)
        if joint.name in joints:
            raise UrdfError(f"joint '{joint.name}' is not unique.")
        if joint.child not in inertial:
            raise UrdfError(f"child link [{joint.child}] of joint [{joint.name}] not found")
        if joint.parent not in inertial:
            raise UrdfError(
                f"parent link [{joint.parent}] of joint [{joint.name}] not found. This is not "
                "valid according to the URDF spec. Every link you refer to from a joint needs "
                "to be explicitly defined in the robot description. Add "
                f'"<link name="{joint.parent}" />" or remove the joint [{joint.name}].'
            )
        if joint.child in parent_of:
            first = parent_of[joint.child].name
            raise UrdfError(
                f"link [{joint.child}] has two parents: joints [{first}] and [{joint.name}]; "
                "a URDF must be a tree"
            )
        parent_of[joint.child] = joint
        joints[joint.name] = joint
    for joint in joints.values():
        if joint.mimic is not None and joint.mimic.joint not in joints:
            raise UrdfError(f"Joint [{joint.name}] mimics an unknown joint [{joint.mimic.joint}]")
    roots = [link for link in links if link not in parent_of]
    if len(roots) > 1:
        raise UrdfError(
            f"Failed to find root link: Two root links found: [{roots[0]}] and [{roots[1]}]"
        )
    if not roots:
        raise UrdfError(
            "Failed to find root link: No root link found. The robot xml is not a valid tree."
        )
    reached = _reachable(roots[0], joints)
    looped = [link for link in links if link not in reached]
    if looped:
        raise UrdfError(
            f"links [{', '.join(looped)}] form a loop (each is its own ancestor): "
            "a URDF must be a tree"
        )
    return RobotModel(name, roots[0], tuple(links), joints, inertial[roots[0]])


def _reachable(root: str, joints: dict[str, Joint]) -> set[str]:
    children: dict[str, list[str]] = {}
    for joint in joints.values():
        children.setdefault(joint.parent, []).append(joint.child)
    seen, stack = {root}, [root]
    while stack:
        for child in children.get(stack.pop(), []):
            if child not in seen:
                seen.add(child)
                stack.append(child)
    return seen

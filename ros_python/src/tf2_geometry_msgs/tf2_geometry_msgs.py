"""Transforming geometry_msgs with a TransformStamped, as upstream's tf2_geometry_msgs.

Importing this module registers each ``do_transform_*`` with tf2_ros, so
``buffer.transform(point_stamped, 'frame')`` works for these types.
"""

from __future__ import annotations

from typing import Any

import tf2_ros
from geometry_msgs.msg import (
    Point,
    PointStamped,
    Pose,
    PoseStamped,
    TransformStamped,
    Vector3,
    Vector3Stamped,
)
from tf2_py.linear_math import Quat, Vec, quat_multiply, quat_rotate


def _rotation(transform: TransformStamped) -> Quat:
    r = transform.transform.rotation
    return (r.x, r.y, r.z, r.w)


def _translation(transform: TransformStamped) -> Vec:
    t = transform.transform.translation
    return (t.x, t.y, t.z)


def _apply(transform: TransformStamped, p: Vec) -> Vec:
    r = quat_rotate(_rotation(transform), p)
    t = _translation(transform)
    return (r[0] + t[0], r[1] + t[1], r[2] + t[2])


def to_msg_msg(msg: Any) -> Any:
    return msg


def from_msg_msg(msg: Any) -> Any:
    return msg


for _type in (Vector3Stamped, PoseStamped, PointStamped):
    tf2_ros.ConvertRegistration().add_to_msg(_type, to_msg_msg)
    tf2_ros.ConvertRegistration().add_from_msg(_type, from_msg_msg)


def do_transform_point(point: PointStamped, transform: TransformStamped) -> PointStamped:
    """The point expressed in the transform's parent frame (header from the transform)."""
    x, y, z = _apply(transform, (point.point.x, point.point.y, point.point.z))
    res = PointStamped()
    res.point = Point(x=x, y=y, z=z)
    res.header = transform.header
    return res


tf2_ros.TransformRegistration().add(PointStamped, do_transform_point)


def do_transform_vector3(vector3: Vector3Stamped, transform: TransformStamped) -> Vector3Stamped:
    """A direction: rotated only, never translated."""
    v = vector3.vector
    x, y, z = quat_rotate(_rotation(transform), (v.x, v.y, v.z))
    res = Vector3Stamped()
    res.vector = Vector3(x=x, y=y, z=z)
    res.header = transform.header
    return res


tf2_ros.TransformRegistration().add(Vector3Stamped, do_transform_vector3)


def do_transform_pose(pose: Pose, transform: TransformStamped) -> Pose:
    """A pose (position and orientation) in the transform's parent frame."""
    p, o = pose.position, pose.orientation
    x, y, z = _apply(transform, (p.x, p.y, p.z))
    qx, qy, qz, qw = quat_multiply(_rotation(transform), (o.x, o.y, o.z, o.w))
    res = Pose()
    res.position.x, res.position.y, res.position.z = x, y, z
    res.orientation.x, res.orientation.y, res.orientation.z, res.orientation.w = qx, qy, qz, qw
    return res


def do_transform_pose_stamped(pose: PoseStamped, transform: TransformStamped) -> PoseStamped:
    res = PoseStamped()
    res.pose = do_transform_pose(pose.pose, transform)
    res.header = transform.header
    return res


tf2_ros.TransformRegistration().add(PoseStamped, do_transform_pose_stamped)

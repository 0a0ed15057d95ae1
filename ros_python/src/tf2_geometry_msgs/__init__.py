"""tf2_geometry_msgs: do_transform_* for geometry_msgs, registered with tf2_ros."""

from tf2_geometry_msgs.tf2_geometry_msgs import (
    do_transform_point,
    do_transform_pose,
    do_transform_pose_stamped,
    do_transform_vector3,
    from_msg_msg,
    to_msg_msg,
)

__all__ = [
    "do_transform_point",
    "do_transform_pose",
    "do_transform_pose_stamped",
    "do_transform_vector3",
    "from_msg_msg",
    "to_msg_msg",
]

"""turtle_tf2_broadcaster: the "Writing a broadcaster (Python)" tutorial's node.

For every ``/<turtlename>/pose`` it broadcasts ``world -> <turtlename>`` on
/tf (parameter ``turtlename``, default ``turtle``): turtlesim is 2D, so z is
0 and the rotation is the pose's theta about z.

ROS concepts shown: TransformBroadcaster, a transform stamped with the
node's clock, a parameter that chooses which turtle.
"""

import math

import numpy as np
from geometry_msgs.msg import TransformStamped
from rclpy.node import Node
from tf2_ros import TransformBroadcaster
from turtlesim.msg import Pose

from nodes.common.run import spin_node


def quaternion_from_euler(ai: float, aj: float, ak: float) -> np.ndarray:
    """(x, y, z, w) of fixed-axis rotations roll ``ai``, pitch ``aj``, yaw ``ak``."""
    ai /= 2.0
    aj /= 2.0
    ak /= 2.0
    ci, si = math.cos(ai), math.sin(ai)
    cj, sj = math.cos(aj), math.sin(aj)
    ck, sk = math.cos(ak), math.sin(ak)
    cc, cs = ci * ck, ci * sk
    sc, ss = si * ck, si * sk
    q = np.empty((4,))
    q[0] = cj * sc - sj * cs
    q[1] = cj * ss + sj * cc
    q[2] = cj * cs - sj * sc
    q[3] = cj * cc + sj * ss
    return q


class FramePublisher(Node):
    def __init__(self) -> None:
        super().__init__("turtle_tf2_frame_publisher")
        # Declare and acquire `turtlename` parameter
        self.turtlename = (
            self.declare_parameter("turtlename", "turtle").get_parameter_value().string_value
        )
        # Initialize the transform broadcaster
        self.tf_broadcaster = TransformBroadcaster(self)
        # Subscribe to a turtle{1}{2}/pose topic and call handle_turtle_pose
        # callback function on each message
        self.subscription = self.create_subscription(
            Pose, f"/{self.turtlename}/pose", self.handle_turtle_pose, 1
        )

    def handle_turtle_pose(self, msg: Pose) -> None:
        t = TransformStamped()
        # Read message content and assign it to corresponding tf variables
        t.header.stamp = self.get_clock().now().to_msg()
        t.header.frame_id = "world"
        t.child_frame_id = self.turtlename
        # Turtle only exists in 2D, thus we get x and y translation
        # coordinates from the message and set the z coordinate to 0
        t.transform.translation.x = msg.x
        t.transform.translation.y = msg.y
        t.transform.translation.z = 0.0
        # For the same reason, turtle can only rotate around one axis
        # and this why we set rotation in x and y to 0 and obtain
        # rotation in z axis from the message
        q = quaternion_from_euler(0, 0, msg.theta)
        t.transform.rotation.x = q[0]
        t.transform.rotation.y = q[1]
        t.transform.rotation.z = q[2]
        t.transform.rotation.w = q[3]
        # Send the transformation
        self.tf_broadcaster.sendTransform(t)


def main(args=None) -> None:
    spin_node(FramePublisher, args)


if __name__ == "__main__":
    main()

"""static_turtle_tf2_broadcaster: the "Writing a static broadcaster (Python)" tutorial's node.

``ros2 run learning_tf2_py static_turtle_tf2_broadcaster mystaticturtle 0 0 1 0 0 0``
publishes ``world -> mystaticturtle`` once on /tf_static (child x y z roll
pitch yaw). The topic is transient local, so a later listener still gets it.

ROS concepts shown: StaticTransformBroadcaster, a TransformStamped filled by
hand, Euler angles to a quaternion.
"""

import math
import sys

import numpy as np
import rclpy
from geometry_msgs.msg import TransformStamped
from rclpy.node import Node
from tf2_ros.static_transform_broadcaster import StaticTransformBroadcaster

from nodes.common.run import init_ros, ros_started, stopped_quietly


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


class StaticFramePublisher(Node):
    """Broadcast transforms that never change."""

    def __init__(self, transformation: list[str]) -> None:
        super().__init__("static_turtle_tf2_broadcaster")
        self.tf_static_broadcaster = StaticTransformBroadcaster(self)
        # Publish static transforms once at startup
        self.make_transforms(transformation)

    def make_transforms(self, transformation: list[str]) -> None:
        t = TransformStamped()
        t.header.stamp = self.get_clock().now().to_msg()
        t.header.frame_id = "world"
        t.child_frame_id = transformation[1]
        t.transform.translation.x = float(transformation[2])
        t.transform.translation.y = float(transformation[3])
        t.transform.translation.z = float(transformation[4])
        quat = quaternion_from_euler(
            float(transformation[5]), float(transformation[6]), float(transformation[7])
        )
        t.transform.rotation.x = quat[0]
        t.transform.rotation.y = quat[1]
        t.transform.rotation.z = quat[2]
        t.transform.rotation.w = quat[3]
        self.tf_static_broadcaster.sendTransform(t)


def main() -> None:
    logger = rclpy.logging.get_logger("logger")
    args = rclpy.utilities.remove_ros_args(sys.argv)
    # obtain parameters from command line arguments
    if len(args) != 8:
        logger.info(
            "Invalid number of parameters. Usage: \n"
            "$ ros2 run learning_tf2_py static_turtle_tf2_broadcaster "
            "child_frame_name x y z roll pitch yaw"
        )
        sys.exit(1)
    if args[1] == "world":
        logger.info('Your static turtle name cannot be "world"')
        sys.exit(2)
    try:
        [float(word) for word in args[2:]]
    except ValueError:
        logger.info("x y z roll pitch yaw must be numbers")
        sys.exit(2)
    # pass parameters and initialize node
    node = None
    try:
        with stopped_quietly():  # Ctrl+C or SIGTERM, even during start-up: leave quietly
            init_ros()
            node = StaticFramePublisher(args)
            ros_started()
            rclpy.spin(node)
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

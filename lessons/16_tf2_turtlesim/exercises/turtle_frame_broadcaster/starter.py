"""Exercise: broadcast world -> turtle1 on /tf from turtle1's pose."""

import rclpy
from geometry_msgs.msg import TransformStamped
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from tf2_ros import TransformBroadcaster
from turtlesim.msg import Pose


class TurtleFrameBroadcaster(Node):
    def __init__(self):
        super().__init__("turtle_frame_broadcaster")
        self.tf_broadcaster = TransformBroadcaster(self)
        self.subscription = self.create_subscription(Pose, "/turtle1/pose", self.on_pose, 10)

    def on_pose(self, msg):
        t = TransformStamped()
        t.header.stamp = self.get_clock().now().to_msg()
        # TODO 1: the parent frame and the child frame.
        # TODO 2: the translation from msg.x and msg.y.
        # TODO 3: the rotation: theta about z as a quaternion (x, y, z, w).
        self.tf_broadcaster.sendTransform(t)


def main():
    rclpy.init()
    node = TurtleFrameBroadcaster()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

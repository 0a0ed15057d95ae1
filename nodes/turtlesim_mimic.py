"""mimic: make one turtle copy another's motion, as turtlesim's ``mimic`` does.

The node ``/turtle_mimic`` subscribes to ``input/pose`` (``turtlesim/msg/Pose``)
and, for every pose, publishes a ``geometry_msgs/msg/Twist`` on
``output/cmd_vel`` with the pose's ``linear_velocity`` as ``linear.x`` and its
``angular_velocity`` as ``angular.z``. Both names are relative and meant to be
remapped, which is the point of the program:

    ros2 run turtlesim mimic --ros-args
        --remap input/pose:=turtlesim1/turtle1/pose
        --remap output/cmd_vel:=turtlesim2/turtle1/cmd_vel

drives turtlesim2's turtle with whatever turtlesim1's turtle does.

ROS concepts shown: a node that is both a subscriber and a publisher (a
relay), topic remapping as the way to wire nodes together without changing
their code, and a queue of one (only the newest pose matters), as upstream.
"""

from geometry_msgs.msg import Twist
from rclpy.node import Node
from turtlesim.msg import Pose

from nodes.common.run import spin_node


class Mimic(Node):
    def __init__(self) -> None:
        super().__init__("turtle_mimic")
        self.twist_publisher = self.create_publisher(Twist, "output/cmd_vel", 1)
        self.pose_subscription = self.create_subscription(Pose, "input/pose", self.on_pose, 1)

    def on_pose(self, pose: Pose) -> None:
        twist = Twist()
        twist.linear.x = float(pose.linear_velocity)
        twist.angular.z = float(pose.angular_velocity)
        self.twist_publisher.publish(twist)


def main(args=None) -> None:
    spin_node(Mimic, args)


if __name__ == "__main__":
    main()

"""Reference: turtle1 in turtle2's frame, then turn and drive towards it."""

import math

import rclpy
from geometry_msgs.msg import Twist
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from tf2_ros import Buffer, TransformException, TransformListener
from turtlesim.srv import Spawn


class TurtleFollower(Node):
    def __init__(self):
        super().__init__("turtle_follower")
        self.tf_buffer = Buffer()
        self.tf_listener = TransformListener(self.tf_buffer, self)
        self.publisher = self.create_publisher(Twist, "/turtle2/cmd_vel", 1)
        self.spawner = self.create_client(Spawn, "/spawn")
        self.spawn_request = None
        self.timer = self.create_timer(0.1, self.on_timer)

    def spawn_turtle2(self):
        """Ask turtlesim for turtle2 once, as soon as /spawn is there."""
        if self.spawn_request is None and self.spawner.service_is_ready():
            self.spawn_request = self.spawner.call_async(
                Spawn.Request(x=4.0, y=2.0, theta=0.0, name="turtle2")
            )

    def on_timer(self):
        self.spawn_turtle2()
        try:
            t = self.tf_buffer.lookup_transform("turtle2", "turtle1", rclpy.time.Time())
        except TransformException as ex:
            self.get_logger().info(f"Could not transform turtle1 to turtle2: {ex}")
            return
        x, y = t.transform.translation.x, t.transform.translation.y
        msg = Twist()
        msg.angular.z = 4.0 * math.atan2(y, x)
        msg.linear.x = 0.5 * math.sqrt(x * x + y * y)
        self.publisher.publish(msg)


def main():
    rclpy.init()
    node = TurtleFollower()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

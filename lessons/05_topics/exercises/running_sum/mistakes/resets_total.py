"""A plausible mistake: the total is a local variable, so it starts at 0 for every message."""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import Int32, Int64


class Summer(Node):
    def __init__(self):
        super().__init__("summer")
        self.publisher = self.create_publisher(Int64, "sum", 10)
        self.subscription = self.create_subscription(Int32, "numbers", self.on_number, 10)

    def on_number(self, msg):
        total = 0
        total += msg.data
        self.publisher.publish(Int64(data=total))
        self.get_logger().info(f"received {msg.data}, total {total}")


def main():
    rclpy.init()
    node = Summer()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

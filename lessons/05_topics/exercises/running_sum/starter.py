"""Exercise: publish the running total of the numbers that arrive."""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import Int32, Int64


class Summer(Node):
    def __init__(self):
        super().__init__("summer")
        # TODO 1: start the total at 0 (it must survive from one message to the next).
        # TODO 2: create a publisher of Int64 messages on the topic "sum".
        self.subscription = self.create_subscription(Int32, "numbers", self.on_number, 10)

    def on_number(self, msg):
        self.get_logger().info(f"received {msg.data}")
        # TODO 3: add msg.data to the total and publish the total.


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

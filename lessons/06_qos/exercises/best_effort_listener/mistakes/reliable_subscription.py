"""A plausible mistake: a queue size of 10 means the default QoS, which is reliable."""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import String


class BestEffortListener(Node):
    def __init__(self):
        super().__init__("best_effort_listener")
        self.subscription = self.create_subscription(String, "qos_chatter", self.on_message, 10)

    def on_message(self, msg):
        self.get_logger().info(f'I heard: "{msg.data}"')


def main():
    rclpy.init()
    node = BestEffortListener()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

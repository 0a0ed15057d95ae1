"""Exercise: hear a best-effort publisher on /qos_chatter."""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import String


class BestEffortListener(Node):
    def __init__(self):
        super().__init__("best_effort_listener")
        # TODO 1: make a QoS profile the best-effort talker can serve.
        # TODO 2: subscribe to "qos_chatter" (String) with that profile,
        #         calling self.on_message for each message.

    def on_message(self, msg):
        # TODO 3: log the text of the message, e.g. I heard: "QoS message 7".
        pass


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

"""A plausible mistake: a blocking call() inside a timer callback.

The only thread that could process the answer is the one spinning the node,
and it is stuck in this callback: the request reaches the server, the answer
never reaches the code.
"""

import sys

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from tutorial_interfaces.srv import AddTwoInts


class Asker(Node):
    def __init__(self):
        super().__init__("asker")
        self.client = self.create_client(AddTwoInts, "add_two_ints")
        self.a, self.b = numbers(sys.argv)
        self.timer = self.create_timer(0.5, self.on_timer)

    def on_timer(self):
        self.timer.cancel()  # ask only once
        while not self.client.wait_for_service(timeout_sec=1.0):
            self.get_logger().info("/add_two_ints is not available yet, waiting...")
        response = self.client.call(AddTwoInts.Request(a=self.a, b=self.b))
        self.get_logger().info(f"{self.a} + {self.b} = {response.sum}")


def numbers(argv):
    """The two numbers from the command line (python asker.py 5 7), else 20 and 22."""
    words = rclpy.utilities.remove_ros_args(argv)[1:]
    return (int(words[0]), int(words[1])) if len(words) >= 2 else (20, 22)


def main():
    rclpy.init()
    node = Asker()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

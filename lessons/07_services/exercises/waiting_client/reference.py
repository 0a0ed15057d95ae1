"""Reference solution: wait for /add_two_ints, ask for the sum of two numbers, log the answer."""

import sys

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from tutorial_interfaces.srv import AddTwoInts


class Asker(Node):
    def __init__(self):
        super().__init__("asker")
        self.client = self.create_client(AddTwoInts, "add_two_ints")

    def wait_for_server(self):
        while not self.client.wait_for_service(timeout_sec=1.0):
            self.get_logger().info("/add_two_ints is not available yet, waiting...")

    def ask(self, a, b):
        return self.client.call_async(AddTwoInts.Request(a=a, b=b))


def numbers(argv):
    """The two numbers from the command line (python asker.py 5 7), else 20 and 22."""
    words = rclpy.utilities.remove_ros_args(argv)[1:]
    return (int(words[0]), int(words[1])) if len(words) >= 2 else (20, 22)


def main():
    rclpy.init()
    a, b = numbers(sys.argv)
    node = Asker()
    try:
        node.wait_for_server()
        future = node.ask(a, b)
        rclpy.spin_until_future_complete(node, future)
        node.get_logger().info(f"{a} + {b} = {future.result().sum}")
        rclpy.spin(node)  # keep the node running once the answer is logged
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

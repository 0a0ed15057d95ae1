"""Exercise: wait for /add_two_ints, ask for the sum of two numbers, log the answer."""

import sys

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from tutorial_interfaces.srv import AddTwoInts


class Asker(Node):
    def __init__(self):
        super().__init__("asker")
        # TODO 1: create a client for the service "add_two_ints" of type AddTwoInts.


def numbers(argv):
    """The two numbers from the command line (python asker.py 5 7), else 20 and 22."""
    words = rclpy.utilities.remove_ros_args(argv)[1:]
    return (int(words[0]), int(words[1])) if len(words) >= 2 else (20, 22)


def main():
    rclpy.init()
    a, b = numbers(sys.argv)
    node = Asker()
    try:
        # TODO 2: wait until the service is available, logging while you wait.
        # TODO 3: send the request with a and b using call_async, spin until the
        #         answer is in, and log it as f"{a} + {b} = {sum}" (e.g. "20 + 22 = 42").
        rclpy.spin(node)  # keep the node running once the answer is logged
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

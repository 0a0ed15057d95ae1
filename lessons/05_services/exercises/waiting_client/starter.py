"""Exercise: wait for /add_two_ints, ask for 20 + 22, log the answer."""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from tutorial_interfaces.srv import AddTwoInts


class Asker(Node):
    def __init__(self):
        super().__init__("asker")
        # TODO 1: create a client for the service "add_two_ints" of type AddTwoInts.


def main():
    rclpy.init()
    node = Asker()
    try:
        # TODO 2: wait until the service is available, logging while you wait.
        # TODO 3: send the request a=20, b=22 with call_async, spin until the
        #         answer is in, and log it as "20 + 22 = 42".
        rclpy.spin(node)  # keep the node running once the answer is logged
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

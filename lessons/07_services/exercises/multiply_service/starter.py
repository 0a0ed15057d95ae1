"""Exercise: a service server that multiplies two integers."""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from tutorial_interfaces.srv import AddTwoInts


class Multiplier(Node):
    def __init__(self):
        super().__init__("multiplier")
        # TODO 1: create the service "multiply" of type AddTwoInts,
        #         handled by self.on_multiply.

    def on_multiply(self, request, response):
        # TODO 2: put request.a times request.b into response.sum.
        return response


def main():
    rclpy.init()
    node = Multiplier()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

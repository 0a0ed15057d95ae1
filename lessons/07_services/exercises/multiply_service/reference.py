"""Reference solution: a service server that multiplies two integers."""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from tutorial_interfaces.srv import AddTwoInts


class Multiplier(Node):
    def __init__(self):
        super().__init__("multiplier")
        self.service = self.create_service(AddTwoInts, "multiply", self.on_multiply)

    def on_multiply(self, request, response):
        response.sum = request.a * request.b
        self.get_logger().info(f"{request.a} * {request.b} = {response.sum}")
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

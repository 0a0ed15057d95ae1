"""Accepted, written differently: a plain function as the service callback, main() only."""

import rclpy
from rclpy.executors import ExternalShutdownException
from tutorial_interfaces.srv import AddTwoInts


def multiply(request, response):
    response.sum = request.a * request.b
    return response


if __name__ == "__main__":
    rclpy.init()
    node = rclpy.create_node("multiplier")
    node.create_service(AddTwoInts, "/multiply", multiply)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    rclpy.try_shutdown()

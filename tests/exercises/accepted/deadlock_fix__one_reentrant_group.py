"""Accepted, written differently: one reentrant callback group for the service and the
client (instead of two groups), and a rclpy.spin with a MultiThreadedExecutor."""

import rclpy
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.node import Node
from tutorial_interfaces.srv import AddTwoInts


class RelayServer(Node):
    def __init__(self):
        super().__init__("relay_server")
        group = ReentrantCallbackGroup()
        self.client = self.create_client(AddTwoInts, "/add_two_ints", callback_group=group)
        self.create_service(AddTwoInts, "/relay_add", self.relay, callback_group=group)

    def relay(self, request, response):
        self.client.wait_for_service(timeout_sec=2.0)
        response.sum = self.client.call(AddTwoInts.Request(a=request.a, b=request.b)).sum
        return response


def main():
    rclpy.init()
    node = RelayServer()
    try:
        rclpy.spin(node, executor=MultiThreadedExecutor())
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

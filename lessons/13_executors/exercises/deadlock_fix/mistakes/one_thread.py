"""Mistake: a callback group of its own, but still one thread (rclpy.spin)."""

import rclpy
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from tutorial_interfaces.srv import AddTwoInts


class RelayServer(Node):
    def __init__(self):
        super().__init__("relay_server")
        # The client's answers are handled in a group of their own, so they
        # can run while the service callback (default group) is still waiting.
        self.client_group = MutuallyExclusiveCallbackGroup()
        self.client = self.create_client(
            AddTwoInts, "add_two_ints", callback_group=self.client_group
        )
        # Offer /relay_add only once /add_two_ints can be reached, so whoever sees
        # /relay_add gets an answer (finding another node can take seconds on a busy machine).
        while not self.client.wait_for_service(timeout_sec=1.0):
            self.get_logger().info("waiting for /add_two_ints ...")
        self.service = self.create_service(AddTwoInts, "relay_add", self.on_request)

    def on_request(self, request, response):
        if not self.client.wait_for_service(timeout_sec=2.0):
            self.get_logger().error("/add_two_ints is not available")
            return response
        forwarded = AddTwoInts.Request(a=request.a, b=request.b)
        answer = self.client.call(forwarded)  # blocks this thread only
        response.sum = answer.sum
        self.get_logger().info(f"relayed {request.a} + {request.b} = {response.sum}")
        return response


def main():
    rclpy.init()
    node = RelayServer()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

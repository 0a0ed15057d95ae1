"""Mistake: a multi-threaded executor, but the client stays in the default group."""

import rclpy
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.node import Node
from tutorial_interfaces.srv import AddTwoInts


class RelayServer(Node):
    def __init__(self):
        super().__init__("relay_server")
        self.client = self.create_client(AddTwoInts, "add_two_ints")
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
    executor = MultiThreadedExecutor()
    executor.add_node(node)
    try:
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

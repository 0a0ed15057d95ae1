"""Reference solution: wait for /add_two_ints, ask for 20 + 22, log the answer."""

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


def main():
    rclpy.init()
    node = Asker()
    try:
        node.wait_for_server()
        future = node.ask(20, 22)
        rclpy.spin_until_future_complete(node, future)
        node.get_logger().info(f"20 + 22 = {future.result().sum}")
        rclpy.spin(node)  # keep the node running once the answer is logged
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

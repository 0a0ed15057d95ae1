"""add_two_ints_client: ask /add_two_ints for the sum of two numbers, then exit.

Usage: ``python -m nodes.add_two_ints_client A B [--ros-args ...]``

The client is a short-lived node: it waits until a server offers the
service (printing a message every second while it waits, so a missing server
is obvious), sends one request, prints the sum and exits with status 0. Bad
arguments print a usage line on stderr and exit with status 2, before any ROS
work starts.

ROS concepts shown
- ``create_client(type, name)`` and ``wait_for_service(timeout_sec)``;
- ``call_async(request)`` returns a future at once; the node must keep
  spinning for the response to arrive, which
  ``rclpy.spin_until_future_complete(node, future)`` does for us (a
  blocking ``call()`` inside a callback would deadlock a single-threaded node);
- program arguments and ROS arguments share ``sys.argv``:
  ``rclpy.utilities.remove_ros_args`` drops everything from ``--ros-args``
  on, leaving ours.
"""

import sys

import rclpy
from rclpy.node import Node
from rclpy.utilities import remove_ros_args
from tutorial_interfaces.srv import AddTwoInts

from nodes.common.run import stopped_quietly

USAGE = "usage: add_two_ints_client A B [--ros-args ...]   (A and B are integers)"
EXIT_USAGE = 2
INT64_MIN, INT64_MAX = -(2**63), 2**63 - 1


def parse_operands(argv: list[str]) -> tuple[int, int]:
    """The two integers from the program arguments (without the program name)."""
    if len(argv) != 2:
        raise ValueError(f"expected 2 integers, got {len(argv)} argument(s)")
    numbers = []
    for text in argv:
        try:
            value = int(text)
        except ValueError:
            raise ValueError(f"not an integer: {text!r}") from None
        if not INT64_MIN <= value <= INT64_MAX:
            raise ValueError(f"does not fit in int64: {text}")
        numbers.append(value)
    return numbers[0], numbers[1]


class AddTwoIntsClient(Node):
    def __init__(self) -> None:
        super().__init__("add_two_ints_client")
        self.client = self.create_client(AddTwoInts, "add_two_ints")

    def wait_for_server(self) -> None:
        while not self.client.wait_for_service(timeout_sec=1.0):
            self.get_logger().info("service /add_two_ints not available, waiting for a server...")

    def send_request(self, a: int, b: int):
        return self.client.call_async(AddTwoInts.Request(a=a, b=b))


def main(args=None) -> None:
    argv = remove_ros_args(args if args is not None else sys.argv)[1:]
    try:
        a, b = parse_operands(argv)
    except ValueError as exc:
        print(f"add_two_ints_client: error: {exc}\n{USAGE}", file=sys.stderr)
        raise SystemExit(EXIT_USAGE) from None

    node = None
    try:
        # Ctrl+C or SIGTERM, even while it waits for the server: leave quietly.
        with stopped_quietly():
            rclpy.init(args=args)
            node = AddTwoIntsClient()
            node.wait_for_server()
            future = node.send_request(a, b)
            rclpy.spin_until_future_complete(node, future)
            response = future.result()
            node.get_logger().info(f"Result of add_two_ints: {a} + {b} = {response.sum}")
    finally:
        # Ctrl+C can arrive before the node exists: clean up only what was made.
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

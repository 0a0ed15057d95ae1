"""fibonacci_action_client: send one goal to /fibonacci, show feedback and result.

Usage: ``python -m nodes.fibonacci_action_client [ORDER] [--ros-args ...]``
(ORDER defaults to 10; the server accepts 0..46).

The client waits for an action server (saying so every second), sends the
goal, prints every feedback message as the sequence grows, prints the final
result and exits: status 0 when the goal succeeded, 1 when it was rejected,
aborted or canceled, 2 for bad arguments.

ROS concepts shown
- ``ActionClient(node, type, name)`` and ``wait_for_server``;
- the asynchronous chain of an action: ``send_goal_async`` -> goal response
  (accepted or rejected) -> ``get_result_async`` -> result with a status,
  each step handled in its own callback, with feedback arriving in between;
- ``rclpy.spin_until_future_complete`` on a future that the last callback
  completes, so the program ends when the whole exchange is over.
"""

import sys

import rclpy
from action_msgs.msg import GoalStatus
from rclpy.action import ActionClient
from rclpy.node import Node
from rclpy.task import Future
from rclpy.utilities import remove_ros_args
from tutorial_interfaces.action import Fibonacci

from nodes.common.run import stopped_quietly

USAGE = "usage: fibonacci_action_client [ORDER] [--ros-args ...]   (ORDER: integer, default 10)"
DEFAULT_ORDER = 10
EXIT_USAGE = 2
STATUS_NAMES = {
    GoalStatus.STATUS_SUCCEEDED: "SUCCEEDED",
    GoalStatus.STATUS_CANCELED: "CANCELED",
    GoalStatus.STATUS_ABORTED: "ABORTED",
}


def parse_order(argv: list[str]) -> int:
    if not argv:
        return DEFAULT_ORDER
    if len(argv) > 1:
        raise ValueError(f"expected at most 1 argument, got {len(argv)}")
    try:
        order = int(argv[0])
    except ValueError:
        raise ValueError(f"not an integer: {argv[0]!r}") from None
    if not -(2**31) <= order < 2**31:
        raise ValueError(f"does not fit in int32: {argv[0]}")
    return order


class FibonacciActionClient(Node):
    def __init__(self) -> None:
        super().__init__("fibonacci_action_client")
        self.action_client = ActionClient(self, Fibonacci, "fibonacci")
        self.done = Future()  # completed with True (succeeded) or False

    def send_goal(self, order: int) -> None:
        while not self.action_client.wait_for_server(timeout_sec=1.0):
            self.get_logger().info("action /fibonacci not available, waiting for a server...")
        self.get_logger().info(f"Sending goal: order {order}")
        goal_future = self.action_client.send_goal_async(
            Fibonacci.Goal(order=order), feedback_callback=self.on_feedback
        )
        goal_future.add_done_callback(self.on_goal_response)

    def on_goal_response(self, future: Future) -> None:
        goal_handle = future.result()
        if not goal_handle.accepted:
            self.get_logger().error("Goal rejected by the server (see its log for the reason)")
            self.done.set_result(False)
            return
        self.get_logger().info("Goal accepted")
        goal_handle.get_result_async().add_done_callback(self.on_result)

    def on_feedback(self, feedback_msg: Fibonacci.Impl.FeedbackMessage) -> None:
        sequence = list(feedback_msg.feedback.partial_sequence)
        self.get_logger().info(f"Feedback: {sequence}")

    def on_result(self, future: Future) -> None:
        response = future.result()
        status = STATUS_NAMES.get(response.status, f"status {response.status}")
        sequence = list(response.result.sequence)
        self.get_logger().info(f"Result ({status}): {sequence}")
        self.done.set_result(response.status == GoalStatus.STATUS_SUCCEEDED)


def main(args=None) -> None:
    argv = remove_ros_args(args if args is not None else sys.argv)[1:]
    try:
        order = parse_order(argv)
    except ValueError as exc:
        print(f"fibonacci_action_client: error: {exc}\n{USAGE}", file=sys.stderr)
        raise SystemExit(EXIT_USAGE) from None

    node = None
    succeeded = False
    try:
        # Ctrl+C or SIGTERM, even while it waits for the server: stopped on request,
        # not a failure.
        succeeded = True
        with stopped_quietly():
            rclpy.init(args=args)
            node = FibonacciActionClient()
            node.send_goal(order)
            rclpy.spin_until_future_complete(node, node.done)
            succeeded = bool(node.done.result())
    finally:
        # Ctrl+C can arrive before the node exists: clean up only what was made.
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    if not succeeded:
        raise SystemExit(1)


if __name__ == "__main__":
    main()

"""A plausible mistake: everything right, but spun by a single-threaded executor.

While execute() sleeps, the only thread is busy: the cancel request waits
until the goal has succeeded.
"""

import time

import rclpy
from rclpy.action import ActionServer, CancelResponse
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from tutorial_interfaces.action import Fibonacci

STEP_SEC = 0.2  # pause after each number


class FibServer(Node):
    def __init__(self):
        super().__init__("fib_server")
        self.action_server = ActionServer(
            self,
            Fibonacci,
            "fibonacci_exercise",
            execute_callback=self.execute,
            cancel_callback=self.on_cancel,
        )

    def on_cancel(self, goal_handle):
        self.get_logger().info("Cancel requested")
        return CancelResponse.ACCEPT

    def execute(self, goal_handle):
        order = goal_handle.request.order
        sequence = [0, 1][: order + 1]
        while len(sequence) < order + 1:
            if goal_handle.is_cancel_requested:
                goal_handle.canceled()
                self.get_logger().info(f"Canceled after {sequence}")
                return Fibonacci.Result(sequence=sequence)
            sequence.append(sequence[-1] + sequence[-2])
            goal_handle.publish_feedback(Fibonacci.Feedback(partial_sequence=sequence))
            time.sleep(STEP_SEC)
        goal_handle.succeed()
        self.get_logger().info(f"Done: {sequence}")
        return Fibonacci.Result(sequence=sequence)


def main():
    rclpy.init()
    node = FibServer()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

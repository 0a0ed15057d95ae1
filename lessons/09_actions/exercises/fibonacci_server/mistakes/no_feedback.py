"""A plausible mistake: the numbers are computed, but no feedback is ever sent."""

import time

import rclpy
from rclpy.action import ActionServer, CancelResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.node import Node
from tutorial_interfaces.action import Fibonacci

STEP_SEC = 0.2  # pause after each number


class FibServer(Node):
    def __init__(self):
        super().__init__("fib_server")
        # Reentrant: the cancel callback may run while execute() is still busy.
        self.action_server = ActionServer(
            self,
            Fibonacci,
            "fibonacci_exercise",
            execute_callback=self.execute,
            cancel_callback=self.on_cancel,
            callback_group=ReentrantCallbackGroup(),
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
            time.sleep(STEP_SEC)
        goal_handle.succeed()
        self.get_logger().info(f"Done: {sequence}")
        return Fibonacci.Result(sequence=sequence)


def main():
    rclpy.init()
    node = FibServer()
    try:
        # Several threads: one runs execute(), another can take the cancel request.
        rclpy.spin(node, executor=MultiThreadedExecutor())
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

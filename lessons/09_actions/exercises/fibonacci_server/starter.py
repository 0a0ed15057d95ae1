"""Exercise: an action server for Fibonacci sequences, with feedback and cancel."""

import time

import rclpy
from rclpy.action import ActionServer
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from tutorial_interfaces.action import Fibonacci

STEP_SEC = 0.2  # pause after each number


class FibServer(Node):
    def __init__(self):
        super().__init__("fib_server")
        # TODO 1: let clients cancel: add a cancel_callback that accepts, and a
        #         ReentrantCallbackGroup so it can run while a goal executes.
        self.action_server = ActionServer(
            self, Fibonacci, "fibonacci_exercise", execute_callback=self.execute
        )

    def execute(self, goal_handle):
        order = goal_handle.request.order
        sequence = [0, 1][: order + 1]
        # TODO 2: until the sequence has order + 1 numbers: stop if a cancel was
        #         requested (goal_handle.canceled() and return what you have),
        #         append the next number, publish feedback, sleep STEP_SEC.
        time.sleep(STEP_SEC)
        goal_handle.succeed()
        return Fibonacci.Result(sequence=sequence)


def main():
    rclpy.init()
    node = FibServer()
    try:
        # TODO 3: spin with a MultiThreadedExecutor.
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

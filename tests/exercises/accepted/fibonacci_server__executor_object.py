"""Accepted, written differently: an explicit MultiThreadedExecutor object, the sequence
built by a generator, and feedback sent before the pause."""

import time

import rclpy
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.node import Node
from tutorial_interfaces.action import Fibonacci


def fibonacci(order):
    a, b = 0, 1
    for _ in range(order + 1):
        yield a
        a, b = b, a + b


class Server(Node):
    def __init__(self):
        super().__init__("fib_server")
        group = ReentrantCallbackGroup()
        self._server = ActionServer(
            self,
            Fibonacci,
            "/fibonacci_exercise",
            self.run_goal,
            goal_callback=lambda _goal: GoalResponse.ACCEPT,
            cancel_callback=lambda _handle: CancelResponse.ACCEPT,
            callback_group=group,
        )

    def run_goal(self, handle):
        done = []
        for number in fibonacci(handle.request.order):
            if handle.is_cancel_requested:
                handle.canceled()
                return Fibonacci.Result(sequence=done)
            done.append(number)
            if len(done) >= 2:
                handle.publish_feedback(Fibonacci.Feedback(partial_sequence=done))
                time.sleep(0.15)
        handle.succeed()
        return Fibonacci.Result(sequence=done)


def main():
    rclpy.init()
    executor = MultiThreadedExecutor(num_threads=4)
    server = Server()
    executor.add_node(server)
    try:
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        executor.shutdown()
        server.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

"""Accepted, written differently: the beats come from a thread of its own, not a timer."""

import threading
import time

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node


class Heartbeat(Node):
    def __init__(self):
        super().__init__("heartbeat")
        self.stop = threading.Event()
        self.worker = threading.Thread(target=self.beat, daemon=True)
        self.worker.start()

    def beat(self):
        n, due = 0, time.monotonic()
        while not self.stop.is_set():
            due += 0.5
            if self.stop.wait(max(0.0, due - time.monotonic())):
                break
            n += 1
            self.get_logger().info("beat " + str(n))


def main():
    rclpy.init()
    node = Heartbeat()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.stop.set()
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

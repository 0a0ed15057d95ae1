"""Accepted, written differently: no timer, a loop that spins and publishes on a schedule."""

import time

import rclpy
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from std_msgs.msg import Int32


def main():
    rclpy.init()
    node = rclpy.create_node("counter")
    publisher = node.create_publisher(Int32, "/count", 10)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    count, due = 0, time.monotonic()
    try:
        while rclpy.ok():
            publisher.publish(Int32(data=count))
            count += 1
            due += 0.2  # 5 Hz, on a fixed schedule (no drift)
            while (left := due - time.monotonic()) > 0:
                executor.spin_once(timeout_sec=left)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

"""Accepted, written differently: its own executor, the arguments read with argparse after
rclpy removed its own, and the wait logged once."""

import argparse
import sys

import rclpy
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.utilities import remove_ros_args
from tutorial_interfaces.srv import AddTwoInts


def main():
    rclpy.init()
    parser = argparse.ArgumentParser()
    parser.add_argument("a", type=int, nargs="?", default=20)
    parser.add_argument("b", type=int, nargs="?", default=22)
    args = parser.parse_args(remove_ros_args(sys.argv)[1:])
    node = rclpy.create_node("asker")
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    client = node.create_client(AddTwoInts, "/add_two_ints")
    try:
        if not client.service_is_ready():
            node.get_logger().info("waiting for /add_two_ints")
        while not client.wait_for_service(timeout_sec=0.5):
            pass
        future = client.call_async(AddTwoInts.Request(a=args.a, b=args.b))
        executor.spin_until_future_complete(future)
        node.get_logger().info(f"{args.a} + {args.b} = {future.result().sum}")
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

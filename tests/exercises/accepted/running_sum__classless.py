"""Accepted, written differently: no Node subclass, the total kept in a closure."""

import rclpy
from rclpy.executors import ExternalShutdownException
from std_msgs.msg import Int32, Int64


def main():
    rclpy.init()
    node = rclpy.create_node("summer")
    total = [0]
    publisher = node.create_publisher(Int64, "sum", 10)

    def on_number(msg):
        total[0] += msg.data
        publisher.publish(Int64(data=total[0]))

    node.create_subscription(Int32, "numbers", on_number, 10)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


main()

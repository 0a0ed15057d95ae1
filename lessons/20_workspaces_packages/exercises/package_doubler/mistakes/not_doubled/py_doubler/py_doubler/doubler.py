import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node

from std_msgs.msg import Int32, Int64


class Doubler(Node):
    """Answers every number on /numbers with twice its value on /doubled."""

    def __init__(self):
        super().__init__('doubler')
        self.publisher_ = self.create_publisher(Int64, 'doubled', 10)
        self.subscription = self.create_subscription(Int32, 'numbers', self.number_callback, 10)

    def number_callback(self, msg):
        self.publisher_.publish(Int64(data=msg.data))


def main(args=None):
    rclpy.init(args=args)
    node = Doubler()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()

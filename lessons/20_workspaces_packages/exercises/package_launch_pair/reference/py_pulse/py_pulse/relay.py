import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node

from std_msgs.msg import Int32, Int64


class Relay(Node):
    """Passes every number on 'input' on to 'output', plus one."""

    def __init__(self):
        super().__init__('relay')
        self.publisher_ = self.create_publisher(Int64, 'output', 10)
        self.subscription = self.create_subscription(Int32, 'input', self.input_callback, 10)

    def input_callback(self, msg):
        self.publisher_.publish(Int64(data=msg.data + 1))


def main(args=None):
    rclpy.init(args=args)
    node = Relay()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()

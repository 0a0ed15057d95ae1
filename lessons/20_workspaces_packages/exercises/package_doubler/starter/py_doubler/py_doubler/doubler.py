import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node

from std_msgs.msg import Int32, Int64


class Doubler(Node):
    """Answers every number on /numbers with twice its value on /doubled."""

    def __init__(self):
        super().__init__('doubler')
        # TODO: a publisher of Int64 on 'doubled' and a subscription to Int32 on 'numbers'

    def number_callback(self, msg):
        pass  # TODO: publish twice msg.data


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

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node

from std_msgs.msg import String


class Monitor(Node):
    """Logs every beat it hears on /beat."""

    def __init__(self):
        super().__init__('monitor')
        self.subscription = self.create_subscription(String, 'beat', self.beat_callback, 10)

    def beat_callback(self, msg):
        self.get_logger().info('Heard %s' % msg.data)


def main(args=None):
    rclpy.init(args=args)
    node = Monitor()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()

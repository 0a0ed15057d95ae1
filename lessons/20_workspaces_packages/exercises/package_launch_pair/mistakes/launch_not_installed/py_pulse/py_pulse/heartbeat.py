import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node

from std_msgs.msg import String


class Heartbeat(Node):
    """Publishes 'beat N' on /beat twice a second."""

    def __init__(self):
        super().__init__('heartbeat')
        self.publisher_ = self.create_publisher(String, 'beat', 10)
        self.timer = self.create_timer(0.5, self.timer_callback)
        self.count = 0

    def timer_callback(self):
        self.publisher_.publish(String(data='beat %d' % self.count))
        self.count += 1


def main(args=None):
    rclpy.init(args=args)
    node = Heartbeat()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()

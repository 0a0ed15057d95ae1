"""Exercise: a ticker whose rate parameter is validated and applied while it runs."""

import rclpy
from rcl_interfaces.msg import SetParametersResult
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import Empty


class Ticker(Node):
    def __init__(self):
        super().__init__("ticker")
        self.declare_parameter("rate_hz", 2.0)
        self.add_on_set_parameters_callback(self.on_set_parameters)
        self.add_post_set_parameters_callback(self.on_parameters_set)
        self.publisher = self.create_publisher(Empty, "tick", 10)
        rate = self.get_parameter("rate_hz").value
        self.timer = self.create_timer(1.0 / rate, self.on_timer)

    def on_set_parameters(self, params):
        """Decide: accept or refuse the new values (do not apply them here)."""
        # TODO 1: refuse a rate_hz that is zero or less, with a reason
        #         saying that it must be positive.
        return SetParametersResult(successful=True)

    def on_parameters_set(self, params):
        """Apply the values that were accepted."""
        for param in params:
            self.get_logger().info(f"{param.name} is now {param.value}")
            # TODO 2: for rate_hz, replace the timer by one with the new period.

    def on_timer(self):
        self.publisher.publish(Empty())


def main():
    rclpy.init()
    node = Ticker()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

"""A plausible mistake: only negative rates are refused; 0.0 is accepted and crashes."""

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
        for param in params:
            if param.name == "rate_hz" and param.value < 0.0:
                return SetParametersResult(
                    successful=False, reason=f"rate_hz must be positive, got {param.value}"
                )
        return SetParametersResult(successful=True)

    def on_parameters_set(self, params):
        """Apply the values that were accepted."""
        for param in params:
            self.get_logger().info(f"{param.name} is now {param.value}")
            if param.name == "rate_hz":
                # A timer's period is fixed: make a new timer for the new rate.
                self.destroy_timer(self.timer)
                self.timer = self.create_timer(1.0 / param.value, self.on_timer)

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

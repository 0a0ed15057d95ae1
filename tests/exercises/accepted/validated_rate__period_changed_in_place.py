"""Accepted, written differently: one timer whose period is changed in place, validated
and applied in one callback (the issue's "parameter exercise written differently")."""

import rclpy
from rcl_interfaces.msg import SetParametersResult
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import Empty


class Ticker(Node):
    def __init__(self):
        super().__init__("ticker")
        rate = self.declare_parameter("rate_hz", 2.0).value
        self.pub = self.create_publisher(Empty, "/tick", 1)
        self.timer = self.create_timer(1.0 / rate, lambda: self.pub.publish(Empty()))
        self.add_on_set_parameters_callback(self.on_parameters)

    def on_parameters(self, params):
        for p in params:
            if p.name != "rate_hz":
                continue
            if p.value <= 0.0:
                return SetParametersResult(successful=False, reason="not a positive rate")
            self.timer.timer_period_ns = int(1e9 / p.value)
            self.timer.reset()
        return SetParametersResult(successful=True)


def main(args=None):
    rclpy.init(args=args)
    ticker = Ticker()
    try:
        rclpy.spin(ticker)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        ticker.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

"""flood_node: a misbehaving node that publishes and logs far too fast, on purpose.

ROS concepts shown
- nothing stops a node from publishing thousands of messages a second: a
  subscriber with a small queue (keep-last depth) simply loses the oldest;
- every ``get_logger().info`` goes to the terminal *and* to /rosout, so a
  chatty logger loads every tool that listens to /rosout;
- the dashboard keeps bounded buffers and tells you what it dropped.

Parameters: ``rate_hz`` (messages a second, default 2000), ``topic``
(default ``chatter``), ``log_every`` (log one line per N messages, default 1).

Try it: ``ros2 run tutorial_nodes flood_node --ros-args -p rate_hz:=5000``.
"""

from rclpy.node import Node
from std_msgs.msg import String

from nodes.common.run import spin_node

TICK_SEC = 0.01  # publish in bursts, 100 times a second


class FloodNode(Node):
    def __init__(self) -> None:
        super().__init__("flood_node")
        self.rate_hz = float(self.declare_parameter("rate_hz", 2000.0).value)
        topic = str(self.declare_parameter("topic", "chatter").value)
        self.log_every = max(1, int(self.declare_parameter("log_every", 1).value))
        self.count = 0
        self.owed = 0.0
        self.publisher = self.create_publisher(String, topic, 10)
        self.timer = self.create_timer(TICK_SEC, self.on_timer)

    def on_timer(self) -> None:
        self.owed += self.rate_hz * TICK_SEC
        while self.owed >= 1.0:
            self.owed -= 1.0
            msg = String(data=f"Flood: {self.count}")
            self.publisher.publish(msg)
            if self.count % self.log_every == 0:
                self.get_logger().info(f"Flooding: {self.count}")
            self.count += 1


def main(args=None) -> None:
    spin_node(FloodNode, args)


if __name__ == "__main__":
    main()

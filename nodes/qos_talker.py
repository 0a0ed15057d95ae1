"""qos_talker: publish on /qos_chatter with the QoS chosen by parameters.

Parameters (read once at start-up, hence read-only; QoS is fixed when the
publisher is created):

- ``reliability``: ``reliable`` (default) or ``best_effort``;
- ``durability``: ``volatile`` (default) or ``transient_local``;
- ``depth``: how many messages the history keeps (default 10).

It publishes "QoS message N" twice a second. Its publisher has event
callbacks, so the node *tells you* when a subscriber connects and when one
asks for more than this publisher offers (incompatible QoS). Without them a
QoS mismatch is silent: both sides run and no message ever arrives.

ROS concepts shown
- ``QoSProfile`` with reliability, durability, history depth (see
  ``nodes/qos_settings.py``);
- ``PublisherEventCallbacks(incompatible_qos=..., matched=...)`` passed as
  ``event_callbacks`` to ``create_publisher``;
- read-only parameters for settings that cannot change after start-up.

Try it: ``ros2-classroom launch qos_mismatch`` (a best-effort talker and a
reliable listener), or ``ros2-classroom run qos_talker --ros-args -p
reliability:=best_effort``.
"""

import sys

import rclpy
from rcl_interfaces.msg import ParameterDescriptor
from rclpy.event_handler import PublisherEventCallbacks, QoSOfferedIncompatibleQoSInfo
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import qos_policy_name_from_kind
from std_msgs.msg import String

from nodes.qos_settings import describe, profile_from_names

EXIT_BAD_PARAMETER = 2


class QosTalker(Node):
    def __init__(self) -> None:
        super().__init__("qos_talker")
        read_only = ParameterDescriptor(read_only=True, description="fixed at start-up")
        reliability = self.declare_parameter("reliability", "reliable", read_only).value
        durability = self.declare_parameter("durability", "volatile", read_only).value
        depth = self.declare_parameter("depth", 10, read_only).value
        qos = profile_from_names(reliability, durability, depth)  # ValueError if bad
        self.count = 0
        self.publisher = self.create_publisher(
            String,
            "qos_chatter",
            qos,
            event_callbacks=PublisherEventCallbacks(
                incompatible_qos=self.on_incompatible_qos, matched=self.on_matched
            ),
        )
        self.timer = self.create_timer(0.5, self.on_timer)
        self.get_logger().info(f"Publishing on /qos_chatter with QoS: {describe(qos)}")

    def on_timer(self) -> None:
        msg = String(data=f"QoS message {self.count}")
        self.publisher.publish(msg)
        self.get_logger().info(f'Publishing: "{msg.data}"')
        self.count += 1

    def on_incompatible_qos(self, event: QoSOfferedIncompatibleQoSInfo) -> None:
        policy = qos_policy_name_from_kind(event.last_policy_kind)
        self.get_logger().error(
            f"INCOMPATIBLE QoS: a subscriber requests more than this publisher offers "
            f"(policy {policy}); it will receive nothing from us "
            f"({event.total_count} incompatible subscriber(s) so far)"
        )

    def on_matched(self, event) -> None:
        self.get_logger().info(f"Matched subscribers: {event.current_count}")


def main(args=None) -> None:
    node = None
    try:
        rclpy.init(args=args)
        node = QosTalker()
        rclpy.spin(node)
    except ValueError as exc:  # a QoS parameter with an unknown value
        print(f"qos_talker: error: {exc}", file=sys.stderr)
        raise SystemExit(EXIT_BAD_PARAMETER) from None
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        # Ctrl+C can arrive before the node exists: clean up only what was made.
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

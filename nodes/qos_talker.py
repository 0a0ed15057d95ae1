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
- read-only parameters for settings that cannot change after start-up
  (declared in ``qos_settings.declare_qos_parameters``).

Try it: ``ros2-classroom launch qos_mismatch`` (a best-effort talker and a
reliable listener), or ``ros2 run tutorial_nodes qos_talker --ros-args -p
reliability:=best_effort``.
"""

from rclpy.event_handler import PublisherEventCallbacks, QoSOfferedIncompatibleQoSInfo
from rclpy.node import Node
from rclpy.qos import qos_policy_name_from_kind
from std_msgs.msg import String

from nodes.common.run import spin_node
from nodes.qos_settings import declare_qos_parameters, describe


class QosTalker(Node):
    def __init__(self) -> None:
        super().__init__("qos_talker")
        # Three read-only parameters (reliability, durability, depth) make the profile.
        qos = declare_qos_parameters(self)  # ValueError if a value is not understood
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
    # A QoS parameter with an unknown value: one error line and exit status 2.
    spin_node(QosTalker, args, program="qos_talker")


if __name__ == "__main__":
    main()

"""qos_listener: subscribe to /qos_chatter with the QoS chosen by parameters.

Same parameters as ``qos_talker`` (``reliability``, ``durability``,
``depth``; read-only). It logs every message it receives and, through
subscription event callbacks, when a publisher matches and when a publisher
offers less than this subscriber requests. Start a reliable listener next to
a best-effort talker and the log says "INCOMPATIBLE QoS ... RELIABILITY"
instead of leaving you with an inexplicably quiet topic.

With ``durability:=transient_local`` and a transient-local talker that has
been running a while, the first messages printed are old ones, kept by the
talker for late joiners.

ROS concepts shown
- requested vs offered QoS and the compatibility rule;
- ``SubscriptionEventCallbacks(incompatible_qos=..., matched=...)`` passed as
  ``event_callbacks`` to ``create_subscription``.
"""

from rclpy.event_handler import QoSRequestedIncompatibleQoSInfo, SubscriptionEventCallbacks
from rclpy.node import Node
from rclpy.qos import qos_policy_name_from_kind
from std_msgs.msg import String

from nodes.common.run import spin_node
from nodes.qos_settings import declare_qos_parameters, describe


class QosListener(Node):
    def __init__(self) -> None:
        super().__init__("qos_listener")
        # Three read-only parameters (reliability, durability, depth) make the profile.
        qos = declare_qos_parameters(self)  # ValueError if a value is not understood
        self.subscription = self.create_subscription(
            String,
            "qos_chatter",
            self.on_qos_chatter,
            qos,
            event_callbacks=SubscriptionEventCallbacks(
                incompatible_qos=self.on_incompatible_qos, matched=self.on_matched
            ),
        )
        self.get_logger().info(f"Listening on /qos_chatter with QoS: {describe(qos)}")

    def on_qos_chatter(self, msg: String) -> None:
        self.get_logger().info(f'I heard: "{msg.data}"')

    def on_incompatible_qos(self, event: QoSRequestedIncompatibleQoSInfo) -> None:
        policy = qos_policy_name_from_kind(event.last_policy_kind)
        self.get_logger().error(
            f"INCOMPATIBLE QoS: a publisher offers less than this subscriber requests "
            f"(policy {policy}); no messages will arrive from it "
            f"({event.total_count} incompatible publisher(s) so far)"
        )

    def on_matched(self, event) -> None:
        self.get_logger().info(f"Matched publishers: {event.current_count}")


def main(args=None) -> None:
    # A QoS parameter with an unknown value: one error line and exit status 2.
    spin_node(QosListener, args, program="qos_listener")


if __name__ == "__main__":
    main()

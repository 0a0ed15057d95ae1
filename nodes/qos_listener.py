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

import sys

import rclpy
from rcl_interfaces.msg import ParameterDescriptor
from rclpy.event_handler import QoSRequestedIncompatibleQoSInfo, SubscriptionEventCallbacks
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import qos_policy_name_from_kind
from std_msgs.msg import String

from nodes.qos_settings import describe, profile_from_names

EXIT_BAD_PARAMETER = 2


class QosListener(Node):
    def __init__(self) -> None:
        super().__init__("qos_listener")
        read_only = ParameterDescriptor(read_only=True, description="fixed at start-up")
        reliability = self.declare_parameter("reliability", "reliable", read_only).value
        durability = self.declare_parameter("durability", "volatile", read_only).value
        depth = self.declare_parameter("depth", 10, read_only).value
        qos = profile_from_names(reliability, durability, depth)  # ValueError if bad
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
    node = None
    try:
        rclpy.init(args=args)
        node = QosListener()
        rclpy.spin(node)
    except ValueError as exc:  # a QoS parameter with an unknown value
        print(f"qos_listener: error: {exc}", file=sys.stderr)
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

"""What feeds a ``TurtlesimView`` from one running sim: its trails, poses and background.

The Turtlesim tool and the turtlesim stage both draw a sim this way, from what
any ROS program sees: the sim's hidden trails topic (and the request topic
that asks it for a full snapshot), each turtle's pose, and its
``background_r/g/b`` parameters (read once, then followed on
``/parameter_events``). One feed follows one sim at a time; ``follow`` and
``sync_turtles`` run on the UI thread.
"""

from __future__ import annotations

from rcl_interfaces.msg import ParameterEvent
from rclpy.node import Node
from rclpy.publisher import Publisher
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.subscription import Subscription
from std_msgs.msg import Empty, UInt8MultiArray
from turtlesim.msg import Pose

from app.panels.turtlesim_view import TurtlesimView
from app.ros.context import panel_context
from app.ros.params import get_values, python_value
from app.ui.loop import UiLoop

TRAILS_SUFFIX = "/_trails"
TRAILS_TYPE = "std_msgs/msg/UInt8MultiArray"
BACKGROUND = ("background_r", "background_g", "background_b")
TRAILS_QOS = QoSProfile(
    depth=50, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)
# A viewer needs only the newest pose: best effort, one deep (no queue to work through).
POSE_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.BEST_EFFORT)


def find_sims(node: Node) -> list[str]:
    """Nodes publishing a trails topic (hidden names are not in a graph snapshot: ask DDS)."""
    return sorted(
        name[: -len(TRAILS_SUFFIX)]
        for name, types in node.get_topic_names_and_types()
        if name.endswith(TRAILS_SUFFIX) and TRAILS_TYPE in types and node.count_publishers(name) > 0
    )


class TurtlesimFeed:
    """Subscriptions that keep ``view`` drawing ``sim``; none while it follows nothing."""

    def __init__(self, node: Node, ui: UiLoop, view: TurtlesimView) -> None:
        self._node = node
        self._ui = ui
        self.view = view
        self.sim: str | None = None  # the followed node's full name
        self._trails: Subscription | None = None
        self._events: Subscription | None = None
        self._requests: Publisher | None = None
        self._poses: dict[str, tuple[str, Subscription]] = {}  # turtle -> (topic, subscription)

    @property
    def turtles(self) -> list[str]:
        return sorted(self._poses)

    def ask_snapshot(self) -> None:
        """From the view's thread: the trails are out of step, ask the sim for a snapshot."""
        publisher = self._requests
        if publisher is not None:
            try:
                publisher.publish(Empty())
            except Exception:  # swapped for another sim's just now: the view asks again
                pass

    def follow(self, sim: str | None) -> None:
        """Draw ``sim`` from now on (None: nothing), dropping the last one's subscriptions."""
        if sim == self.sim:
            return
        for subscription in (self._trails, self._events):
            if subscription is not None:
                self._node.destroy_subscription(subscription)
        if self._requests is not None:
            requests, self._requests = self._requests, None
            self._node.destroy_publisher(requests)
        self._trails = self._events = None
        self.sync_turtles({})
        self.sim = sim
        view = self.view
        view.follow(sim is not None)
        if sim is None:
            return
        node = self._node
        self._requests = node.create_publisher(Empty, sim + "/_trails_request", 10)

        def on_trails(msg: UInt8MultiArray) -> None:
            view.offer_trails(bytes(msg.data))

        self._trails = node.create_subscription(
            UInt8MultiArray, sim + TRAILS_SUFFIX, on_trails, TRAILS_QOS
        )
        self._events = node.create_subscription(
            ParameterEvent, "/parameter_events", lambda msg: self._on_event(sim, msg), 100
        )
        ctx = panel_context(node)

        def work() -> list[object]:
            return [python_value(v) for v in get_values(ctx, sim, list(BACKGROUND))]

        def done(values: list[object]) -> None:
            channels = [v for v in values if isinstance(v, int)]
            if self.sim == sim and len(channels) == len(values):
                view.set_background((channels[0], channels[1], channels[2]))

        self._ui.run_job(work, done, lambda _text: None)

    def _on_event(self, sim: str, event: ParameterEvent) -> None:
        """Executor thread: a background channel changed on the followed sim."""
        if event.node != sim:
            return
        rgb = list(self.view.background)
        for parameter in (*event.new_parameters, *event.changed_parameters):
            if parameter.name in BACKGROUND:
                value = python_value(parameter.value)
                if isinstance(value, int):
                    rgb[BACKGROUND.index(parameter.name)] = value
        self.view.set_background((rgb[0], rgb[1], rgb[2]))

    def sync_turtles(self, topics: dict[str, str]) -> None:
        """One pose subscription per turtle in ``topics`` (name -> pose topic), no others."""
        for name, (topic, subscription) in list(self._poses.items()):
            if topics.get(name) != topic:
                self._node.destroy_subscription(subscription)
                del self._poses[name]
        view = self.view
        for name, topic in topics.items():
            if name not in self._poses:

                def on_pose(msg: Pose, name: str = name) -> None:
                    view.offer_pose(name, msg.x, msg.y, msg.theta)

                subscription = self._node.create_subscription(Pose, topic, on_pose, POSE_QOS)
                self._poses[name] = (topic, subscription)
        view.keep_turtles(set(topics))

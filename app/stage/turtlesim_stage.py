"""Turtlesim's window on stage, at the size the stage gives it, with the keys that drive it.

The drawing is the Turtlesim tool's own (``TurtlesimView``: trails, background,
turtles), fed here from what any ROS program sees: the sim's hidden trails
topic, its ``background_r/g/b`` parameters and each turtle's pose. Only while
turtlesim is on stage: no subscription otherwise.

Keys: as in the Turtlesim tool, a hidden frame turns arrow and letter keys on
the page into page-link fetches, which publish the key's name for
``turtle_teleop_key``; only while this window is shown and the tool's own
listener is not (one key press, one key).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from typing import Any

import viser
from rcl_interfaces.msg import ParameterEvent
from rclpy.node import Node
from rclpy.publisher import Publisher
from rclpy.subscription import Subscription
from std_msgs.msg import Empty, String, UInt8MultiArray
from turtlesim.msg import Pose

from app.panels.turtlesim_panel import (
    BACKGROUND,
    KEY_TOPIC,
    KEYS,
    POSE_QOS,
    TRAILS_QOS,
    TRAILS_SUFFIX,
    TRAILS_TYPE,
    pose_topics,
)
from app.panels.turtlesim_view import TurtlesimView
from app.ros.context import panel_context
from app.ros.graph import GraphSnapshot
from app.ros.params import get_values, python_value
from app.ui import MarkdownView
from app.ui.loop import UiLoop
from app.ui.page_links import PageLinks
from app.ui.page_script import page_script

NO_SIM = (
    "_turtlesim_node is not running._ Start it from the lesson's button, "
    "**Run › Turtlesim**, or type `ros2 run turtlesim turtlesim_node` in **Run › Console**."
)
KEY_HINT = (
    "Arrow keys drive turtle1 while this window is shown (turtle_teleop_key must run: "
    "**Run › Turtlesim** starts it); G B V C D E R T turn it, F cancels the turn."
)

_KEYS_SCRIPT = """
const links = %s;
const keys = %s;
const shown = (frame) => !!frame && !!frame.parentElement
  && frame.parentElement.getClientRects().length > 0;
const onKey = (event) => {
  const target = event.target;
  if (event.ctrlKey || event.metaKey || event.altKey || !shown(window.frameElement)) return;
  // The Turtlesim tool's own listener takes the keys while its tab is shown.
  if (shown(parent.document.querySelector('iframe[data-turtlesim-keys]'))) return;
  const typing = /^(INPUT|TEXTAREA|SELECT)$/.test(target.tagName) || target.isContentEditable;
  if (typing || (target.closest && target.closest('[role=slider]'))) return;
  const name = keys[event.key.toLowerCase()];
  if (!name) return;
  event.preventDefault();
  event.stopImmediatePropagation();
  fetch(new URL(links[name], parent.location.href), {cache: 'no-store'}).catch(() => {});
};
if (parent.__stageKeysOff) parent.__stageKeysOff();
parent.addEventListener('keydown', onKey, true);
parent.__stageKeysOff = () => parent.removeEventListener('keydown', onKey, true);
window.addEventListener('pagehide', () => parent.__stageKeysOff && parent.__stageKeysOff());
"""


class TurtlesimStage:
    """Built inside the stage window's tab; ``refresh`` and ``set_active`` on the UI thread."""

    def __init__(self, gui: viser.GuiApi, ui: UiLoop, node: Node, links: PageLinks | None):
        self._ui = ui
        self._node = node
        self._active = False
        self._sim: str | None = None
        self._trails: Subscription | None = None
        self._events: Subscription | None = None
        self._requests: Publisher | None = None
        self._poses: dict[str, tuple[str, Subscription]] = {}
        self._keys: Publisher | None = None
        self._box = gui.add_folder(None, visible=False)
        with self._box:
            self._status = MarkdownView(gui, NO_SIM)
            self.view = TurtlesimView(gui, self._ask_snapshot)
            gui.add_markdown(KEY_HINT)
            if links is not None:
                hrefs = {
                    name: links.register(f"stage.turtle-key.{name}", self._key_action(name))
                    for name in sorted(set(KEYS.values()))
                }
                script = _KEYS_SCRIPT % (json.dumps(hrefs), json.dumps(KEYS))
                gui.add_html(page_script(script, "turtlesim keys on stage"))

    # -- keys (viser's asyncio thread posts; the UI thread publishes) -------------

    def _key_action(self, name: str) -> Callable[[], None]:
        return lambda: self._ui.post(lambda: self._publish_key(name))

    def _publish_key(self, name: str) -> None:
        if name not in KEYS.values():
            return
        if self._keys is None:
            self._keys = self._node.create_publisher(String, KEY_TOPIC, 10)
        self._keys.publish(String(data=name))

    # -- following the sim -------------------------------------------------------------

    def set_active(self, active: bool) -> None:
        self._active = active
        self._box.visible = active
        if not active:
            self._follow(None)

    def _ask_snapshot(self) -> None:
        """From the view's thread: the trails are out of step, ask the sim for a snapshot."""
        publisher = self._requests
        if publisher is not None:
            try:
                publisher.publish(Empty())
            except Exception:  # swapped for another sim's just now: the view asks again
                pass

    def _follow(self, sim: str | None) -> None:
        if sim == self._sim:
            return
        for subscription in (self._trails, self._events):
            if subscription is not None:
                self._node.destroy_subscription(subscription)
        if self._requests is not None:
            self._node.destroy_publisher(self._requests)
        self._trails = self._events = self._requests = None
        self._sync_turtles({})
        self._sim = sim
        self.view.follow(sim is not None)
        if sim is None:
            return
        node, view = self._node, self.view
        self._requests = node.create_publisher(Empty, sim + "/_trails_request", 10)

        def on_trails(msg: UInt8MultiArray) -> None:
            view.offer_trails(bytes(msg.data))

        self._trails = node.create_subscription(
            UInt8MultiArray, sim + TRAILS_SUFFIX, on_trails, TRAILS_QOS
        )
        self._events = node.create_subscription(
            ParameterEvent, "/parameter_events", lambda m: self._on_event(sim, m), 100
        )
        ctx = panel_context(node)

        def work() -> list[Any]:
            return [python_value(v) for v in get_values(ctx, sim, list(BACKGROUND))]

        def done(values: list[Any]) -> None:
            if self._sim == sim and all(isinstance(v, int) for v in values):
                view.set_background((values[0], values[1], values[2]))

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

    def _sync_turtles(self, topics: dict[str, str]) -> None:
        for name, (topic, subscription) in list(self._poses.items()):
            if topics.get(name) != topic:
                self._node.destroy_subscription(subscription)
                del self._poses[name]
        view = self.view
        for name, topic in topics.items():
            if name not in self._poses:

                def on_pose(msg: Pose, name: str = name) -> None:
                    view.offer_pose(name, msg.x, msg.y, msg.theta)

                self._poses[name] = (
                    topic,
                    self._node.create_subscription(Pose, topic, on_pose, POSE_QOS),
                )
        view.keep_turtles(set(topics))

    def _find_sim(self, graph: GraphSnapshot) -> str | None:
        """The first node publishing a trails topic (hidden topics: ask DDS itself)."""
        sims = sorted(
            name[: -len(TRAILS_SUFFIX)]
            for name, types in self._node.get_topic_names_and_types()
            if name.endswith(TRAILS_SUFFIX)
            and TRAILS_TYPE in types
            and self._node.count_publishers(name) > 0
        )
        return next((s for s in sims if graph.has_node(s)), None)

    def refresh(self, graph: GraphSnapshot) -> None:
        if not self._active:
            return
        if self._sim is None or not graph.has_node(self._sim):
            self._follow(self._find_sim(graph))
        sim = self._sim
        self._sync_turtles(pose_topics(graph, sim) if sim else {})
        if sim is None:
            self._status.show(NO_SIM)
        else:
            turtles = ", ".join(sorted(self._poses)) or "none yet"
            self._status.show(f"`{sim}` · turtles: {turtles}")

    def close(self) -> None:
        self.view.close()
        self._follow(None)
        if self._keys is not None:
            self._node.destroy_publisher(self._keys)

"""Turtlesim panel: the turtlesim window drawn live, and turtle_teleop_key driven from the page.

The drawing is ``TurtlesimView``; this panel finds the sim on the graph, feeds
the view from ROS (trails, poses, background parameters) and turns buttons
and keys into key names for ``/teleop_turtle`` (``std_msgs/String`` on its
hidden ``/teleop_turtle/_key``), the node that drives the turtle, as in the
tutorial.

Keys: viser sends no keyboard events, so a hidden same-origin frame (its
page is a ``srcdoc`` inside this panel's HTML) listens to ``keydown`` on the
dashboard page and fetches a secret page link (``app.ui.page_links``) per key
name. Only the fixed names below are registered, so the page can send
nothing but those; keys typed into an input field, or pressed while another
tab is shown, are left alone.
"""

from __future__ import annotations

import json
from collections.abc import Callable

import viser
from rclpy.node import Node
from std_msgs.msg import String

from app.panels.turtlesim_feed import TurtlesimFeed, find_sims
from app.panels.turtlesim_view import TurtlesimView
from app.ros.graph import GraphSnapshot
from app.supervisor import Supervisor
from app.ui import MarkdownView, set_options
from app.ui.loop import UiLoop
from app.ui.page_links import PageLinks
from app.ui.page_script import listen_on_page, page_script

NONE = "(no turtlesim)"
POSE_TYPE = "turtlesim/msg/Pose"
KEY_TOPIC = "/teleop_turtle/_key"
TELEOP_NODE = "/teleop_turtle"
# Browser key (KeyboardEvent.key, lower-cased) -> the key name turtle_teleop_key takes.
KEYS = {
    "arrowup": "up", "arrowdown": "down", "arrowleft": "left", "arrowright": "right",
    **{letter: letter for letter in "gbvcdertf"},
}  # fmt: skip
DRIVE = {"↑": "up", "↓": "down", "←": "left", "→": "right"}
HEADINGS = "G B V C D E R T"

INTRO = (
    "Turtlesim's window, drawn live from ROS: the background from the node's "
    "`background_r/g/b` parameters, the pen trails, and every turtle from its "
    "`/<name>/pose` topic."
)
NOT_RUNNING = (
    "_turtlesim_node is not running._ Type `ros2 run turtlesim turtlesim_node` "
    "in the **Console** tab, or press **Start turtlesim_node**."
)
KEY_HELP = (
    "**Drive turtle1** with the buttons, or with the arrow keys while this tab is "
    "open (not while typing in a field). G B V C D E R T turn it to 0°, -45°, -90°, "
    "-135°, 180°, 135°, 90°, 45° (a `rotate_absolute` goal); F cancels the goal."
)


def key_listener(links: dict[str, str]) -> str:
    """A hidden same-origin frame that turns key presses on the page into page-link fetches."""
    script = f"""
const links = {json.dumps(links)};
const keys = {json.dumps(KEYS)};
const shown = () => {{
  const box = window.frameElement && window.frameElement.parentElement;
  return !!box && box.getClientRects().length > 0;
}};
const onKey = (event) => {{
  const target = event.target;
  if (event.ctrlKey || event.metaKey || event.altKey || !shown()) return;
  const typing = /^(INPUT|TEXTAREA|SELECT)$/.test(target.tagName) || target.isContentEditable;
  if (typing || (target.closest && target.closest("[role=slider]"))) return;
  const name = keys[event.key.toLowerCase()];
  if (!name) return;
  event.preventDefault();  // no scrolling, and the tab list does not take the arrows
  event.stopPropagation();
  fetch(new URL(links[name], parent.location.href), {{cache: "no-store"}}).catch(() => {{}});
}};
{listen_on_page("__turtleKeysOff", "keydown", "onKey", capture=True)}
"""
    return page_script(script, "turtlesim keys", turtlesim_keys="")


def pose_topics(graph: GraphSnapshot, sim_fqn: str) -> dict[str, str]:
    """The sim's turtles by name -> pose topic: ``<sim namespace>/<name>/pose``.

    Only topics a node publishes: a turtle's pose topic stays on the graph while we
    still subscribe to it, so a killed turtle (or one of a sim since restarted) was
    listed as there.
    """
    namespace = sim_fqn.rsplit("/", 1)[0]  # '' for a node at the root
    found = {}
    for topic in graph.topics:
        if POSE_TYPE not in topic.types or not topic.name.startswith(namespace + "/"):
            continue
        if topic.publishers <= topic.own_publishers:
            continue
        name, _, tail = topic.name[len(namespace) + 1 :].partition("/")
        if tail == "pose" and name:
            found[name] = topic.name
    return found


class TurtlesimPanel:
    calm = True  # once a second while idle (app.ui.Panel): the drawing has its own thread

    def __init__(
        self,
        gui: viser.GuiApi,
        ui: UiLoop,
        node: Node,
        supervisor: Supervisor,
        page_links: PageLinks,
    ) -> None:
        self._ui = ui
        self._node = node
        self._supervisor = supervisor
        self._started: dict[str, str] = {}  # program -> what its Start button did
        self._nodes: tuple[str, ...] | None = None
        self._sims: list[str] = []
        self._keys = node.create_publisher(String, KEY_TOPIC, 10)

        gui.add_markdown(INTRO)
        self._selector = gui.add_dropdown("Turtlesim node", [NONE], initial_value=NONE)
        self._status = MarkdownView(gui, NOT_RUNNING)
        self._start_sim = gui.add_button("Start turtlesim_node", icon=viser.Icon.PLAYER_PLAY)
        self.view = TurtlesimView(gui, lambda: self._feed.ask_snapshot())
        self._feed = TurtlesimFeed(node, ui, self.view)
        self._teleop_hint = MarkdownView(gui, "")
        self._start_teleop = gui.add_button("Start turtle_teleop_key", icon=viser.Icon.KEYBOARD)
        gui.add_markdown(KEY_HELP)
        self._drive = gui.add_button_group("Drive", list(DRIVE))
        self._rotate = gui.add_button_group("Rotate", HEADINGS.split())
        self._cancel = gui.add_button("Cancel rotation (F)", icon=viser.Icon.X)
        links = {
            name: page_links.register(f"turtlesim-key-{name}", self._key_action(name))
            for name in sorted(set(KEYS.values()))
        }
        gui.add_html(key_listener(links))

        self._selector.on_update(ui.callback(self._follow_selected))
        self._start_sim.on_click(ui.callback(self._start, "turtlesim_node"))
        self._start_teleop.on_click(ui.callback(self._start, "turtle_teleop_key"))
        self._drive.on_click(lambda event: self._post_key(DRIVE.get(event.target.value, "")))
        self._rotate.on_click(lambda event: self._post_key(str(event.target.value).lower()))
        self._cancel.on_click(lambda _event: self._post_key("f"))

    # -- keys (viser's threads post; the UI thread publishes) ------------------

    def _key_action(self, name: str) -> Callable[[], None]:
        return lambda: self._post_key(name)

    def _post_key(self, name: str) -> None:
        if name in KEYS.values():  # only the fixed names ever leave the page
            self._ui.post(lambda: self._keys.publish(String(data=name)))

    def _start(self, program: str) -> None:
        def work() -> str:
            return self._supervisor.start(program).describe()

        def show(text: str) -> None:
            self._started[program] = text

        self._ui.run_job(work, show, show, lane="nodes")

    def _start_note(self, program: str) -> str:
        text = self._started.get(program)
        return f"\n\n{program}: {text}" if text else ""

    # -- following one sim -------------------------------------------------------

    def _follow_selected(self) -> None:
        self._feed.follow(self._selector.value if self._selector.value in self._sims else None)

    # -- the UI thread's refresh ---------------------------------------------------

    def refresh(self, graph: GraphSnapshot) -> None:
        if graph.nodes != self._nodes or not self._sims:
            self._nodes = graph.nodes
            sims = [s for s in find_sims(self._node) if graph.has_node(s)]
            if sims != self._sims:
                self._sims = sims
                set_options(self._selector, sims or [NONE], keep_current=False)
        self._follow_selected()
        sim = self._feed.sim
        self._feed.sync_turtles(pose_topics(graph, sim) if sim else {})
        self._start_sim.visible = sim is None
        self._status.show(self._status_text(sim))
        teleop = graph.has_node(TELEOP_NODE)
        self._start_teleop.visible = not teleop
        self._teleop_hint.show(
            f"`{TELEOP_NODE}` is running: the keys below go to it."
            if teleop
            else "_turtle_teleop_key is not running: the keys below need it._ Type "
            "`ros2 run turtlesim turtle_teleop_key` in the Console, or press the button."
            + self._start_note("turtle_teleop_key")
        )

    def _status_text(self, sim: str | None) -> str:
        if sim is None:
            return NOT_RUNNING + self._start_note("turtlesim_node")
        stats = self.view.stats()
        turtles = ", ".join(self._feed.turtles) or "none yet"
        rate = f"{stats.rate_hz:.0f} frames/s" if stats.rate_hz else "idle"
        cost = f" · {stats.draw_ms:.1f} ms a frame" if stats.draw_ms is not None else ""
        trails = "" if stats.in_step else " · waiting for the trails"
        return (
            f"Drawing `{sim}` · turtles: {turtles} · {rate}{cost} · "
            f"{stats.frames} frames drawn{trails}"
        )

    def close(self) -> None:
        self.view.close()
        self._feed.follow(None)
        self._node.destroy_publisher(self._keys)

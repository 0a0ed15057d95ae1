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
import math
import time
from collections.abc import Callable

import numpy as np
import viser
from rclpy.node import Node
from rclpy.publisher import Publisher
from rclpy.time import Time
from std_msgs.msg import String
from tf2_ros import TransformException

from app.panels.turtlesim_feed import TurtlesimFeed, find_sims
from app.panels.turtlesim_panel import KEY_TOPIC, KEYS, pose_topics
from app.panels.turtlesim_view import WINDOW_TITLE, SideBySide, TurtlesimView
from app.ros import tf_sources
from app.ros.graph import GraphSnapshot
from app.ui import MarkdownView
from app.ui.loop import UiLoop
from app.ui.page_links import PageLinks
from app.ui.page_script import listen_on_page, page_script
from nodes.common.turtlesim_world import PIXELS, WORLD_SIZE

NO_SIM = (
    "_turtlesim_node is not running._ Start it from the lesson's button, "
    "**Run › Turtlesim**, or type `ros2 run turtlesim turtlesim_node` in **Run › Console**."
)
LOOK_EVERY = 1.0  # s between looks for a sim started since
BURST_SEC = 1.5  # s: sims first seen this close together came from one launch
WORLD_FRAME = "world"  # the tf2 turtlesim demo's fixed frame: the window's corner
PAIR_SEC = 5.0  # s: a sim first seen this close to the followed one is drawn beside it
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
""" + listen_on_page("__stageKeysOff", "keydown", "onKey", capture=True).replace("%", "%%")


def _inside(x: float, y: float) -> bool:
    return 0.0 <= x <= WORLD_SIZE and 0.0 <= y <= WORLD_SIZE


class TurtlesimStage:
    """Built inside the stage window's tab; ``refresh`` and ``set_active`` on the UI thread.

    One sim is drawn at its own size. Two started by one launch (``multisim``, where
    ``mimic`` makes the second turtle copy the first) are drawn side by side."""

    def __init__(self, gui: viser.GuiApi, ui: UiLoop, node: Node, links: PageLinks | None):
        self._ui = ui
        self._node = node
        self._active = False
        self._keys: Publisher | None = None
        self._sims: list[str] = []  # the sims running at the last look
        self._seen: dict[str, float] = {}  # every sim seen since the stage was built: when
        self._next_look = 0.0
        self._adopted_at = -math.inf  # when a new sim last took the stage
        self._paired = False  # read by the drawing thread: where the followed sim's frame goes
        self._tf: tf_sources.TfSources | None = None  # the dashboard's TF reader, while shown
        self._box = gui.add_folder(None, visible=False)
        with self._box:
            self._status = MarkdownView(gui, NO_SIM)
            blank = np.zeros((PIXELS, PIXELS, 3), np.uint8)
            self._single = gui.add_image(blank, label=WINDOW_TITLE, format="png")
            self._pair = SideBySide(gui, f"{WINDOW_TITLE} × 2 (left, right)")
            self._pair.handle.visible = False
            self.view = TurtlesimView(gui, lambda: self._feed.ask_snapshot(), show=self._show)
            self._feed = TurtlesimFeed(node, ui, self.view)
            partner_view = TurtlesimView(
                gui, lambda: self._partner.ask_snapshot(), show=self._pair.right
            )
            self._partner = TurtlesimFeed(node, ui, partner_view)
            gui.add_markdown(KEY_HINT)
            if links is not None:
                hrefs = {
                    name: links.register(f"stage.turtle-key.{name}", self._key_action(name))
                    for name in sorted(set(KEYS.values()))
                }
                script = _KEYS_SCRIPT % (json.dumps(hrefs), json.dumps(KEYS))
                gui.add_html(page_script(script, "turtlesim keys on stage"))

    def _show(self, frame: np.ndarray) -> None:
        """The followed sim's frame (its drawing thread): alone, or the left of a pair."""
        if self._paired:
            self._pair.left(frame)
        else:
            self._single.image = frame

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
        self._next_look = 0.0
        if active and self._tf is None:
            self._tf = tf_sources.shared(self._node)
        if not active:
            self._feed.follow(None)
            self._pair_with(None)
            if self._tf is not None:
                tf_sources.release(self._tf)
                self._tf = None

    def _frame_marks(self) -> dict[str, tuple[float, float]]:
        """TF frames that are no turtle, where they are in turtlesim's ``world`` (the tf2
        lesson's carrot beside turtle1); the view draws those inside the window."""
        sources, turtles = self._tf, set(self._feed.turtles)
        if sources is None:
            return {}
        marks = {}
        for info in sources.frames():
            name = info.frame
            if not info.parent or info.stale or name in turtles or name == WORLD_FRAME:
                continue
            try:
                t = sources.buffer.lookup_transform(WORLD_FRAME, name, Time()).transform
            except TransformException:  # not joined to world (another tree)
                continue
            marks[name] = (t.translation.x, t.translation.y)
        return marks

    def _choose_sim(self, graph: GraphSnapshot) -> None:
        """Follow the sim the learner started last; keep the followed one while it runs.

        A lesson that launches two more sims (``multisim``) while the first still
        runs is about the new ones: a sim not seen before takes the stage.
        """
        now = time.monotonic()
        followed = self._feed.sim
        if followed is not None and graph.has_node(followed) and now < self._next_look:
            return
        self._next_look = now + LOOK_EVERY  # asking DDS for every topic is not free
        self._sims = [s for s in find_sims(self._node) if graph.has_node(s)]
        new = [s for s in self._sims if s not in self._seen]
        self._seen.update({sim: now for sim in new})
        if new:
            # One launch starts several sims whose discovery order varies: within a burst
            # the first by name keeps the stage (multisim: turtlesim1, not turtlesim2).
            if followed in self._sims and now - self._adopted_at < BURST_SEC:
                new = sorted([*new, followed])
            if new[0] != followed:
                self._feed.follow(new[0])
                self._adopted_at = now
        elif followed is None or followed not in self._sims:
            self._feed.follow(self._sims[0] if self._sims else None)
        self._pair_with(self._burst_partner())

    def _burst_partner(self) -> str | None:
        """A running sim first seen close after or before the followed one (multisim's second;
        on a loaded machine one launch's sims are seen seconds apart)."""
        followed = self._feed.sim
        if followed is None:
            return None
        since = self._seen.get(followed, -math.inf)
        near = [
            (abs(self._seen[s] - since), s)
            for s in self._sims
            if s != followed and abs(self._seen[s] - since) < PAIR_SEC
        ]
        return min(near)[1] if near else None  # the one started closest to it

    def _pair_with(self, partner: str | None) -> None:
        if partner == self._partner.sim:
            return
        self._partner.follow(partner)
        self._paired = partner is not None
        self._pair.handle.visible = self._paired
        self._single.visible = not self._paired
        self.view.redraw()  # its frame goes to the other picture now

    def refresh(self, graph: GraphSnapshot) -> None:
        if not self._active:
            return
        self._choose_sim(graph)
        sim, partner = self._feed.sim, self._partner.sim
        self._feed.sync_turtles(pose_topics(graph, sim) if sim else {})
        self._partner.sync_turtles(pose_topics(graph, partner) if partner else {})
        if sim is None:
            self._status.show(NO_SIM)
            return
        marks = self._frame_marks()
        self.view.set_marks(marks)
        shown = [(sim, self._feed)] + ([(partner, self._partner)] if partner else [])
        sides = ("left", "right") if partner else ("",)
        parts = [
            f"`{name}`{f' ({side})' if side else ''} · turtles: "
            + (", ".join(feed.turtles) or "none yet")
            for (name, feed), side in zip(shown, sides, strict=True)
        ]
        others = [f"`{s}`" for s in self._sims if s not in (sim, partner) and graph.has_node(s)]
        also = f" · also running: {', '.join(others)}" if others else ""
        words = [
            name if _inside(*marks[name]) else f"{name} (outside the window now)"
            for name in sorted(marks)
        ]
        frames = f" · other frames (orange): {', '.join(words)}" if words else ""
        self._status.show(" · ".join(parts) + frames + also)

    def close(self) -> None:
        self.set_active(False)
        self.view.close()
        self._partner.view.close()
        self._feed.follow(None)
        self._partner.follow(None)
        if self._keys is not None:
            self._node.destroy_publisher(self._keys)

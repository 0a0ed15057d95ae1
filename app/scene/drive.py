"""Drive the simulated robot from the 3D view, and let each browser's camera follow it.

Driving goes through the sim_drive group's teleop, ``/sim_teleop_key`` (the
arrow-key teleop, remapped onto ``/cmd_vel``), exactly as a terminal's
arrow keys would: the buttons and keys send fixed key names (``up``,
``down``, ``left``, ``right``) as ``std_msgs/String`` on its hidden
``/sim_teleop_key/_key`` topic, and the teleop turns each into one Twist.
The robot stops by itself half a second after the last one (the
simulator's command timeout), so holding a key drives.

Keys: viser sends no keyboard events, so a hidden same-origin frame in this
panel listens to ``keydown`` on the page and clicks the matching drive
button, which reaches us as viser's own button event. Only the four
buttons can be pressed that way; keys typed into a field, or pressed while
the 3D view is not the tab shown, are left alone.

Following: a thread looks at ``base_link``'s pose in the Fixed Frame ten
times a second and moves every connected browser's camera by as much as
the robot moved, keeping each learner's own angle and distance.
"""

from __future__ import annotations

import json
import logging
import threading
from collections.abc import Callable

import numpy as np
import viser
from rclpy.node import Node
from std_msgs.msg import String

from app.ros.graph import GraphSnapshot
from app.ui import MarkdownView
from app.ui.loop import UiLoop
from app.ui.page_script import listen_on_page, page_script

log = logging.getLogger(__name__)

KEY_TOPIC = "/sim_teleop_key/_key"
TELEOP_NODE = "/sim_teleop_key"
SIM_NODE = "/sim_world"
# Button label -> the key name the teleop takes. Labels unlike any other tab's buttons.
BUTTONS = {"◀": "left", "▲": "up", "▼": "down", "▶": "right"}
# Browser key (KeyboardEvent.key, lower-cased) -> the button it presses.
KEYS = {"arrowleft": "◀", "arrowup": "▲", "arrowdown": "▼", "arrowright": "▶"}
FOLLOW_HZ = 10.0
FOLLOW_MIN_MOVE = 0.01  # m: smaller moves leave the cameras alone
ROBOT_FRAME = "base_link"
VIEW_FROM = np.array([-0.45, -0.7, 0.6])  # the overview looks at the room from here (a direction)
OVERVIEW_DISTANCE = 0.85  # the overview's distance, in room sizes
# A building (the 10 m x 8 m office) seen from the room's corner angle fills half the
# stage's height and hides its rooms behind walls: it is looked at from higher up, as
# rviz shows a map, so the map, the particles and the plan on its floor read at a glance.
WIDE_WORLD = 6.0  # m: a world at least this long on the floor is seen from above
VIEW_FROM_ABOVE = np.array([-0.12, -0.45, 1.0])
ABOVE_DISTANCE = 0.7

HELP = (
    "**Drive the robot** with the buttons, or with the arrow keys while this tab is open "
    "(not while typing in a field): ▲ forward, ▼ back, ◀ ▶ turn. Each press is one "
    "`/cmd_vel` command from `/sim_teleop_key`; the robot stops half a second after the last."
)


def key_listener() -> str:
    """A hidden same-origin frame that turns arrow keys on the page into drive-button clicks."""
    script = f"""
const keys = {json.dumps(KEYS)};
const host = window.frameElement;
const box = host && host.parentElement;
const shown = () => !!box && box.getClientRects().length > 0;
const onKey = (event) => {{
  const target = event.target;
  if (event.ctrlKey || event.metaKey || event.altKey || !shown()) return;
  const clickable = /^(checkbox|radio|button|submit|reset)$/.test(target.type || "");
  const field = /^(TEXTAREA|SELECT)$/.test(target.tagName) || target.isContentEditable;
  const typing = field || (target.tagName === "INPUT" && !clickable);
  if (typing || (target.closest && target.closest("[role=slider]"))) return;
  const label = keys[event.key.toLowerCase()];
  if (!label) return;
  const scope = host.closest("[role=tabpanel]") || parent.document;
  const button = [...scope.querySelectorAll("button")].find(
    (b) => b.textContent.trim() === label && b.getClientRects().length > 0);
  if (!button) return;
  event.preventDefault();  // no scrolling, and the tab list does not take the arrows
  event.stopPropagation();
  button.click();
}};
{listen_on_page("__simDriveKeysOff", "keydown", "onKey", capture=True)}
"""
    return page_script(script, "robot drive keys", sim_drive_keys="")


def overview(low: np.ndarray, high: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(camera position, look-at point) that show a box (a room) whole, from above a corner."""
    centre = (np.asarray(low, dtype=float) + np.asarray(high, dtype=float)) / 2.0
    centre[2] = float(low[2])  # look at the floor's middle
    extent = np.asarray(high, dtype=float) - np.asarray(low, dtype=float)
    size = float(np.linalg.norm(extent))
    wide = float(max(extent[0], extent[1])) >= WIDE_WORLD
    view_from, distance = (
        (VIEW_FROM_ABOVE, ABOVE_DISTANCE) if wide else (VIEW_FROM, OVERVIEW_DISTANCE)
    )
    direction = view_from / np.linalg.norm(view_from)
    # No turn aside for the control panel: on the 3D stage it docks, and viser insets the
    # canvas to the room left of it (a shift there put the office off centre, to the left).
    return centre + direction * max(size, 1.0) * distance, centre


Box = tuple[np.ndarray, np.ndarray]  # (low corner, high corner)


def grown_box(box: Box | None, points: np.ndarray) -> Box:
    """``box`` grown to hold ``points`` (N x 3): where a moving robot has been."""
    low, high = points.min(axis=0), points.max(axis=0)
    if box is not None:
        low, high = np.minimum(low, box[0]), np.maximum(high, box[1])
    return low, high


def outgrown(framed: Box | None, box: Box) -> bool:
    """Whether ``box`` reaches past what the cameras were framed on (or none was)."""
    return framed is None or bool((box[0] < framed[0]).any() or (box[1] > framed[1]).any())


def padded(box: Box, margin: float) -> Box:
    """``box`` with ``margin`` more on each side, level with the floor (not up or down)."""
    pad = np.array([margin, margin, 0.0])
    return box[0] - pad, box[1] + pad


def follow_step(
    cameras: list[tuple[np.ndarray, np.ndarray]], robot: np.ndarray, last: np.ndarray | None
) -> list[tuple[np.ndarray, np.ndarray]] | None:
    """New (position, look_at) per camera to keep ``robot`` in view, or None: leave them.

    The first time (``last`` None) each camera moves to look at the robot from its
    own angle and distance; after
    that each moves along with the robot, keeping its angle.
    """
    if last is None:
        return [(position - look_at + robot, robot) for position, look_at in cameras]
    delta = robot - last
    if float(np.linalg.norm(delta)) < FOLLOW_MIN_MOVE:
        return None
    return [(position + delta, look_at + delta) for position, look_at in cameras]


class DriveControls:
    """The 'Simulated robot' controls: drive buttons and keys, follow, look at the room."""

    def __init__(
        self,
        gui: viser.GuiApi,
        ui: UiLoop,
        node: Node,
        server: viser.ViserServer,
        frame_pose: Callable[[str], np.ndarray | None],
    ) -> None:
        """``frame_pose(frame)``: that TF frame's 4x4 pose in the Fixed Frame, or None."""
        self._ui = ui
        self._node = node
        self._server = server
        self._frame_pose = frame_pose
        self._keys = node.create_publisher(String, KEY_TOPIC, 10)
        self.presses = 0
        self.status = MarkdownView(gui)
        self._help = MarkdownView(gui, HELP)
        self._drive = gui.add_button_group("Drive", list(BUTTONS))
        gui.add_html(key_listener())
        self.follow = gui.add_checkbox(
            "Follow the robot",
            False,
            hint="Every browser's 3D camera moves along with base_link, keeping its angle",
        )
        self._look = gui.add_button(
            "Look at the whole world", icon=viser.Icon.FOCUS_2, hint="Move your 3D camera to it"
        )
        self.world_view: Callable[[], tuple[np.ndarray, np.ndarray] | None] = lambda: None
        self._drive.on_click(lambda event: self._press(str(event.target.value)))
        self._look.on_click(self._on_look)
        self._following = False
        self._shown: bool | None = None
        self.follow.on_update(ui.callback(self._on_follow))
        self._stop = threading.Event()
        self._follow_on = threading.Event()  # the follow thread sleeps until it is ticked
        self._thread = threading.Thread(target=self._run, name="scene-follow", daemon=True)
        self._thread.start()

    # --- viser's threads post; the UI thread publishes ---
    def _press(self, label: str) -> None:
        name = BUTTONS.get(label)
        if name is not None:  # only the fixed names ever leave the page
            self._ui.post(lambda: self._publish(name))

    def _publish(self, name: str) -> None:
        self._keys.publish(String(data=name))
        self.presses += 1

    def _on_look(self, event: viser.GuiEvent) -> None:
        view = self.world_view()
        if view is not None and event.client is not None:
            self._place(event.client, *view)

    def _on_follow(self) -> None:
        self._following = self.follow.value is True
        if self._following:
            self._follow_on.set()

    # --- UI thread ---
    def refresh(self, graph: GraphSnapshot) -> None:
        sim, teleop = graph.has_node(SIM_NODE), graph.has_node(TELEOP_NODE)
        if sim != self._shown:  # without a world the folder is one line: how to start one
            self._shown = sim
            for handle in (self._drive, self.follow, self._look, self._help.handle):
                handle.visible = sim
        if sim and teleop:
            self.status.show(f"`{SIM_NODE}` and `{TELEOP_NODE}` are running: drive away.")
        elif sim:
            self.status.show(
                f"⚠️ `{SIM_NODE}` runs, but `{TELEOP_NODE}` does not: the keys need it "
                "(it is in the launch group **sim_drive**)."
            )
        else:
            self.status.show(
                "_No simulated world is running._ Start the launch group **sim_drive** in "
                "the **Nodes** tab: a MuJoCo room with a robot and an arm."
            )

    def move_cameras(self, position: np.ndarray, look_at: np.ndarray) -> None:
        """Every browser's camera to ``position``, looking at ``look_at`` (any thread)."""
        for client in list(self._server.get_clients().values()):
            self._place(client, position, look_at)

    @staticmethod
    def _place(client: viser.ClientHandle, position: np.ndarray, look_at: np.ndarray) -> None:
        try:
            with client.atomic():
                client.camera.position = np.asarray(position, dtype=np.float64)
                client.camera.look_at = np.asarray(look_at, dtype=np.float64)
        except Exception:  # a browser that just left: the others still move
            log.debug("could not move a client's camera", exc_info=True)

    def close(self) -> None:
        self._stop.set()
        self._follow_on.set()
        self._thread.join(timeout=2.0)
        self._node.destroy_publisher(self._keys)

    # --- the follow thread ---
    def _run(self) -> None:
        last: np.ndarray | None = None
        while not self._stop.wait(1.0 / FOLLOW_HZ):
            if not self._following:
                last = None
                self._follow_on.clear()
                if not self._following:  # not ticked meanwhile: sleep until it is
                    self._follow_on.wait()
                continue
            pose = self._frame_pose(ROBOT_FRAME)
            if pose is None:
                continue
            robot = np.array(pose[:3, 3], dtype=float)
            clients = list(self._server.get_clients().values())
            cameras: list[tuple[np.ndarray, np.ndarray] | None] = []
            for client in clients:
                try:
                    cameras.append((client.camera.position.copy(), client.camera.look_at.copy()))
                except AssertionError:  # this browser has not reported its camera yet
                    cameras.append(None)
            known = [c for c in cameras if c is not None]
            moves = follow_step(known, robot, last)
            if moves is None:
                continue
            last = robot
            it = iter(moves)
            for client, camera in zip(clients, cameras, strict=True):
                if camera is None:
                    continue
                self._place(client, *next(it))

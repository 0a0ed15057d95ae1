"""A bare viser websocket client for tests: many at once, cheap, and able to send anything.

A headless Chromium page costs hundreds of MB; this client speaks viser's
wire format directly (zstd-compressed msgpack frames in, plain msgpack out),
keeps the GUI state it is sent (labels, values, markdown) and counts what
arrives, so load tests can run ten of them and fuzz tests can send values a
real page never would.
"""

from __future__ import annotations

import html
import re
import threading
import time
import urllib.request
import uuid as uuid_module
from collections import Counter
from collections.abc import Callable, Iterator
from typing import Any
from urllib.parse import urljoin, urlsplit

import msgspec
import viser
import zstandard
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import ClientConnection, connect

from app.lessons.panel import NEXT_LABEL
from app.ui import TAB_NAMES
from app.ui.shown_tools import SCRIPT_TITLE as SHOWN_SCRIPT_TITLE

# The step card's Next: until the step's checks pass it says what it would skip.
NEXT_OR_SKIP = NEXT_LABEL
# What a rendering page reports about its camera (viser waits for one before it counts
# the client as connected).
CAMERA_REPORT = {
    "type": "ViewerCameraMessage",
    "wxyz": (1.0, 0.0, 0.0, 0.0),
    "position": (3.0, 3.0, 3.0),
    "fov": 1.0,
    "near": 0.01,
    "far": 1000.0,
    "image_height": 900,
    "image_width": 1400,
    "look_at": (0.0, 0.0, 0.0),
    "up_direction": (0.0, 0.0, 1.0),
}


# What a tool's tab holds until the dashboard has built it (app/dashboard.py).
PLACEHOLDER = re.compile(r"\*Opening .+…\*")

# How often a reader looks up from its socket to see whether it should close it.
READ_POLL_SEC = 0.05


def connect_quietly(url: str, **options: Any) -> ClientConnection:
    """A websockets sync client without its keepalive thread (see frames_until_closed)."""
    return connect(url, ping_interval=None, **options)


def frames_until_closed(ws: ClientConnection, closing: threading.Event) -> Iterator[str | bytes]:
    """Each frame ``ws`` receives until ``closing`` is set; then this thread closes ``ws``.

    Only one thread may ever join websockets' event thread. On CPython 3.11 two
    threads joining one thread as it ends can race (``Thread._stop`` asserts the
    state lock is free while the other joiner holds it, then releases the
    other's lock): ``RuntimeError: release unlocked lock``, which once killed a
    churner in CI's viser stress test. websockets joins that thread in
    ``recv()`` and ``close()`` when the connection ends, and its keepalive
    thread sleeps in such a join; so test clients run without keepalive (they
    live seconds) and the thread that reads is the one that closes.
    """
    while not closing.is_set():
        try:
            yield ws.recv(timeout=READ_POLL_SEC)
        except TimeoutError:
            continue
    ws.close()


def decode_frame(frame: bytes) -> list[dict[str, Any]]:
    """One server->client frame: [raw size][compressed size][zstd msgpack][binary tail]."""
    raw_size = int.from_bytes(frame[:8], "little")
    packed_size = int.from_bytes(frame[8:16], "little")
    inner = zstandard.ZstdDecompressor().decompress(
        frame[16 : 16 + packed_size], max_output_size=raw_size
    )
    return list(msgspec.msgpack.decode(inner)["messages"])


class WireClient:
    """Connects, reads every frame in a thread, and keeps the GUI state it was sent."""

    def __init__(
        self,
        url: str,
        *,
        headers: dict[str, str] | None = None,
        open_timeout: float = 10.0,
        open_every_tool: bool = True,
        on_message: Callable[[dict[str, Any]], None] | None = None,
    ) -> None:
        """``open_every_tool``: report every tool shown once, as a page that had opened
        them all, so a dashboard builds the tools it builds only when shown
        (app.ui.shown_tools); then report none, so they refresh as tools nobody looks at."""
        self.url = url.replace("http://", "ws://", 1)
        self._headers = dict(headers or {})
        self._open_every_tool = open_every_tool
        self.tools_asked = threading.Event()  # set once every tool was asked for
        self.tools_error: str | None = None  # why asking for them failed
        self.ws: ClientConnection = connect_quietly(
            self.url,
            subprotocols=[f"viser-v{viser.__version__}"],  # type: ignore[list-item]
            additional_headers=headers or {},
            max_size=None,
            open_timeout=open_timeout,
        )
        self.lock = threading.Lock()
        self.gui: dict[str, dict[str, Any]] = {}  # uuid -> {"type", "props"...}
        self.counts: Counter[str] = Counter()
        self.frames = 0
        self.bytes = 0
        self.last_frame_at = 0.0
        self.closed_reason: str | None = None
        # Called with each message once it is applied, under ``lock`` (on the reader thread):
        # what a test sees at the moment a message arrives, in the order they were sent.
        # (Given here, it sees the first message too.)
        self.on_message: Callable[[dict[str, Any]], None] | None = on_message
        # Called once a frame's messages are all applied, under ``lock``: a page draws
        # what one frame brought at once, so this is each state a page can show.
        self.on_frame: Callable[[], None] | None = None
        self._closing = threading.Event()
        self._reader = threading.Thread(target=self._read, name="wire-reader", daemon=True)
        self._reader.start()
        # viser counts a client as connected (and runs its clicks) only after
        # the first camera report, which a page sends as soon as it renders.
        self.send(CAMERA_REPORT)

    def _read(self) -> None:
        try:
            for frame in frames_until_closed(self.ws, self._closing):
                assert isinstance(frame, bytes)
                messages = decode_frame(frame)
                with self.lock:
                    self.frames += 1
                    self.bytes += len(frame)
                    self.last_frame_at = time.monotonic()
                    for message in messages:
                        self._apply(message)
                        if self.on_message is not None:
                            self.on_message(message)
                    if self.on_frame is not None:
                        self.on_frame()
        except ConnectionClosed as exc:
            self.closed_reason = str(exc)
        except Exception as exc:  # reported, then the test fails on it
            self.closed_reason = f"{type(exc).__name__}: {exc}"

    def _apply(self, message: dict[str, Any]) -> None:
        kind = message.get("type", "?")
        self.counts[kind] += 1
        uuid = message.get("uuid")
        if kind == "PointCloudMessage":
            self.counts["cloud_frames"] += 1
        if kind.startswith("Gui") and "props" in message and uuid:
            self.gui[uuid] = {"type": kind, **dict(message["props"])}
            if kind == "GuiHtmlMessage" and self._open_every_tool:
                self._maybe_ask_for_tools(str(self.gui[uuid].get("content", "")))
            self.gui[uuid]["container_uuid"] = message.get("container_uuid")  # where it sits
            if "value" in message:
                self.gui[uuid]["value"] = message["value"]
        elif kind == "GuiUpdateMessage" and uuid in self.gui:
            self.gui[uuid].update(message.get("updates", {}))
        elif kind == "SceneNodeUpdateMessage" and "points" in message.get("updates", {}):
            self.counts["cloud_frames"] += 1  # a new cloud drawn in place of the old one
        elif kind == "GuiRemoveMessage" and uuid:
            self.gui.pop(uuid, None)

    def _maybe_ask_for_tools(self, content: str) -> None:
        """The dashboard's shown-tools script: ask for every tool, off the reader thread."""
        if self.tools_asked.is_set() or f'title="{SHOWN_SCRIPT_TITLE}"' not in content:
            return
        link = re.search(r'data-link="([^"]*)"', content)
        names = re.search(r'data-names="([^"]*)"', content)
        if link is None or names is None:
            return
        # The tools' indices only (a report has room for 64 characters; groups need none).
        listed = html.unescape(names.group(1)).split(",")
        every = ".".join(str(i) for i, name in enumerate(listed) if name in TAB_NAMES)
        href = html.unescape(link.group(1))
        threading.Thread(
            target=self._ask_for_tools, args=(href, every), name="wire-tools", daemon=True
        ).start()

    def _ask_for_tools(self, href: str, every: str) -> None:
        page = f"w{uuid_module.uuid4().hex[:6]}"
        base = urlsplit(self.url.replace("ws://", "http://", 1))
        # The link is relative to the page, which is the folder the websocket opened at.
        folder = base._replace(query="", path=base.path.rstrip("/") + "/").geturl()
        for value in (every, "none"):
            target = urlsplit(urljoin(folder, f"{href}/{page}-{value}"))
            request = urllib.request.Request(
                target._replace(query=base.query).geturl(), headers=self._headers
            )
            try:
                with urllib.request.urlopen(request, timeout=10) as answer:
                    answer.read()
            except OSError as exc:  # wait_for_every_tool says so; a lookup misses a label
                self.tools_error = f"could not ask for the tools: {exc}"
                return
        self.tools_asked.set()

    def wait_for_every_tool(self, timeout: float = 30.0) -> None:
        """Until every tool's widgets have come: asked for, and no tab says "Opening ..."."""
        deadline = time.monotonic() + timeout
        asked = self.tools_asked.wait(timeout)
        assert asked, self.tools_error or self.closed_reason or "never asked for the tools"
        while any(PLACEHOLDER.fullmatch(line) for line in self.markdown().splitlines()):
            assert time.monotonic() < deadline, "a tool was still not built"
            time.sleep(0.05)

    # -- queries -------------------------------------------------------------

    def find(self, label: str | re.Pattern[str], kind: str | None = None) -> str | None:
        """A widget by its label as shown now (a pattern: the whole label matches it)."""
        with self.lock:
            for uuid, props in self.gui.items():
                shown = props.get("label")
                if isinstance(label, re.Pattern):
                    named = isinstance(shown, str) and label.fullmatch(shown) is not None
                else:
                    named = shown == label
                if named and (kind is None or props["type"] == kind):
                    return uuid
        return None

    def graph_nodes(self) -> list[str]:
        """The Logs panel's node filter: exactly the nodes the dashboard's DDS sees."""
        with self.lock:
            for props in self.gui.values():
                options = props.get("options") or []
                if props["type"] == "GuiDropdownMessage" and "(all nodes)" in options:
                    return [o for o in options if str(o).startswith("/")]
        return []

    def markdown(self) -> str:
        with self.lock:
            return "\n".join(str(p["_markdown"]) for p in self.gui.values() if "_markdown" in p)

    def value(self, uuid: str) -> Any:
        with self.lock:
            return self.gui[uuid].get("value")

    # -- actions -------------------------------------------------------------

    def send(self, message: dict[str, Any]) -> None:
        self.ws.send(msgspec.msgpack.encode(message))

    def set_value(self, uuid: str, value: Any) -> None:
        """What a page sends when a widget changes (or a button is clicked: True)."""
        self.send({"type": "GuiUpdateMessage", "uuid": uuid, "updates": {"value": value}})

    def click(self, label: str | re.Pattern[str]) -> None:
        uuid = self.find(label, "GuiButtonMessage")
        assert uuid, f"no button {label!r}"
        self.set_value(uuid, True)

    def close(self) -> None:
        self._closing.set()
        self._reader.join(timeout=5)

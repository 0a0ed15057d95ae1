"""An atomic group reaches a browser in one frame, even right behind a burst (issue 38).

viser 1.1.1 sends a browser its messages in windows of at most 128. An
``atomic()`` block only holds windows back while it runs: once it ends, the next
window takes whatever waits, the group last, and stops at 128. So a group queued
behind a burst of other updates was cut in two, and a page drew the first part
alone. The busy rehearsal ci150 saw a lesson's step switch cut so (the new title
with the last step's buttons) while the tools a test client asked for were being
built. app/viser_threads.py lifts the cap for our servers. Real server, real
websocket client (tests/wire_client.py); no DDS.
"""

from __future__ import annotations

import random
import re

import viser

from tests.conftest import wait_until
from tests.wire_client import WireClient

GROUPS = 40
BURST = (90, 127)  # other updates queued just before each group: around one window's worth
BUTTONS = 10  # the group: a new title, the old buttons removed, new ones added
TITLE = re.compile(r"^group (\d+)$")
BUTTON = re.compile(r"^(\d+)-\d+$")


def test_a_group_behind_a_burst_arrives_in_one_frame(bare_server: viser.ViserServer):
    others = [bare_server.gui.add_markdown(f"other {n}") for n in range(BURST[1])]
    title = bare_server.gui.add_markdown("group 0")
    holder = bare_server.gui.add_folder("buttons")
    with holder:
        buttons = [bare_server.gui.add_button(f"0-{n}") for n in range(BUTTONS)]
    client = WireClient(f"http://127.0.0.1:{bare_server.get_port()}", open_every_tool=False)
    wrong: list[str] = []
    frames: list[int] = []

    def groups_shown() -> tuple[int | None, set[int]]:
        """The title's group and the groups of the buttons shown (under the client's lock)."""
        shown_title: int | None = None
        shown_buttons: set[int] = set()
        for props in client.gui.values():
            text = str(props.get("_markdown") or props.get("label") or "")
            if props["type"] == "GuiMarkdownMessage" and (match := TITLE.match(text)):
                shown_title = int(match.group(1))
            elif props["type"] == "GuiButtonMessage" and (match := BUTTON.match(text)):
                shown_buttons.add(int(match.group(1)))
        return shown_title, shown_buttons

    def settled_on(group: int) -> bool:
        with client.lock:
            return groups_shown() == (group, {group})

    def look() -> None:  # after each frame, on the client's reader thread
        frames.append(1)
        shown_title, shown_buttons = groups_shown()
        if shown_title is not None and shown_buttons != {shown_title}:
            wrong.append(f"title of group {shown_title} drawn with buttons of {shown_buttons}")

    try:
        wait_until(lambda: settled_on(0), timeout=30, what="the first load")
        client.on_frame = look
        rng = random.Random(150)
        for group in range(1, GROUPS + 1):
            for n, other in enumerate(others[: rng.randint(*BURST)]):
                other.content = f"other {n}: {group}"
            with bare_server.atomic():
                title.content = f"group {group}"
                for button in buttons:
                    button.remove()
                with holder:
                    buttons = [bare_server.gui.add_button(f"{group}-{n}") for n in range(BUTTONS)]
            wait_until(lambda g=group: settled_on(g), timeout=30, what=f"group {group}")
    finally:
        client.close()
    assert not wrong, f"{len(wrong)} of {len(frames)} frames: " + "; ".join(wrong[:5])

"""`serve` gives the page's address as soon as its web server listens, then builds the
dashboard into the pages already open (app/ui/opening.py)."""

from __future__ import annotations

import threading
import urllib.request

from app.ui.opening import OPENING_WORDS
from tests.conftest import DashboardProcess, free_port, wait_until
from tests.wire_client import WireClient


def test_a_page_opened_at_the_first_address_gets_the_whole_dashboard(ros_env, progress_dir):
    dash = DashboardProcess(
        ros_env, free_port(), ["--progress-dir", str(progress_dir)], until="is starting"
    )
    seen: list[str] = []  # what the client was told, in order: "note", "gone", "lesson"
    note: list[str] = []  # the opening line's widget
    lock = threading.Lock()

    def told(message: dict) -> None:
        with lock:
            markdown = str(message.get("props", {}).get("_markdown", ""))
            if OPENING_WORDS in markdown:
                note.append(message["uuid"])
                seen.append("note")
            elif message.get("type") == "GuiRemoveMessage" and message.get("uuid") in note:
                seen.append("gone")
            elif "Domain id" in markdown:
                seen.append("header")

    client = None
    try:
        # At the first line the page answers already, while the rest is imported and built.
        with urllib.request.urlopen(dash.url, timeout=10) as page:
            assert page.status == 200, page.status
            assert "<html" in page.read(4096).decode(errors="replace").lower()
        client = WireClient(dash.url, on_message=told)
        # A client that came before the imports were done (as this one does, unless the
        # machine builds the dashboard in the few ms it takes to connect) sees the line,
        # the dashboard arrive under it, then the line go. Either way none of it is left.
        wait_until(
            lambda: (
                "is ready" in dash.log()
                and "header" in seen
                and (seen[0] != "note" or "gone" in seen)
            ),
            timeout=60,
            what=lambda: f"the dashboard built and the opening line gone; told {seen}",
        )
        log = dash.log()
        assert log.index("is starting") < log.index("is ready"), log
        if seen[0] == "note":
            assert seen.index("header") < seen.index("gone"), seen
        assert OPENING_WORDS not in client.markdown()
        assert "Domain id" in client.markdown()
        assert client.closed_reason is None, client.closed_reason
    finally:
        if client is not None:
            client.close()
        assert dash.stop() == 0, dash.log()

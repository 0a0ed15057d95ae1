"""A value a widget cannot take never reaches viser's handle, nor a panel (``app.viser_input``).

viser takes any string a browser sends as a dropdown's value, and casts any value
sent for a number. A real viser server and a bare websocket client (the forged
messages a hostile page could send) show that such an update is dropped where it
comes in: the handle keeps its value, no callback runs, the sending page is told
the value back, and the log has one warning per widget, no traceback.
"""

from __future__ import annotations

import logging

from app.access import make_server
from app.ui import set_options
from app.ui.loop import UiLoop
from tests.conftest import free_port, wait_until
from tests.wire_client import WireClient


def test_a_value_the_dropdown_does_not_offer_is_ignored_and_the_page_told(caplog):
    server, _ = make_server("127.0.0.1", free_port(), None)
    loop = UiLoop()
    acted_on: list[str] = []
    dropdown = server.gui.add_dropdown("Node", ["talker", "listener"], initial_value="talker")
    dropdown.on_update(loop.callback(lambda: acted_on.append(dropdown.value)))
    client = WireClient(f"http://127.0.0.1:{server.get_port()}")
    watcher = WireClient(f"http://127.0.0.1:{server.get_port()}")
    try:
        uuid = wait_until(lambda: client.find("Node", "GuiDropdownMessage"), what="the dropdown")

        def applied() -> list[str]:
            loop.apply_pending()
            return acted_on

        client.set_value(uuid, "listener")  # a real choice: the panel acts on it
        assert wait_until(applied, what="the learner's choice") == ["listener"]

        seen: list[str] = []  # every value the handle had, looked at as fast as we can
        with caplog.at_level(logging.DEBUG, logger="app.viser_input"):
            for count, forged in enumerate(("rm -rf /", "", "x" * 20_000, "talker "), 1):
                client.set_value(uuid, forged)
                wait_until(
                    lambda n=count: (
                        seen.append(dropdown.value)
                        or len([r for r in caplog.records if "offer" in r.message]) == n
                    ),
                    what=f"the refusal of {forged[:20]!r}",
                )
        assert set(seen) == {"listener"}, "a forged value landed on the handle"
        for page in (client, watcher):
            wait_until(lambda p=page: p.value(uuid) == "listener", what="the page told")
        applied()
        assert acted_on == ["listener"], "a forged value reached the panel"
        warnings = [r for r in caplog.records if r.levelno == logging.WARNING]
        assert len(warnings) == 1, "one warning per dropdown, not one per forged message"
        assert "'rm -rf /'" in warnings[0].message and "'Node'" in warnings[0].message

        dropdown.options = ["turtlesim"]  # the server's list moves on: value follows it
        client.set_value(uuid, "listener")  # a pick that raced the new list
        wait_until(lambda: client.value(uuid) == "turtlesim", what="the raced pick put back")
        applied()
        assert acted_on == ["listener"] and dropdown.value == "turtlesim"
    finally:
        client.close()
        watcher.close()
        loop.close()
        server.stop()


def test_a_number_sent_as_words_is_ignored_without_a_traceback(caplog):
    server, _ = make_server("127.0.0.1", free_port(), None)
    number = server.gui.add_number("Rate", initial_value=2.0)
    client = WireClient(f"http://127.0.0.1:{server.get_port()}")
    try:
        uuid = wait_until(lambda: client.find("Rate", "GuiNumberMessage"), what="the number")
        with caplog.at_level(logging.DEBUG):
            for forged in ("rm -rf /", None, [1, 2], {"a": 1}):
                client.set_value(uuid, forged)
            client.set_value(uuid, 5)  # a real value after them: it lands, in order
            wait_until(lambda: number.value == 5.0, what="the real value")
        refused = [r for r in caplog.records if "which takes float" in r.getMessage()]
        assert len(refused) == 4 and refused[0].levelno == logging.WARNING, refused
        assert "'Rate'" in refused[0].getMessage()
        assert not [r for r in caplog.records if r.exc_info or "never retrieved" in r.message]
    finally:
        client.close()
        server.stop()


def test_new_options_keep_the_learners_choice():
    server, _ = make_server("127.0.0.1", free_port(), None)
    dropdown = server.gui.add_dropdown("Topic", ["/a", "/b"], initial_value="/a")
    client = WireClient(f"http://127.0.0.1:{server.get_port()}")
    try:
        uuid = wait_until(lambda: client.find("Topic", "GuiDropdownMessage"), what="the dropdown")
        client.set_value(uuid, "/b")
        wait_until(lambda: dropdown.value == "/b", what="the learner's choice")
        set_options(dropdown, ["/a", "/c"])  # /b went away: it stays, it may come back
        assert dropdown.options == ("/a", "/c", "/b") and dropdown.value == "/b"
        set_options(dropdown, ["/a"], keep_current=False)
        assert dropdown.options == ("/a",) and dropdown.value == "/a"
    finally:
        client.close()
        server.stop()

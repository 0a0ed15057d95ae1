"""A dropdown value the dropdown does not offer never reaches a panel (``app.ui.loop``).

viser takes any string a browser sends as a dropdown's value. A real viser server and
a bare websocket client (the forged messages a hostile page could send) show that
``UiLoop.callback`` posts no intent for such a value and puts the dropdown back, for
this browser and every other, while a choice among the options goes through.
"""

from __future__ import annotations

import logging

from app.access import make_server
from app.ui import set_options
from app.ui.loop import UiLoop
from tests.conftest import free_port, wait_until
from tests.wire_client import WireClient


def test_a_value_the_dropdown_does_not_offer_is_put_back_and_never_acted_on(caplog):
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

        with caplog.at_level(logging.DEBUG, logger="app.ui.loop"):
            # One at a time: viser's pool runs each callback after the message, and a
            # callback reads the value the dropdown has by then.
            for count, forged in enumerate(("rm -rf /", "", "x" * 20_000, "talker "), 1):
                client.set_value(uuid, forged)
                wait_until(
                    lambda n=count: (
                        len([r for r in caplog.records if "offer" in r.message]) == n
                        and dropdown.value == "listener"
                    ),  # logged, then put back (ci85)
                    what=f"the refusal of {forged[:20]!r}",
                )
        assert dropdown.value == "listener", "put back to what the panel last acted on"
        for page in (client, watcher):
            wait_until(lambda p=page: p.value(uuid) == "listener", what="the page put back")
        applied()
        assert acted_on == ["listener"], "a forged value reached the panel"
        warnings = [r for r in caplog.records if r.levelno == logging.WARNING]
        assert len(warnings) == 1, "one warning per dropdown, not one per forged message"
        assert "'rm -rf /'" in warnings[0].message and "'Node'" in warnings[0].message

        dropdown.options = ["turtlesim"]  # the server's list moves on: value follows it
        client.set_value(uuid, "listener")  # a pick that raced the new list
        wait_until(lambda: client.value(uuid) == "turtlesim", what="the raced pick put back")
        applied()
        assert acted_on == ["listener"]
    finally:
        client.close()
        watcher.close()
        loop.close()
        server.stop()


def test_new_options_keep_the_learners_choice_but_never_a_forged_value():
    server, _ = make_server("127.0.0.1", free_port(), None)
    # No callback: the forged value stays, as it does for a moment before it is put back.
    dropdown = server.gui.add_dropdown("Topic", ["/a", "/b"], initial_value="/a")
    client = WireClient(f"http://127.0.0.1:{server.get_port()}")
    try:
        uuid = wait_until(lambda: client.find("Topic", "GuiDropdownMessage"), what="the dropdown")
        client.set_value(uuid, "/b")
        wait_until(lambda: dropdown.value == "/b", what="the learner's choice")
        set_options(dropdown, ["/a", "/c"])  # /b went away: it stays, it may come back
        assert dropdown.options == ("/a", "/c", "/b") and dropdown.value == "/b"

        client.set_value(uuid, "rm -rf /")
        wait_until(lambda: dropdown.value == "rm -rf /", what="the forged value")
        set_options(dropdown, ["/a", "/c"])  # a refresh in the moment before it is put back
        assert "rm -rf /" not in dropdown.options
    finally:
        client.close()
        server.stop()

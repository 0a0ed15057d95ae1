"""The Bags panel in a real browser: record the talker, see the bag, replay it."""

from __future__ import annotations

import re
import threading
import traceback
import zipfile

import pytest
from playwright.sync_api import expect
from std_msgs.msg import String

from app.access import make_server
from app.panels.bags_panel import BagsPanel
from app.ros.graph import GraphSnapshot
from app.ros.monitor import TopicMonitor
from app.ui.loop import UiLoop
from tests.browser.helpers import (
    click,
    cut_off_at_panel_edge,
    expect_text,
    open_folder,
    open_page,
    watched_click,
)
from tests.conftest import free_port, wait_until

pytestmark = [pytest.mark.browser, pytest.mark.ros]


@pytest.fixture
def bags_page(browser, probe, tmp_path):
    """Only the Bags panel on a viser server, refreshed as the dashboard's UI thread does."""
    server, _ = make_server("127.0.0.1", free_port(), None)  # as the dashboard makes its own
    ui = UiLoop()
    panel = BagsPanel(server.gui, ui, probe.node, tmp_path / "bags")
    stop = threading.Event()
    failures: list[str] = []  # a refresh that raised: told at the end, not a silent dead loop

    def refresh_loop() -> None:
        while not stop.is_set():
            try:
                ui.wait(0.2)
                ui.apply_pending()
                panel.refresh(GraphSnapshot())
                server.flush()
            except Exception:
                failures.append(traceback.format_exc())

    thread = threading.Thread(target=refresh_loop, daemon=True)
    thread.start()
    context = browser.new_context(viewport={"width": 1400, "height": 900})
    page = context.new_page()
    open_page(page, f"http://127.0.0.1:{server.get_port()}", "button", "Record")
    yield page, tmp_path / "bags"
    context.close()
    stop.set()
    thread.join(2)
    ui.close()
    panel.close()
    server.stop()
    assert not failures, failures[0]


def test_record_stop_inspect_and_replay_in_the_panel(bags_page, supervisor, probe):
    page, folder = bags_page
    supervisor.start("talker")
    wait_until(lambda: probe.node.count_publishers("/chatter") >= 1, timeout=30, what="talker")
    click(page, "Record")
    expect_text(page, "Recording into")
    # Live per-topic counts: the line for /chatter reaches 3 messages.
    expect_text(page, re.compile(r"\[std_msgs/msg/String\] · ([3-9]|\d\d+) messages"), 30_000)
    click(page, "Stop recording")
    expect_text(page, re.compile(r"Saved rosbag2_.*: \d+ messages"))
    expect_text(page, re.compile(r"Topic: /chatter \| Type: std_msgs/msg/String \| Count: \d+"))
    assert cut_off_at_panel_edge(page, "button", "Record") == [], (
        "cut off at the panel's right edge"
    )
    assert supervisor.stop("talker").result(timeout=15).exit_code == 0
    (bag,) = [p for p in folder.iterdir() if p.is_dir()]
    assert (bag / "metadata.yaml").exists()

    wait_until(lambda: probe.node.count_publishers("/chatter") == 0, timeout=30, what="no talker")
    listener = TopicMonitor(probe.node, "/chatter", String, qos=100)
    click(page, "Play")
    expect_text(page, re.compile(r"Played rosbag2_.*: \d+ messages"), timeout=30_000)
    assert listener.count >= 3
    assert all(m.data.startswith("Hello World: ") for _s, m in listener.recent())
    listener.close()

    with page.expect_download(timeout=20_000) as download:
        click(page, "Download bag (.zip)")
    saved = folder.parent / "download.zip"
    download.value.save_as(saved)
    with zipfile.ZipFile(saved) as archive:
        names = sorted(archive.namelist())
    assert names == sorted(f"{bag.name}/{p.name}" for p in bag.iterdir())

    # Loop, pause, resume, stop: the progress line follows.
    page.get_by_label("Loop").check()
    click(page, "Play")
    expect_text(page, re.compile(r"^playing: "))
    click(page, "Pause")
    expect_text(page, re.compile(r"^paused: "))
    click(page, "Resume")
    expect_text(page, re.compile(r"^playing: .* · pass \d+$"))
    click(page, "Stop playback")
    expect_text(page, re.compile(r"Stopped rosbag2_.* after \d+ messages"))


def test_open_in_foxglove_serves_the_live_graph_until_stopped(bags_page, supervisor, probe):
    """The Bags tool's Open in Foxglove: a Foxglove client (tests/foxglove/client.py, written
    from the protocol's specification) at the address shown gets /chatter as ROS 2 CDR."""
    from rclpy.serialization import deserialize_message

    from tests.foxglove.client import FoxgloveClient

    page, _folder = bags_page
    supervisor.start("talker")
    wait_until(lambda: probe.node.count_publishers("/chatter") >= 1, timeout=30, what="talker")
    open_folder(page, "Open in Foxglove")
    seen = watched_click(page, "Open in Foxglove")
    served = page.get_by_text(re.compile(r"Serving this dashboard's ROS graph at ws://"))
    try:
        expect(served.first).to_be_visible(timeout=20_000)
    except AssertionError as exc:  # what the click did, if it did not land (ci104, cb18c3d's)
        raise AssertionError(f"the click: {seen()}") from exc
    url = re.search(r"ws://127\.0\.0\.1:\d+", served.first.inner_text())
    assert url, served.first.inner_text()
    client = FoxgloveClient(url.group())
    try:
        channel = client.wait_for(lambda: client.channel("/chatter"), 30, "/chatter offered")
        assert (channel["encoding"], channel["schemaEncoding"]) == ("cdr", "ros2msg")
        # As Foxglove's app does, a topic offered again on a new channel is subscribed
        # again: the bridge closes a channel whose publishers were all gone for 2 s and
        # offers a new one when they are back (rehearsal ci62, one core busy: the client
        # subscribed to channel 1 after the server had closed it, and heard nothing).
        subscriptions = {channel["id"]: client.subscribe(channel["id"])}

        def chatter_heard() -> int:
            now = client.channel("/chatter")
            if now is not None and now["id"] not in subscriptions:
                subscriptions[now["id"]] = client.subscribe(now["id"])
            return sum(client.count(sub) for sub in subscriptions.values())

        client.wait_for(lambda: chatter_heard() >= 2, 30, f"two /chatter messages {subscriptions}")
        last = max(subscriptions.values(), key=client.count)
        said = deserialize_message(client.messages(last)[-1].payload, String)
        assert said.data.startswith("Hello World: ")
        expect_text(page, re.compile(r"\d+ topics offered · 1 watched by Foxglove"))
        click(page, "Stop the Foxglove server")
        expect_text(page, "The Foxglove server is stopped.")
        assert client.closed.wait(10), "the client is still connected after Stop"
    finally:
        client.close()
        supervisor.stop("talker").result(timeout=15)

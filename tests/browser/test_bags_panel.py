"""The Bags panel in a real browser: record the talker, see the bag, replay it."""

from __future__ import annotations

import re
import threading
import zipfile

import pytest
import viser
from std_msgs.msg import String

from app.panels.bags_panel import BagsPanel
from app.ros.graph import GraphSnapshot
from app.ros.monitor import TopicMonitor
from app.ui.loop import UiLoop
from tests.browser.helpers import click, cut_off_at_panel_edge, expect_text
from tests.conftest import free_port, wait_until

pytestmark = [pytest.mark.browser, pytest.mark.ros]


@pytest.fixture
def bags_page(browser, probe, tmp_path):
    """Only the Bags panel on a viser server, refreshed as the dashboard's UI thread does."""
    server = viser.ViserServer(host="127.0.0.1", port=free_port(), verbose=False)
    ui = UiLoop()
    panel = BagsPanel(server.gui, ui, probe.node, tmp_path / "bags")
    stop = threading.Event()

    def refresh_loop() -> None:
        while not stop.is_set():
            ui.wait(0.2)
            ui.apply_pending()
            panel.refresh(GraphSnapshot())
            server.flush()

    thread = threading.Thread(target=refresh_loop, daemon=True)
    thread.start()
    context = browser.new_context(viewport={"width": 1400, "height": 900})
    page = context.new_page()
    page.goto(f"http://127.0.0.1:{server.get_port()}")
    yield page, tmp_path / "bags"
    context.close()
    stop.set()
    thread.join(2)
    ui.close()
    panel.close()
    server.stop()


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

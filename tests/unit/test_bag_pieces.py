"""The pure parts of app.bags: remap rules, replay QoS, sizes, and repairing a cut MCAP."""

from __future__ import annotations

import pytest
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rosbags.rosbag2 import Reader, StoragePlugin, Writer

from app.bags.definitions import definition
from app.bags.errors import BagError
from app.bags.info import human_size
from app.bags.player import parse_remap
from app.bags.qos import replay_profile, to_bag
from app.bags.repair import reindex


def test_remap_rules():
    assert parse_remap(["/a:=/b", " /c := /d "]) == {"/a": "/b", "/c": "/d"}
    for bad in ("/a", ":=/b", "/a:="):
        with pytest.raises(BagError, match="bad remap rule"):
            parse_remap([bad])


def test_replay_qos_follows_what_was_offered():
    latched = to_bag(
        QoSProfile(
            depth=1,
            durability=DurabilityPolicy.TRANSIENT_LOCAL,
            reliability=ReliabilityPolicy.RELIABLE,
        )
    )
    volatile = to_bag(QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT))
    profile = replay_profile([latched])
    assert profile.durability == DurabilityPolicy.TRANSIENT_LOCAL
    assert profile.reliability == ReliabilityPolicy.RELIABLE and profile.depth == 1
    mixed = replay_profile([latched, volatile])  # one volatile publisher: not latched
    assert mixed.durability == DurabilityPolicy.VOLATILE
    assert mixed.reliability == ReliabilityPolicy.BEST_EFFORT and mixed.depth >= 100
    assert replay_profile([]).reliability == ReliabilityPolicy.BEST_EFFORT


def test_sizes_as_rosbag2_prints_them():
    assert human_size(512) == "512 B"
    assert human_size(13.5 * 1024) == "13.5 KiB"
    assert human_size(3 * 1024**3) == "3.0 GiB"


def test_a_cut_off_mcap_is_repaired_in_place_up_to_its_last_complete_chunk(tmp_path):
    bag = tmp_path / "cut"
    msgdef, digest = definition("std_msgs/msg/String")
    writer = Writer(bag, version=9, storage_plugin=StoragePlugin.MCAP)
    writer.open()
    conn = writer.add_connection("/t", "std_msgs/msg/String", msgdef=msgdef, rihs01=digest)
    chunk_ends = []
    for n in range(300):
        text = f"{n:04d}".encode() + b"x" * 10_000
        data = b"\x00\x01\x00\x00" + (len(text) + 1).to_bytes(4, "little") + text + b"\x00"
        writer.write(conn, 1_000_000_000 + n * 1_000_000, data)
        if n % 100 == 99:  # what the recorder does every flush interval
            writer.storage.close_chunk()  # type: ignore[union-attr]
            writer.storage.bio.flush()  # type: ignore[union-attr]
            chunk_ends.append(writer.storage.bio.tell())  # type: ignore[union-attr]
    mcap = bag / "cut.mcap"
    writer.storage.bio.close()  # type: ignore[union-attr]  # a crash: no summary, no metadata
    with open(mcap, "r+b") as handle:
        handle.truncate(chunk_ends[1] + 5000)  # the third chunk was half written

    line = reindex(bag)
    assert line.startswith(f"Reindexed {bag}: 200 messages on 1 topics")
    with Reader(bag) as reader:
        texts = [raw[8:12].decode() for _c, _t, raw in reader.messages()]
    assert texts == [f"{n:04d}" for n in range(200)]
    assert reindex(bag).endswith("1 topics")  # a second reindex changes nothing


def test_in_the_dashboard_a_bag_name_never_leaves_the_bags_folder(tmp_path, monkeypatch):
    from app.bags import folder
    from app.bags.errors import BagError

    monkeypatch.setenv(folder.ENV_VAR, str(tmp_path / "bags"))
    monkeypatch.setattr(folder._Policy, "confined", True)
    inside = (tmp_path / "bags").resolve()
    assert folder.output_path("talker_bag") == inside / "talker_bag"
    assert folder.existing_path("sub/b") == inside / "sub" / "b"
    escapes = [
        (folder.output_path, "/etc/cron.d/x"),
        (folder.output_path, "../progress"),
        (folder.output_path, "a/../../x"),
        (folder.existing_path, "/root/.ssh/id_rsa"),
        (folder.existing_path, "../../app"),
    ]
    for resolve, name in escapes:
        with pytest.raises(BagError, match="bags folder"):
            resolve(name)


def test_a_forged_bag_name_in_the_panel_reaches_no_file_outside_the_folder(tmp_path):
    """viser does not check a dropdown's value: info, play and download must not follow it."""
    from app.panels.bags_panel import BagsPanel
    from app.ui.loop import UiLoop
    from tests.unit.fake_gui import FakeGui

    folder = tmp_path / "bags"
    (folder / "talker_bag").mkdir(parents=True)
    (folder / "talker_bag" / "metadata.yaml").write_text("rosbag2_bagfile_information: {}\n")
    (tmp_path / "secret").mkdir()
    panel = BagsPanel(FakeGui(), UiLoop(), node=None, folder=folder)  # type: ignore[arg-type]
    panel._refresh_bags()  # what the UI thread does every few seconds: list the folder
    for forged in ("../secret", "/etc", "talker_bag/../../secret"):
        panel._selector.value = forged
        assert panel._selected() is None, forged
    panel._selector.value = "talker_bag"
    assert panel._selected() == folder / "talker_bag"

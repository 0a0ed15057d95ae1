"""The bag stage reads a bag's summary and its messages' times, and draws a tick for each."""

from __future__ import annotations

import re

from rosbags.rosbag2 import Writer
from rosbags.typesys import Stores, get_typestore

from app.stage import bag_stage
from app.stage.bag_stage import read_bag, timeline_svg

SEC = 1_000_000_000


def _write(folder, chatter: int, other: int) -> None:
    store = get_typestore(Stores.ROS2_JAZZY)
    string = store.types["std_msgs/msg/String"]
    with Writer(folder, version=8) as writer:
        for topic, count in (("/chatter", chatter), ("/other", other)):
            conn = writer.add_connection(topic, string.__msgtype__, typestore=store)
            for i in range(count):
                data = store.serialize_cdr(string(data=f"hello {i}"), string.__msgtype__)
                writer.write(conn, 100 * SEC + i * SEC // 2, data)


def test_every_message_is_a_tick_on_its_topics_row(tmp_path):
    _write(tmp_path / "talker_bag", chatter=24, other=3)
    picture = read_bag(tmp_path / "talker_bag")
    assert picture.info.message_count == 27
    assert {t: len(s) for t, s in picture.stamps.items()} == {"/chatter": 24, "/other": 3}
    svg = timeline_svg(picture)
    assert len(re.findall(r"<line x1=\"[\d.]+\" y1=\"\d+\"", svg)) == 27 + 1  # and the axis
    assert "/chatter (24)" in svg and "/other (3)" in svg
    assert "11.5 s" in svg  # the last second mark: the bag's length


def test_a_long_bag_draws_at_most_max_ticks_per_topic(tmp_path, monkeypatch):
    monkeypatch.setattr(bag_stage, "MAX_TICKS", 10)
    _write(tmp_path / "long", chatter=95, other=0)
    picture = read_bag(tmp_path / "long")
    assert 9 <= len(picture.stamps["/chatter"]) <= 10  # every 10th message of 95

"""Independent readers for the bags we write: the `mcap` package, and rosbags' own."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_typestore


def mcap_messages(bag: Path) -> list[tuple[str, int, Any]]:
    """(topic, log time, decoded message) for every message, decoded by mcap_ros2."""
    out = []
    for path in sorted(bag.glob("*.mcap")):
        with open(path, "rb") as handle:
            reader = make_reader(handle, decoder_factories=[DecoderFactory()])
            for _schema, channel, message, decoded in reader.iter_decoded_messages():
                out.append((channel.topic, message.log_time, decoded))
    return out


def rosbags_messages(bag: Path) -> list[tuple[str, int, Any]]:
    """(topic, timestamp, message) for every message, deserialized by rosbags."""
    store = get_typestore(Stores.ROS2_JAZZY)
    with Reader(bag) as reader:
        return [
            (conn.topic, stamp, store.deserialize_cdr(raw, conn.msgtype))
            for conn, stamp, raw in reader.messages()
        ]

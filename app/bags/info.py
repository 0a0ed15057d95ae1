"""What `ros2 bag info` prints, from a bag's metadata (read by rosbags)."""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import yaml
from rosbags.interfaces import ConnectionExtRosbag2

from app.bags.bagfile import bag_dir, open_bag
from app.bags.qos import describe

LABEL_WIDTH = 19  # rosbag2 aligns values after "Topic information: "


@dataclass(frozen=True)
class TopicInfo:
    name: str
    msgtype: str
    count: int
    serialization_format: str
    qos: str  # "reliable, transient_local": how a replay will publish it


@dataclass(frozen=True)
class BagInfo:
    path: Path
    files: tuple[str, ...]
    size: int  # bytes on disk, every file of the bag folder
    storage: str
    distro: str
    start_ns: int
    duration_ns: int
    message_count: int
    compression: str  # "zstd (file)", or "" when uncompressed
    topics: tuple[TopicInfo, ...]

    @property
    def end_ns(self) -> int:
        return self.start_ns + self.duration_ns


def human_size(size: float) -> str:
    """rosbag2's sizes: binary units with one decimal ('13.5 KiB')."""
    for unit in ("B", "KiB", "MiB", "GiB"):
        if size < 1024 or unit == "GiB":
            return f"{size:.0f} {unit}" if unit == "B" else f"{size:.1f} {unit}"
        size /= 1024
    return f"{size:.1f} GiB"


def stamp_text(ns: int) -> str:
    """'Nov 23 2026 04:07:27.123456789 (1763870847.123456789)', local time as rosbag2 prints."""
    sec, frac = divmod(ns, 1_000_000_000)
    day = time.strftime("%b %e %Y %H:%M:%S", time.localtime(sec))
    return f"{day}.{frac:09d} ({sec}.{frac:09d})"


def read_info(path: Path) -> BagInfo:
    """The bag's summary; BagError (one line) if it is damaged or not a bag."""
    with open_bag(path) as reader:
        topics = []
        for name, topic in sorted(reader.topics.items()):
            conns = topic.connections
            offered = [
                q
                for c in conns
                if isinstance(c.ext, ConnectionExtRosbag2)
                for q in c.ext.offered_qos_profiles
            ]
            fmt = (
                conns[0].ext.serialization_format
                if conns and isinstance(conns[0].ext, ConnectionExtRosbag2)
                else "cdr"
            )
            topics.append(
                TopicInfo(name, topic.msgtype or "?", topic.msgcount, fmt, describe(offered))
            )
        folder = bag_dir(path)
        # rosbags checked this file while opening; the fields it does not expose come from it.
        text = (folder / "metadata.yaml").read_text(encoding="utf-8")
        meta = yaml.safe_load(text)["rosbag2_bagfile_information"]
        files = tuple(Path(p).name for p in meta.get("relative_file_paths") or [])
        mode = str(meta.get("compression_mode") or "")
        fmt = str(meta.get("compression_format") or "")
        return BagInfo(
            path=folder,
            files=files,
            size=sum(p.stat().st_size for p in folder.iterdir() if p.is_file()),
            storage=str(meta.get("storage_identifier", "")),
            distro=str(meta.get("ros_distro") or ""),
            start_ns=reader.start_time if reader.message_count else 0,
            duration_ns=reader.duration if reader.message_count else 0,
            message_count=reader.message_count,
            compression=f"{fmt} ({mode})" if mode and fmt else "",
            topics=tuple(topics),
        )


def _row(label: str, value: str) -> str:
    return f"{label + ':':<{LABEL_WIDTH}}{value}"


def info_lines(info: BagInfo) -> list[str]:
    """The text of `ros2 bag info` (Jazzy's layout)."""
    lines = [
        _row("Files", info.files[0] if info.files else ""),
        *[" " * LABEL_WIDTH + name for name in info.files[1:]],
        _row("Bag size", human_size(info.size)),
        _row("Storage id", info.storage),
        _row("ROS Distro", info.distro),
        _row("Duration", f"{info.duration_ns / 1e9:.9f}s"),
        _row("Start", stamp_text(info.start_ns)),
        _row("End", stamp_text(info.end_ns)),
        _row("Messages", str(info.message_count)),
    ]
    if info.compression:
        lines.append(_row("Compression", info.compression))
    topic_lines = [
        f"Topic: {t.name} | Type: {t.msgtype} | Count: {t.count} | "
        f"Serialization Format: {t.serialization_format}"
        for t in info.topics
    ]
    lines.append(_row("Topic information", topic_lines[0] if topic_lines else ""))
    lines.extend(" " * LABEL_WIDTH + line for line in topic_lines[1:])
    lines.append(_row("Service", "0"))
    lines.append(_row("Service information", ""))
    return lines

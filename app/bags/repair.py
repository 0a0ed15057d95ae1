"""`ros2 bag reindex`: make a recording that never closed readable again.

A recording killed mid-way (SIGKILL, power cut, disk full) has no
``metadata.yaml``, and its MCAP file stops in the middle of a record with no
summary or footer. Repair keeps every complete record, cuts the rest, ends
the file the way MCAP allows for a file without a summary (a data-end record
and a footer whose summary offset is 0, which every MCAP reader answers by
scanning), and writes ``metadata.yaml`` from what is really in the file. An
sqlite3 bag keeps its committed transactions; only the metadata is rebuilt.
Both work in place, so a full disk needs no room for a copy.
"""

from __future__ import annotations

import os
import sqlite3
from pathlib import Path
from typing import BinaryIO

import yaml
from rosbags.interfaces import ConnectionExtRosbag2, Qos
from rosbags.rosbag2 import ReaderError
from rosbags.rosbag2.metadata import TopicWithMessageCount, dump_qos_v9, parse_qos
from rosbags.rosbag2.storage_mcap import McapReader

from app.bags.bagfile import first_line, storage_files
from app.bags.definitions import definition
from app.bags.errors import BagError

ROS_DISTRO = "jazzy"  # the release these bags are for, as a rosbag2 of it writes

MAGIC = b"\x89MCAP0\r\n"
OP_FOOTER, OP_DATA_END, OP_MAX = 0x02, 0x0F, 0x10
FOOTER_SIZE = 1 + 8 + 20 + len(MAGIC)
BAG_VERSION = 9

# What a storage file holds: (topic entries, message count, first stamp, last stamp).
Summary = tuple[list[TopicWithMessageCount], int, int, int]


def truncate_storage(path: Path, end: int) -> None:
    """Cut a storage file back to ``end`` bytes (the end of its last flushed chunk)."""
    if end > 0:
        with open(path, "r+b") as handle:
            handle.truncate(end)


def _has_footer(handle: BinaryIO, size: int) -> bool:
    if size < len(MAGIC) + FOOTER_SIZE:
        return False
    handle.seek(size - FOOTER_SIZE)
    tail = handle.read(FOOTER_SIZE)
    return tail[-8:] == MAGIC and tail[0] == OP_FOOTER


def close_mcap(path: Path) -> bool:
    """End a cut-off MCAP file after its last complete record; False if it was complete."""
    size = path.stat().st_size
    with open(path, "r+b") as handle:
        if handle.read(len(MAGIC)) != MAGIC:
            raise BagError(f"{path} is not an MCAP file")
        if _has_footer(handle, size):
            return False
        pos = good = len(MAGIC)
        while pos + 9 <= size:
            handle.seek(pos)
            head = handle.read(9)
            op, length = head[0], int.from_bytes(head[1:], "little")
            end = pos + 9 + length
            if op == 0 or op > OP_MAX or end > size or op in (OP_FOOTER, OP_DATA_END):
                break  # cut mid-record, garbage, or a half-written summary: stop here
            pos = good = end
        handle.truncate(good)
        handle.seek(good)
        handle.write(bytes([OP_DATA_END]) + (4).to_bytes(8, "little") + bytes(4))
        handle.write(bytes([OP_FOOTER]) + (20).to_bytes(8, "little") + bytes(20) + MAGIC)
        handle.flush()
        os.fsync(handle.fileno())
    return True


def _type_hash(msgtype: str) -> str:
    try:
        return definition(msgtype)[1]
    except BagError:
        return ""  # a type not installed here: readers decode from the stored definition


def _topic_entry(name: str, msgtype: str, qos: list[Qos], count: int) -> TopicWithMessageCount:
    return {
        "topic_metadata": {
            "name": name,
            "type": msgtype,
            "serialization_format": "cdr",
            "offered_qos_profiles": dump_qos_v9(qos),
            "type_description_hash": _type_hash(msgtype),
        },
        "message_count": count,
    }


def _mcap_summary(path: Path) -> Summary:
    """(topic entries, message count, first stamp, last stamp) by scanning the file."""
    reader = McapReader(path)
    try:
        reader.open()
        stats = reader.statistics
        assert stats is not None
        topics = [
            _topic_entry(
                c.topic,
                c.msgtype,
                c.ext.offered_qos_profiles if isinstance(c.ext, ConnectionExtRosbag2) else [],
                stats.channel_message_counts.get(c.id, 0),
            )
            for c in reader.connections
        ]
        return topics, stats.message_count, stats.start_time, stats.end_time
    except (ReaderError, OSError, ValueError) as exc:
        raise BagError(f"cannot reindex {path}: {first_line(exc)}") from None
    finally:
        if reader.bio:
            reader.close()


def _sqlite_summary(path: Path) -> Summary:
    try:
        # A normal connection: a hot journal left by a killed writer is rolled back here.
        conn = sqlite3.connect(f"file:{path}", uri=True)
        try:
            rows = conn.execute(
                "SELECT id, name, type, offered_qos_profiles FROM topics ORDER BY id"
            ).fetchall()
            stats = {
                tid: (n, lo, hi)
                for tid, n, lo, hi in conn.execute(
                    "SELECT topic_id, COUNT(*), MIN(timestamp), MAX(timestamp) "
                    "FROM messages GROUP BY topic_id"
                )
            }
        finally:
            conn.close()
    except sqlite3.Error as exc:
        raise BagError(f"cannot reindex {path}: {first_line(exc)}") from None
    topics = [
        _topic_entry(name, msgtype, parse_qos(qos or ""), stats.get(tid, (0, 0, 0))[0])
        for tid, name, msgtype, qos in rows
    ]
    count = sum(s[0] for s in stats.values())
    start = min((s[1] for s in stats.values()), default=0)
    end = max((s[2] for s in stats.values()), default=0)
    return topics, count, start, end


def write_metadata(folder: Path, storage: str, files: list[Path], summary: Summary) -> None:
    topics, count, start, end = summary
    start = start if count else 0
    duration = max(0, end - start) if count else 0
    info = {
        "version": BAG_VERSION,
        "storage_identifier": storage,
        "relative_file_paths": [f.name for f in files],
        "duration": {"nanoseconds": duration},
        "starting_time": {"nanoseconds_since_epoch": start},
        "message_count": count,
        "topics_with_message_count": topics,
        "compression_format": "",
        "compression_mode": "",
        "files": [
            {
                "path": f.name,
                "starting_time": {"nanoseconds_since_epoch": start},
                "duration": {"nanoseconds": duration},
                "message_count": count,
            }
            for f in files
        ],
        "custom_data": None,
        "ros_distro": ROS_DISTRO,
    }
    target = folder / "metadata.yaml"
    tmp = folder / ".metadata.yaml.tmp"
    tmp.write_text(yaml.safe_dump({"rosbag2_bagfile_information": info}, sort_keys=False))
    tmp.replace(target)


def stamp_distro(folder: Path) -> None:
    """Name the ROS release in a closed bag's metadata, as rosbag2 does ('jazzy'): the
    writer library puts its own name there, which ``ros2 bag info`` then showed as the
    distro. Raises OSError or yaml.YAMLError when the file cannot be rewritten."""
    target = folder / "metadata.yaml"
    data = yaml.safe_load(target.read_text(encoding="utf-8"))
    data["rosbag2_bagfile_information"]["ros_distro"] = ROS_DISTRO
    tmp = folder / ".metadata.yaml.tmp"
    tmp.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    tmp.replace(target)


def reindex(folder: Path) -> str:
    """Repair the bag folder in place; returns one line saying what was done."""
    if not folder.is_dir():
        raise BagError(f"no bag folder at {folder}")
    files = storage_files(folder)
    if not files:
        raise BagError(f"{folder} holds no .mcap or .db3 file to reindex")
    if any(f.name.endswith(".zstd") for f in files):
        raise BagError(f"{folder} is compressed as a whole file; it cannot be reindexed")
    if all(f.suffix == ".mcap" for f in files):
        closed = [f.name for f in files if close_mcap(f)]
        summaries = [_mcap_summary(f) for f in files]
        storage = "mcap"
    elif all(f.suffix == ".db3" for f in files):
        closed = []
        summaries = [_sqlite_summary(f) for f in files]
        storage = "sqlite3"
    else:
        raise BagError(f"{folder} mixes storage formats; keep one kind of file")
    merged: dict[str, TopicWithMessageCount] = {}
    for topics, *_ in summaries:
        for entry in topics:
            name = entry["topic_metadata"]["name"]
            if name in merged:
                merged[name]["message_count"] += entry["message_count"]
            else:
                merged[name] = entry
    count = sum(s[1] for s in summaries)
    starts = [s[2] for s in summaries if s[1]]
    ends = [s[3] for s in summaries if s[1]]
    summary = (list(merged.values()), count, min(starts, default=0), max(ends, default=0))
    write_metadata(folder, storage, files, summary)
    cut = f"; closed the cut-off file {', '.join(closed)}" if closed else ""
    return f"Reindexed {folder}: {count} messages on {len(merged)} topics{cut}"

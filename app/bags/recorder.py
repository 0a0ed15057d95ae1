"""Recording: one writer thread takes the messages and owns the bag.

Messages are never deserialized here. Each subscription is raw (the
middleware's CDR bytes) and belongs to the recording's own node, which no
executor spins: every ``BATCH_PAUSE_SEC`` the writer thread takes whatever
waits on each subscription (the public ``Subscription.handle.take_message``
an executor uses), stamped with the time the middleware received it, and
writes the batch in receive-time order. Topics are added by the thread that
drives the recording (``poll``) through a queue the writer reads first, so a
topic's connection always exists before its first message is taken.

Why no executor: rclpy's executor rebuilds its wait set, every waitable of
every node it spins included, for each message it hands over. A recording of
every topic of the simulated world (some 600 messages a second at twice real
time) on the grader's node made that node's executor wake for each one: a
third of the grading process's CPU (measured on the wall_follower gradings).
Taken in batches, a topic waits at most one pause in its queue
(``SUBSCRIPTION_DEPTH`` deep: a 1 kHz topic survives a writer held up for a
second). Measured side by side (bench/bag_record.py): on a loaded machine
this recorder lost 0 of 50,150 messages where a plain rosbags writer fed by
plain subscribers lost 17,196.

Durability: every ``flush_interval`` the writer closes the current MCAP
chunk and hands it to the kernel (sqlite3: commits), so a SIGKILL of the
process loses at most that last interval; ``repair`` makes the rest readable.
A write that fails (disk full, file too large) stops the recording with a
message, cuts the file back to its last flushed chunk and closes it as a
readable bag.
"""

from __future__ import annotations

import contextlib
import queue
import sqlite3
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import yaml
from rclpy.exceptions import InvalidHandle
from rclpy.node import Node
from rclpy.subscription import Subscription
from rclpy.topic_endpoint_info import TopicEndpointInfo
from rosbags.interfaces import Connection, Qos
from rosbags.rosbag2 import CompressionFormat, CompressionMode, StoragePlugin, Writer, WriterError
from rosbags.rosbag2.storage_mcap import McapWriter
from rosbags.rosbag2.storage_sqlite3 import Sqlite3Writer

from app.bags import qos as bag_qos
from app.bags.definitions import definition
from app.bags.errors import BagError
from app.bags.repair import reindex, stamp_distro, truncate_storage
from app.ros.convert import ConversionError, import_type
from app.ros.names import QUIET_TOPICS, is_internal_topic
from app.ros.qos import matching_qos

STORAGES = {"mcap": StoragePlugin.MCAP, "sqlite3": StoragePlugin.SQLITE3}
COMPRESSION_MODES = {"none": CompressionMode.NONE, "file": CompressionMode.FILE}
COMPRESSION_MODES["message"] = CompressionMode.MESSAGE
# Deep enough that a 1 kHz topic survives a slow writer moment without drops.
SUBSCRIPTION_DEPTH = 1000
BATCH_PAUSE_SEC = 0.02  # the writer lets messages gather this long between batches...
IDLE_PAUSE_SEC = 0.1  # ...or this long after a batch that found none (a quiet recording)
SUBSCRIBED = "Subscribed to topic"  # rosbag2's words, the line a learner waits for
TAKE_MAX = 5_000  # messages taken from one subscription in one batch (then the next topic)
READER_NAME = "rosbag2_recorder"  # the recording's own node, as `ros2 bag record` names it
BAG_VERSION: Literal[9] = 9  # Jazzy's rosbag2 metadata version
# Writing errors that end a recording: the disk, the file size limit, sqlite's own.
WRITE_ERRORS = (OSError, sqlite3.Error, WriterError)


@dataclass(frozen=True)
class TopicCount:
    topic: str
    msgtype: str
    count: int
    size: int  # serialized bytes


@dataclass(frozen=True)
class RecordingStatus:
    """A snapshot for progress lines and the panel (immutable, any thread)."""

    path: Path
    topics: tuple[TopicCount, ...]
    duration: float  # seconds since the recording started
    size: int  # bytes on disk so far
    flushed: int  # messages safely handed to the kernel (survive a SIGKILL)
    failure: str | None  # why the recording stopped early
    finished: bool

    @property
    def count(self) -> int:
        return sum(t.count for t in self.topics)


@dataclass(frozen=True)
class _NewTopic:
    key: int
    topic: str
    msgtype: str
    msgdef: str
    rihs01: str
    offered: list[Qos]
    subscription: Subscription
    py_type: type


_Message = tuple[int, int, bytes]  # (topic key, receive time in ns, CDR bytes)
_Item = _NewTopic | None  # what the driving thread hands the writer: a topic, or stop


def _in_time_order(batch: list[_Message]) -> list[_Message]:
    """Messages by receive time (they are taken in per-topic runs).

    Writing in time order keeps each MCAP chunk's time range apart from the
    next one's, which readers (rosbags' among them) need to replay smoothly.
    """
    return sorted(batch, key=_stamp)


def _stamp(item: _Message) -> int:
    return item[1]


def _never_called(_message: object) -> None:
    """The callback rclpy asks for; no executor spins the recording's node."""


class Recorder:
    """One recording into one new bag folder. Drive it with ``poll`` and end it with ``stop``."""

    def __init__(
        self,
        node: Node,
        path: Path,
        topics: list[str] | None = None,
        *,
        all_topics: bool = False,
        storage: str = "mcap",
        compression_mode: str = "none",
        compression_format: str = "zstd",
        flush_interval: float = 1.0,
        skip_types: frozenset[str] = frozenset(),
        reader_name: str = READER_NAME,
    ) -> None:
        """``node`` looks at the graph; the subscriptions are on a node of the recording's
        own, ``reader_name``, in ``node``'s context and namespace. ``skip_types``: message types
        ``all_topics`` leaves out (a topic named in ``topics`` is recorded whatever its
        type)."""
        if storage not in STORAGES:
            raise BagError(f"unknown storage '{storage}' (choose {' or '.join(STORAGES)})")
        if compression_mode not in COMPRESSION_MODES:
            raise BagError(f"unknown compression mode '{compression_mode}' (file or message)")
        if compression_mode != "none" and compression_format != "zstd":
            raise BagError(f"unknown compression format '{compression_format}' (only zstd)")
        if not topics and not all_topics:
            raise BagError("name the topics to record, or -a for all of them")
        self.path = path
        self._node = node
        self._wanted = list(dict.fromkeys(topics or []))
        self._all = all_topics
        self._skip_types = skip_types
        self._flush_interval = flush_interval
        self._queue: queue.SimpleQueue[_Item] = queue.SimpleQueue()
        self._stopping = threading.Event()
        self._subs: dict[str, Subscription] = {}
        self._topics: list[tuple[str, str]] = []  # by key: (topic, type)
        self._skipped: set[str] = set()
        self._lock = threading.Lock()  # guards the counters and the failure below
        self._counts: list[int] = []
        self._sizes: list[int] = []
        self._flushed = 0
        self._failure: str | None = None
        self._finished = False
        self._accepting = True
        self._started = time.monotonic()
        if path.exists():
            raise BagError(f"cannot record into {path}: it already exists")
        # No executor spins it: the writer thread takes its messages (see the docstring).
        self._reader = Node(
            reader_name,
            namespace=node.get_namespace(),
            context=node.context,
            start_parameter_services=False,
            enable_rosout=False,
        )
        try:
            self._writer = Writer(path, version=BAG_VERSION, storage_plugin=STORAGES[storage])
            if compression_mode != "none":
                self._writer.set_compression(
                    COMPRESSION_MODES[compression_mode], CompressionFormat.ZSTD
                )
        except BaseException:
            self._reader.destroy_node()
            raise
        self._good_end = 0
        # The writer thread opens the bag itself: sqlite3 connections belong to one thread.
        self._opened = threading.Event()
        self._open_error: str | None = None
        self._thread = threading.Thread(target=self._write_loop, name="bag-writer", daemon=True)
        self._thread.start()
        self._opened.wait()
        if self._open_error:
            raise BagError(self._open_error)  # the writer thread has ended the reader

    # ------------------------------------------------------------ driving thread

    def poll(self) -> list[str]:
        """Subscribe to wanted topics that have appeared; returns lines worth showing once."""
        if self._failure or not self._accepting:
            return []
        lines = []
        graph = dict(self._node.get_topic_names_and_types())
        candidates = self._wanted or []
        if self._all:
            candidates = [
                t
                for t in sorted(graph)
                if (not is_internal_topic(t) or t in QUIET_TOPICS)
                and not set(graph[t]) <= self._skip_types
            ]
        for topic in candidates:
            if topic in self._subs or topic in self._skipped or topic not in graph:
                continue
            publishers = self._node.get_publishers_info_by_topic(topic)
            if not publishers:
                continue  # rosbag2 waits for a publisher: its QoS is what we store
            try:
                lines.append(self._subscribe(topic, graph[topic], publishers))
            except BagError as exc:
                self._skipped.add(topic)
                lines.append(f"[WARN] cannot record {topic}: {exc}")
            except InvalidHandle:  # a failed write ended the recording (and its node) meanwhile
                break
        return lines

    def missing_topics(self) -> list[str]:
        """Requested topics not recorded (yet): nobody publishes them."""
        subscribed = {topic for topic, _type in self._topics}
        return [t for t in self._wanted if t not in subscribed and t not in self._skipped]

    def _subscribe(self, topic: str, types: list[str], publishers: list[TopicEndpointInfo]) -> str:
        msgtype = types[0]
        try:
            py_type = import_type(msgtype, "msg")
        except ConversionError as exc:
            raise BagError(f"its type {msgtype} is not installed here") from exc
        msgdef, rihs01 = definition(msgtype)
        offered = [bag_qos.to_bag(p.qos_profile) for p in publishers]
        key = len(self._topics)
        self._topics.append((topic, msgtype))
        with self._lock:
            self._counts.append(0)
            self._sizes.append(0)
        subscription = self._reader.create_subscription(
            py_type,
            topic,
            _never_called,
            matching_qos(self._node, topic, depth=SUBSCRIPTION_DEPTH),
            raw=True,
        )
        self._subs[topic] = subscription
        self._queue.put(
            _NewTopic(key, topic, msgtype, msgdef, rihs01, offered, subscription, py_type)
        )
        return f"{SUBSCRIBED} '{topic}'"

    def status(self) -> RecordingStatus:
        with self._lock:
            counts, sizes = list(self._counts), list(self._sizes)
            failure, flushed, finished = self._failure, self._flushed, self._finished
        topics = tuple(
            TopicCount(t, m, c, s)
            for (t, m), c, s in zip(self._topics, counts, sizes, strict=False)
        )
        size = sum(p.stat().st_size for p in self.path.glob("*") if p.is_file())
        return RecordingStatus(
            self.path,
            topics,
            time.monotonic() - self._started,
            size,
            flushed,
            failure,
            finished,
        )

    @property
    def failed(self) -> str | None:
        with self._lock:
            return self._failure

    def set_custom_data(self, key: str, value: str) -> None:
        """A key and value for ``metadata.yaml``'s ``custom_data`` (before ``stop``)."""
        self._writer.set_custom_data(key, value)

    def stop(self, timeout: float = 30.0) -> RecordingStatus:
        """End the recording: the writer takes what has arrived, closes the bag and ends
        the recording's node."""
        self._accepting = False
        self._queue.put(None)
        self._stopping.set()  # no pause: the writer takes what is there and closes now
        self._thread.join(timeout)
        if self._thread.is_alive():
            with self._lock:
                self._failure = self._failure or (
                    f"the writer was still busy after {timeout:g} s; the bag {self.path} "
                    "will be closed when it is done"
                )
        return self.status()

    # ------------------------------------------------------------ writer thread

    def _open(self) -> bool:
        try:
            self._writer.open()
            # The MCAP header goes to the kernel now, not with the first flush a
            # second later: a recording killed in its first second was a 0-byte
            # file that `ros2 bag info` called damaged and `reindex` could not
            # mend (found by tests/faults/test_kill_restart.py).
            storage = self._writer.storage
            if isinstance(storage, McapWriter):
                storage.bio.flush()
            self._good_end = self._storage_end()
        except WriterError:
            self._open_error = f"cannot record into {self.path}: it already exists"
        except (OSError, sqlite3.Error) as exc:
            reason = getattr(exc, "strerror", None) or str(exc)
            self._open_error = f"cannot record into {self.path}: {reason}"
        finally:
            self._opened.set()
        return self._open_error is None

    def _write_loop(self) -> None:
        try:
            if self._open():
                self._write_until_stopped()
        finally:
            self._end_reader()
            with self._lock:
                self._finished = True

    def _write_until_stopped(self) -> None:
        connections: dict[int, Connection] = {}
        taking: list[_NewTopic] = []  # each topic's subscription, once its connection exists
        next_flush = time.monotonic() + self._flush_interval
        try:
            pause = BATCH_PAUSE_SEC
            while True:
                # Let messages gather for a moment and take them in one go.
                self._stopping.wait(pause)
                news: list[_Item] = []
                while True:
                    try:
                        news.append(self._queue.get_nowait())
                    except queue.Empty:
                        break
                stopping = None in news
                self._add_topics(news, connections, taking)
                batch = self._take(taking)
                self._write_batch(_in_time_order(batch), connections)
                pause = BATCH_PAUSE_SEC if batch or news else IDLE_PAUSE_SEC
                if stopping:
                    self._writer.close()
                    with contextlib.suppress(OSError, KeyError, TypeError, yaml.YAMLError):
                        stamp_distro(self.path)  # a bag without it is still a good bag
                    with self._lock:
                        self._flushed = sum(self._counts)
                    return
                if time.monotonic() >= next_flush:
                    self._flush()
                    next_flush = time.monotonic() + self._flush_interval
        except WRITE_ERRORS as exc:
            self._fail(exc)

    def _add_topics(
        self, news: list[_Item], connections: dict[int, Connection], taking: list[_NewTopic]
    ) -> None:
        for item in news:
            if isinstance(item, _NewTopic):
                connections[item.key] = self._writer.add_connection(
                    item.topic,
                    item.msgtype,
                    msgdef=item.msgdef,
                    rihs01=item.rihs01,
                    offered_qos_profiles=item.offered,
                )
                taking.append(item)

    @staticmethod
    def _take(taking: list[_NewTopic]) -> list[_Message]:
        """Everything that waits on the subscriptions."""
        batch: list[_Message] = []
        for topic in taking:
            handle = topic.subscription.handle
            for _ in range(TAKE_MAX):
                with handle:
                    taken = handle.take_message(topic.py_type, True)
                if taken is None:
                    break
                data, info = taken
                batch.append((topic.key, info.get("received_timestamp") or time.time_ns(), data))
        return batch

    def _end_reader(self) -> None:
        """The recording's node and its subscriptions go with the writer thread that took
        from them (no other thread touches them after the constructor and ``poll``)."""
        with contextlib.suppress(InvalidHandle):
            self._reader.destroy_node()

    def _write_batch(self, batch: list[_Message], connections: dict[int, Connection]) -> None:
        """Write the messages taken."""
        counts: dict[int, int] = {}
        sizes: dict[int, int] = {}
        try:
            for key, stamp, data in batch:
                self._writer.write(connections[key], stamp, data)
                counts[key] = counts.get(key, 0) + 1
                sizes[key] = sizes.get(key, 0) + len(data)
        finally:
            with self._lock:
                for key, n in counts.items():
                    self._counts[key] += n
                    self._sizes[key] += sizes[key]

    def _flush(self) -> None:
        """Hand everything written so far to the kernel, as complete chunks/transactions."""
        storage = self._writer.storage
        if isinstance(storage, McapWriter):
            if storage.chunk.bio.tell():
                storage.close_chunk()
            storage.bio.flush()
        elif isinstance(storage, Sqlite3Writer):
            storage.conn.commit()
        self._good_end = self._storage_end()
        with self._lock:
            self._flushed = sum(self._counts)

    def _storage_end(self) -> int:
        storage = self._writer.storage
        return storage.bio.tell() if isinstance(storage, McapWriter) else 0

    def _fail(self, exc: BaseException) -> None:
        """Stop at the first failed write; keep what was flushed, as a readable bag."""
        self._accepting = False
        reason = getattr(exc, "strerror", None) or str(exc).strip() or type(exc).__name__
        kept = self._flushed
        storage = self._writer.storage
        with contextlib.suppress(*WRITE_ERRORS):
            self._writer.abort()
        try:
            if isinstance(storage, McapWriter):
                truncate_storage(storage.path, self._good_end)
            reindex(self.path)
            note = f"the bag keeps the {kept} messages flushed before it"
        except (BagError, OSError) as repair_exc:
            note = f"the bag could not be closed ({repair_exc}); try `ros2 bag reindex {self.path}`"
        with self._lock:
            self._failure = f"recording stopped: {reason} while writing {self.path}; {note}"

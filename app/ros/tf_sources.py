"""The dashboard's one reader of /tf and /tf_static: who publishes each frame, how often,
how long ago, and a tf2 Buffer fed from the same data.

The TF tool, the 3D view's TF layer and the stage's TF tree read it
(``shared(node)``): /tf is taken and decoded once per dashboard, whichever
of them are open. It is also the home of how every /tf reader of ours
subscribes (``TF_QOS``, ``STATIC_QOS``) and when a frame counts as stale.

The TF tool needs, per frame, the node that broadcasts it. A /tf message
names frames, never its sender; the middleware knows the sender (each
received sample carries its writer's GID, ``rmw_message_info_t.publisher_gid``)
and the graph maps every writer's GID to its node
(``get_publishers_info_by_topic``). rclpy's take drops the GID, so the
panel takes its samples itself: two raw subscriptions on a hidden node that
no executor spins, read by one thread of ours through rcl's
``rcl_take_serialized_message`` (ctypes on the librcl rclpy has loaded).
Where that is impossible (another rmw, a changed ABI) it falls back to
rclpy's own take and names a publisher only when one node publishes the
topic: an honest "one of ..." otherwise.

Every transform also goes into a real ``tf2_ros.Buffer`` with its
publisher's name as the authority, so the panel's tf2_echo readout is a
tf2 lookup. The 3D view's TF layer gets the same transforms from here
(``shared(node)`` and ``on_transforms``): /tf is taken and read once per
dashboard. Threads: this module's thread writes and calls the
``on_transforms`` sinks; the UI thread reads copies (``frames()``) and calls
the buffer (which has its own lock).
"""

from __future__ import annotations

import ctypes
import logging
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.serialization import deserialize_message
from rclpy.subscription import Subscription
from tf2_msgs.msg import TFMessage
from tf2_ros._wire import Entry, decode_tf_message
from tf2_ros.buffer import Buffer

from app.ros.names import node_fqn

if TYPE_CHECKING:
    from geometry_msgs.msg import TransformStamped

log = logging.getLogger(__name__)

TAPS_NODE = "_classroom_tf_panel"  # hidden, as `ros2 node list` hides '_' names
POLL_SEC = 0.02  # take what arrived 50 times a second...
IDLE_POLL_SEC = 0.25  # ...or 4 times while nothing has come for IDLE_AFTER_SEC
IDLE_AFTER_SEC = 2.0
MAX_TAKES = 400  # per topic and poll: a flood cannot starve the rest of the loop
GRAPH_EVERY_SEC = 1.0  # re-read which GID belongs to which node...
GRAPH_SOON_SEC = 0.25  # ...sooner when a sample came from a GID not known yet
CONFLICT_SEC = 5.0  # a second parent seen this recently is still news
RATE_WINDOW = 20  # arrivals a frame's rate is measured over...
RATE_MIN_ARRIVALS = 5  # ...and the fewest that give one: from 2 or 3, one late sample skews it
RCL_RET_OK = 0
RCL_RET_SUBSCRIPTION_TAKE_FAILED = 401  # nothing to take
STALE_MIN_SEC = 1.0  # a dynamic frame is stale after this long without news...
STALE_PERIODS = 5.0  # ...or after this many of its own periods, if that is longer


def is_stale(static: bool, rate: float | None, received: float, now: float) -> bool:
    """A dynamic frame silent longer than its rate allows (static frames never are)."""
    if static:
        return False
    limit = max(STALE_MIN_SEC, STALE_PERIODS / rate) if rate else STALE_MIN_SEC * 2
    return now - received > limit


# As tf2_ros.TransformListener subscribes (every /tf reader of ours does the same):
# /tf keeps 100, /tf_static is reliable and transient local, so a late joiner hears it.
TF_QOS = QoSProfile(depth=100, history=HistoryPolicy.KEEP_LAST)
STATIC_QOS = QoSProfile(
    depth=100,
    history=HistoryPolicy.KEEP_LAST,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
    reliability=ReliabilityPolicy.RELIABLE,
)


# --- rcl through ctypes: the sample and its writer's GID ------------------------------------
class _Allocator(ctypes.Structure):  # rcutils_allocator_t
    _fields_ = [
        ("allocate", ctypes.c_void_p),
        ("deallocate", ctypes.c_void_p),
        ("reallocate", ctypes.c_void_p),
        ("zero_allocate", ctypes.c_void_p),
        ("state", ctypes.c_void_p),
    ]


class _Bytes(ctypes.Structure):  # rcutils_uint8_array_t == rmw_serialized_message_t
    _fields_ = [
        ("buffer", ctypes.POINTER(ctypes.c_uint8)),
        ("buffer_length", ctypes.c_size_t),
        ("buffer_capacity", ctypes.c_size_t),
        ("allocator", _Allocator),
    ]


class _Gid(ctypes.Structure):  # rmw_gid_t (RMW_GID_STORAGE_SIZE is 16 in Jazzy)
    _fields_ = [("implementation_identifier", ctypes.c_char_p), ("data", ctypes.c_uint8 * 16)]


class _MessageInfo(ctypes.Structure):  # rmw_message_info_t
    _fields_ = [
        ("source_timestamp", ctypes.c_int64),
        ("received_timestamp", ctypes.c_int64),
        ("publication_sequence_number", ctypes.c_uint64),
        ("reception_sequence_number", ctypes.c_uint64),
        ("publisher_gid", _Gid),
        ("from_intra_process", ctypes.c_bool),
    ]


def _loaded_library(name: str) -> str:
    """The path of a shared library this process has loaded (rclpy loaded rcl)."""
    with open("/proc/self/maps", encoding="utf-8", errors="replace") as maps:
        for line in maps:
            path = line.rsplit(" ", 1)[-1].strip()
            if path.endswith("/" + name):
                return path
    raise OSError(f"{name} is not loaded")


def _entry(t: TransformStamped) -> Entry:
    """A TransformStamped as the fields tf2_ros._wire reads."""
    v, r, stamp = t.transform.translation, t.transform.rotation, t.header.stamp
    return (
        t.header.frame_id,
        t.child_frame_id,
        stamp.sec * 1_000_000_000 + stamp.nanosec,
        (v.x, v.y, v.z),
        (r.x, r.y, r.z, r.w),
    )


class RclTaker:
    """``take(subscription)`` -> (CDR bytes, writer GID) or None when nothing waits."""

    def __init__(self) -> None:
        rcl = ctypes.CDLL(_loaded_library("librcl.so"))
        rcutils = ctypes.CDLL(_loaded_library("librcutils.so"))
        rcutils.rcutils_get_default_allocator.restype = _Allocator
        rcutils.rcutils_uint8_array_init.argtypes = [
            ctypes.POINTER(_Bytes),
            ctypes.c_size_t,
            ctypes.POINTER(_Allocator),
        ]
        rcutils.rcutils_uint8_array_fini.argtypes = [ctypes.POINTER(_Bytes)]
        rcl.rcl_take_serialized_message.argtypes = [
            ctypes.c_void_p,
            ctypes.POINTER(_Bytes),
            ctypes.POINTER(_MessageInfo),
            ctypes.c_void_p,
        ]
        rcl.rcl_take_serialized_message.restype = ctypes.c_int32
        self._rcl, self._rcutils = rcl, rcutils
        self._allocator = rcutils.rcutils_get_default_allocator()
        self._bytes = _Bytes()
        self._info = _MessageInfo()
        if rcutils.rcutils_uint8_array_init(ctypes.byref(self._bytes), 4096, self._allocator):
            raise OSError("could not allocate a buffer for serialized messages")

    def take(self, subscription: Subscription) -> tuple[bytes, bytes] | None:
        with subscription.handle:  # the handle stays alive while rcl uses it
            ret = self._rcl.rcl_take_serialized_message(
                subscription.handle.pointer, ctypes.byref(self._bytes), self._info, None
            )
        if ret == RCL_RET_SUBSCRIPTION_TAKE_FAILED:
            return None
        if ret != RCL_RET_OK:
            raise OSError(f"rcl_take_serialized_message returned {ret}")
        data = ctypes.string_at(self._bytes.buffer, self._bytes.buffer_length)
        return data, bytes(self._info.publisher_gid.data)

    def close(self) -> None:
        self._rcutils.rcutils_uint8_array_fini(ctypes.byref(self._bytes))


class RclpyTaker:
    """The fallback: rclpy's take, which has no GID."""

    def take(self, subscription: Subscription) -> tuple[bytes, bytes] | None:
        with subscription.handle:
            got = subscription.handle.take_message(TFMessage, True)
        if got is None:
            return None
        return got[0], b""

    def close(self) -> None:
        pass


Sink = Callable[[list[Entry], bool], None]  # (transforms of one message, static)
_shared: dict[int, tuple[TfSources, int]] = {}  # id(node) -> (sources, users)
_shared_lock = threading.Lock()


def shared(node: Node) -> TfSources:
    """The one TfSources of ``node`` (made on first use); give it back with ``release``."""
    with _shared_lock:
        sources, users = _shared.get(id(node), (None, 0))
        if sources is None:
            sources = TfSources(node)
        _shared[id(node)] = (sources, users + 1)
        return sources


def release(sources: TfSources) -> None:
    """One user fewer; the last one closes it."""
    with _shared_lock:
        for key, (held, users) in list(_shared.items()):
            if held is sources:
                if users > 1:
                    _shared[key] = (held, users - 1)
                    return
                del _shared[key]
    sources.close()


# --- what the panel shows ---------------------------------------------------------------
@dataclass(frozen=True)
class FrameInfo:
    """One frame as the TF panel shows it (a copy: safe on any thread)."""

    frame: str
    parent: str  # "" for a root (a frame only ever named as a parent)
    static: bool = False
    publisher: str = ""  # "/node", "one of /a, /b", or "" (not known)
    publisher_here: bool = True  # that node is still on the graph
    rate: float | None = None  # Hz, from arrival times (None: too few yet)
    rate_samples: int = 0  # how many arrivals that rate is measured over
    age: float = 0.0  # seconds since its newest transform arrived
    stale: bool = False  # a dynamic frame silent for longer than its rate allows
    conflict: str = ""  # another parent seen lately, in words


@dataclass
class _Record:
    parent: str
    static: bool
    received: float
    gid: bytes
    arrivals: deque[float] = field(default_factory=lambda: deque(maxlen=RATE_WINDOW))
    others: dict[str, tuple[bytes, float]] = field(default_factory=dict)  # parent -> (gid, when)

    def rate(self) -> float | None:
        if len(self.arrivals) < RATE_MIN_ARRIVALS or self.arrivals[-1] <= self.arrivals[0]:
            return None
        return (len(self.arrivals) - 1) / (self.arrivals[-1] - self.arrivals[0])

    def stale(self, now: float) -> bool:
        return is_stale(self.static, self.rate(), self.received, now)


class TfSources:
    """Takes /tf and /tf_static with each sample's publisher; owns a tf2 Buffer fed from them."""

    def __init__(self, node: Node) -> None:
        self.buffer = Buffer()  # 10 s of history, as every tf2 listener keeps
        self._lock = threading.Lock()
        self._frames: dict[str, _Record] = {}
        self._names: dict[bytes, str] = {}  # writer GID -> node, remembered after it leaves
        self._present: set[bytes] = set()  # GIDs on the graph now
        self._topic_publishers: dict[str, list[str]] = {"/tf": [], "/tf_static": []}
        self.version = 0
        self._sinks: list[Sink] = []
        self._taps = Node(
            TAPS_NODE, context=node.context, start_parameter_services=False, enable_rosout=False
        )
        noop = lambda _msg: None  # noqa: E731  (never called: no executor spins this node)
        self._subscriptions = [
            (self._taps.create_subscription(TFMessage, "/tf", noop, TF_QOS, raw=True), False),
            (
                self._taps.create_subscription(TFMessage, "/tf_static", noop, STATIC_QOS, raw=True),
                True,
            ),
        ]
        try:
            self._taker: RclTaker | RclpyTaker = RclTaker()
            self.exact = True  # publishers come from each sample's GID
        except (OSError, AttributeError) as exc:
            log.warning("TF panel: no publisher GIDs (%s); naming publishers by topic", exc)
            self._taker = RclpyTaker()
            self.exact = False
        self._stop = threading.Event()
        self._graph_due = 0.0
        self._thread = threading.Thread(target=self._run, name="tf-sources", daemon=True)
        self._thread.start()

    # --- this module's thread ---
    def _run(self) -> None:
        last_data = 0.0
        while not self._stop.wait(
            POLL_SEC if time.monotonic() - last_data < IDLE_AFTER_SEC else IDLE_POLL_SEC
        ):
            now = time.monotonic()
            if now >= self._graph_due:
                self._read_graph()
                self._graph_due = now + GRAPH_EVERY_SEC
            for subscription, static in self._subscriptions:
                try:
                    if self._drain(subscription, static):
                        last_data = now
                except Exception:  # a bad sample or a closing context: keep the panel going
                    log.exception("TF panel: taking %s failed", subscription.topic_name)

    def _drain(self, subscription: Subscription, static: bool) -> bool:
        """Take and read what waits; whether anything did."""
        took = False
        for _ in range(MAX_TAKES):
            got = self._taker.take(subscription)
            if got is None:
                return took
            took = True
            data, gid = got
            entries = decode_tf_message(data)
            if entries is None:  # not the usual encoding: rclpy reads it
                entries = [_entry(t) for t in deserialize_message(data, TFMessage).transforms]
            self._ingest(entries, gid, static, time.monotonic())
            for sink in list(self._sinks):
                try:
                    sink(entries, static)
                except Exception:  # one consumer's bug stops no other
                    log.exception("TF sink failed")
        return took

    def on_transforms(self, sink: Sink) -> None:
        """Call ``sink(transforms, static)`` (on this module's thread) for every message."""
        self._sinks.append(sink)

    def remove_sink(self, sink: Sink) -> None:
        if sink in self._sinks:
            self._sinks.remove(sink)

    def _read_graph(self) -> None:
        present: set[bytes] = set()
        names: dict[bytes, str] = {}
        topics: dict[str, list[str]] = {}
        try:
            for topic in ("/tf", "/tf_static"):
                infos = self._taps.get_publishers_info_by_topic(topic)
                topics[topic] = sorted({node_fqn(e.node_name, e.node_namespace) for e in infos})
                for e in infos:
                    gid = bytes(e.endpoint_gid)
                    names[gid] = node_fqn(e.node_name, e.node_namespace)
                    present.add(gid)
        except Exception:  # the graph may be unreadable for a moment
            return
        with self._lock:
            self._names.update(names)
            self._present = present
            self._topic_publishers = topics
            self.version += 1

    def _ingest(self, entries: list[Entry], gid: bytes, static: bool, now: float) -> None:
        with self._lock:
            known = gid in self._names
            authority = self._names.get(gid, "")
        if self.exact and not known:
            self._graph_due = min(self._graph_due, now + GRAPH_SOON_SEC)
        who = authority or "unknown_publisher"
        for frame_id, child_frame_id, stamp, t, q in entries:
            if not self.buffer._set_fields(frame_id, child_frame_id, stamp, t, q, who, static):
                continue  # tf2 refused it (and said why in the log): the panel follows tf2
            parent, child = frame_id.lstrip("/"), child_frame_id.lstrip("/")
            with self._lock:
                record = self._frames.get(child)
                if record is None:
                    record = _Record(parent, static, now, gid)
                    self._frames[child] = record
                elif record.parent != parent:
                    record.others[record.parent] = (record.gid, now)
                    record.others.pop(parent, None)
                record.parent, record.static, record.received, record.gid = (
                    parent,
                    static,
                    now,
                    gid,
                )
                record.arrivals.append(now)
                self.version += 1
        self.buffer._call_new_data_callbacks()

    # --- any thread ---
    def frames(self, now: float | None = None) -> list[FrameInfo]:
        """Every frame (children and roots), sorted by name."""
        now = time.monotonic() if now is None else now
        with self._lock:
            rows = [self._info(child, r, now) for child, r in self._frames.items()]
            parents = {r.parent for r in self._frames.values()} - set(self._frames)
        rows += [FrameInfo(root, "") for root in parents]
        return sorted(rows, key=lambda row: row.frame)

    def _info(self, child: str, r: _Record, now: float) -> FrameInfo:
        publisher, here = self._publisher(r.gid, "/tf_static" if r.static else "/tf")
        conflicts = [
            f"also sent with parent `{parent}` by {self._publisher(gid, '/tf')[0] or 'someone'} "
            f"{now - when:.1f} s ago"
            for parent, (gid, when) in r.others.items()
            if now - when < CONFLICT_SEC
        ]
        return FrameInfo(
            child,
            r.parent,
            r.static,
            publisher,
            here,
            rate=r.rate(),
            rate_samples=len(r.arrivals),
            age=max(0.0, now - r.received),
            stale=r.stale(now),
            conflict="; ".join(conflicts),
        )

    def _publisher(self, gid: bytes, topic: str) -> tuple[str, bool]:
        """(who, still on the graph): by GID, else by elimination over the topic's publishers."""
        name = self._names.get(gid) if gid else None
        if name:
            return name, gid in self._present
        candidates = self._topic_publishers.get(topic, [])
        if self.exact or not candidates:
            return "", False
        if len(candidates) == 1:
            return candidates[0], True
        return "one of " + ", ".join(candidates), True

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2.0)
        for subscription, _static in self._subscriptions:
            self._taps.destroy_subscription(subscription)
        self._taker.close()
        self._taps.destroy_node()

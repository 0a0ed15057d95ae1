"""tf2's BufferCore: the frame tree over time, and lookups through it.

Frames are numbered as they appear (0 is "no parent"); each child frame owns
one cache of transforms to its parent. A lookup walks from the source frame up
to the root, then from the target frame up until it meets that path, composing
transforms on the way (tf2's walk, with its early outs and its error wording),
so ``lookup_transform(target, source)`` maps points in ``source`` into
``target``. Time 0 means "the latest time every frame on the path has".
"""

from __future__ import annotations

import math
import threading
from typing import Any

from builtin_interfaces.msg import Time
from geometry_msgs.msg import Quaternion, Transform, TransformStamped, Vector3
from std_msgs.msg import Header

from tf2_py import time_cache as tc
from tf2_py.exceptions import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TransformException,
)
from tf2_py.linear_math import IDENTITY_Q, ZERO_V, Quat, Vec, compose, invert, quat_norm2
from tf2_py.time_cache import CacheError, StaticCache, TimeCache, display_time

MAX_GRAPH_DEPTH = 1000
QUATERNION_NORMALIZATION_TOLERANCE = 10e-3
DEFAULT_CACHE_TIME_NS = 10_000_000_000

_RAISE = {
    tc.LOOKUP_ERROR: LookupException,
    tc.CONNECTIVITY_ERROR: ConnectivityException,
    tc.EXTRAPOLATION_ERROR: ExtrapolationException,
    tc.BACKWARD_EXTRAPOLATION_ERROR: ExtrapolationException,
    tc.FORWARD_EXTRAPOLATION_ERROR: ExtrapolationException,
    tc.NO_DATA_FOR_EXTRAPOLATION_ERROR: ExtrapolationException,
}


def to_nanoseconds(value: Any) -> int:
    """An rclpy Time/Duration, a builtin_interfaces Time/Duration, or int nanoseconds."""
    if isinstance(value, int):
        return value
    ns = getattr(value, "nanoseconds", None)
    if isinstance(ns, int):
        return ns
    sec = getattr(value, "sec", None)
    nanosec = getattr(value, "nanosec", None)
    if isinstance(sec, int) and isinstance(nanosec, int):
        return sec * 1_000_000_000 + nanosec
    raise TypeError("time must have sec and nanosec, or nanoseconds.")


def _log(level: str, text: str) -> None:
    """tf2 logs through rcutils; rclpy's logging prints the same way without rclpy.init."""
    try:
        from rclpy.logging import get_logger

        getattr(get_logger("tf2_buffer"), level)(text)
    except Exception:
        print(f"[{level.upper()}] [tf2_buffer]: {text}", flush=True)


class _Walk:
    """The state of one walk: the accumulated source->top and target->top transforms."""

    __slots__ = ("src_q", "src_t", "tgt_q", "tgt_t", "q", "t")

    def __init__(self) -> None:
        self.src_q: Quat = IDENTITY_Q
        self.src_t: Vec = ZERO_V
        self.tgt_q: Quat = IDENTITY_Q
        self.tgt_t: Vec = ZERO_V
        self.q: Quat = IDENTITY_Q
        self.t: Vec = ZERO_V


class BufferCore:
    """The transform tree with a time cache per frame (``cache_time``: 10 s by default)."""

    def __init__(self, cache_time: Any = None) -> None:
        self._cache_ns = DEFAULT_CACHE_TIME_NS if cache_time is None else to_nanoseconds(cache_time)
        self._lock = threading.RLock()
        self._ids: dict[str, int] = {"NO_PARENT": 0}
        self._names: list[str] = ["NO_PARENT"]
        self._frames: list[TimeCache | StaticCache | None] = [None]
        self._parents: list[int] = [0]  # each frame's newest parent (0: none), for _shortcut
        self._authority: dict[int, str] = {}
        self._parent_warned: set[tuple[int, int]] = set()
        self.last_problem = ""  # the newest warning or error logged (not upstream's API)

    def _say(self, level: str, text: str) -> None:
        """Log as tf2 does; keep the newest warning or error for tools that show it."""
        self.last_problem = text
        _log(level, text)

    # -- input -----------------------------------------------------------------
    def set_transform(self, transform: TransformStamped, authority: str) -> bool:
        return self._set(transform, authority, False)

    def set_transform_static(self, transform: TransformStamped, authority: str) -> bool:
        return self._set(transform, authority, True)

    def _set(self, msg: TransformStamped, authority: str, is_static: bool) -> bool:
        tr, ro = msg.transform.translation, msg.transform.rotation
        return self._set_fields(
            msg.header.frame_id,
            msg.child_frame_id,
            msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec,
            (tr.x, tr.y, tr.z),
            (ro.x, ro.y, ro.z, ro.w),
            authority,
            is_static,
        )

    def _set_fields(
        self,
        frame_id: str,
        child: str,
        stamp: int,
        t: Vec,
        q: Quat,
        authority: str,
        is_static: bool,
    ) -> bool:
        """tf2's setTransform on the fields of one TransformStamped (stamp in ns)."""
        frame_id = frame_id[1:] if frame_id.startswith("/") else frame_id
        child = child[1:] if child.startswith("/") else child
        ok = True
        if child == frame_id:
            self._say(
                "error",
                f'TF_SELF_TRANSFORM: Ignoring transform from authority "{authority}" with '
                f'frame_id and  child_frame_id "{child}" because they are the same',
            )
            ok = False
        if not child:
            self._say(
                "error",
                f'TF_NO_CHILD_FRAME_ID: Ignoring transform from authority "{authority}" '
                "because child_frame_id not set ",
            )
            ok = False
        if not frame_id:
            self._say(
                "error",
                f'TF_NO_FRAME_ID: Ignoring transform with child_frame_id "{child}"  from '
                f'authority "{authority}" because frame_id not set',
            )
            ok = False
        total = t[0] + t[1] + t[2] + q[0] + q[1] + q[2] + q[3]
        if total != total and any(math.isnan(v) for v in (*t, *q)):  # cheap test first
            self._say(
                "error",
                f'TF_NAN_INPUT: Ignoring transform for child_frame_id "{child}" from authority '
                f'"{authority}" because of a nan value in the transform '
                f"({t[0]:f} {t[1]:f} {t[2]:f}) ({q[0]:f} {q[1]:f} {q[2]:f} {q[3]:f})",
            )
            ok = False
        elif abs(quat_norm2(q) - 1.0) >= QUATERNION_NORMALIZATION_TOLERANCE:
            self._say(
                "error",
                f'TF_DENORMALIZED_QUATERNION: Ignoring transform for child_frame_id "{child}" '
                f'from authority "{authority}" because of an invalid quaternion in the '
                f"transform ({q[0]:f} {q[1]:f} {q[2]:f} {q[3]:f})",
            )
            ok = False
        if not ok:
            return False
        with self._lock:
            child_id = self._number_or_insert(child)
            parent_id = self._number_or_insert(frame_id)
            cache = self._frames[child_id]
            if cache is None or isinstance(cache, StaticCache) != is_static:
                cache = StaticCache() if is_static else TimeCache(self._cache_ns)
                self._frames[child_id] = cache
            else:
                self._warn_new_parent(cache, child_id, parent_id, authority)
            if not cache.insert(stamp, (parent_id, q, t)):
                self._say(
                    "warning",
                    f"TF_OLD_DATA ignoring data from the past for frame {child} at time "
                    f"{display_time(stamp)} according to authority {authority}\n"
                    "Possible reasons are listed at http://wiki.ros.org/tf/Errors%20explained",
                )
                return False
            self._authority[child_id] = authority
            self._parents[child_id] = cache.latest_time_and_parent()[1]
        return True

    def _warn_new_parent(
        self, cache: TimeCache | StaticCache, child_id: int, parent_id: int, authority: str
    ) -> None:
        """A frame has one parent: say so (once per pair) when another parent arrives."""
        _stamp, old = cache.latest_time_and_parent()
        if old in (0, parent_id) or (child_id, parent_id) in self._parent_warned:
            return
        self._parent_warned.add((child_id, parent_id))
        self._say(
            "warning",
            f'TF_PARENT_CHANGED: frame "{self._names[child_id]}" had parent '
            f'"{self._names[old]}" and now gets parent "{self._names[parent_id]}" from '
            f'authority "{authority}"; a frame has exactly one parent at a time, so two '
            "broadcasters disagree about the tree (the newest data wins)",
        )

    def clear(self) -> None:
        """Forget every dynamic transform (static frames stay, as in tf2)."""
        with self._lock:
            for cache in self._frames:
                if cache is not None:
                    cache.clear()

    # -- frame numbers -----------------------------------------------------------
    def _number_or_insert(self, name: str) -> int:
        number = self._ids.get(name)
        if number is None:
            number = len(self._names)
            self._ids[name] = number
            self._names.append(name)
            self._frames.append(None)
            self._parents.append(0)
        return number

    def _validate(self, function: str, frame_id: str) -> int:
        if not frame_id:
            raise InvalidArgumentException(
                f'Invalid argument "{frame_id}" passed to {function} - '
                "in tf2 frame_ids cannot be empty"
            )
        if frame_id.startswith("/"):
            raise InvalidArgumentException(
                f'Invalid argument "{frame_id}" passed to {function} - '
                "in tf2 frame_ids cannot start with a '/'"
            )
        number = self._ids.get(frame_id, 0)
        if number == 0:
            raise LookupException(f'"{frame_id}" passed to {function} does not exist. ')
        return number

    def _validate_quietly(self, function: str, frame_id: str) -> tuple[int, str]:
        if not frame_id:
            why = "in tf2 frame_ids cannot be empty"
        elif frame_id.startswith("/"):
            why = "in tf2 frame_ids cannot start with a '/'"
        else:
            number = self._ids.get(frame_id, 0)
            if number:
                return number, ""
            why = "frame does not exist"
        return 0, f'Invalid frame ID "{frame_id}" passed to {function} - {why}'

    # -- the walk ----------------------------------------------------------------
    def _connectivity_error(self, source: int, target: int) -> str:
        return (
            f"Could not find a connection between '{self._names[target]}' and "
            f"'{self._names[source]}' because they are not part of the same tree."
            "Tf has two or more unconnected trees."
        )

    def _loop_error(self) -> str:
        return f"The tf tree is invalid because it contains a loop.\n{self._all_frames()}\n"

    def _latest_common_time(self, target: int, source: int) -> tuple[int, int, str]:
        """(error code, time, message): the newest time every frame between them has."""
        frames = self._frames
        if source == target:
            cache = frames[source]
            return tc.NO_ERROR, (cache.latest_stamp() if cache else 0), ""
        big = 1 << 62
        chain: list[tuple[int, int]] = []
        frame, depth, common = source, 0, big
        while frame != 0:
            cache = frames[frame]
            if cache is None:
                break
            stamp, parent = cache.latest_time_and_parent()
            if parent == 0:
                break
            if stamp != 0:
                common = min(common, stamp)
            chain.append((stamp, parent))
            frame = parent
            if frame == target:
                return tc.NO_ERROR, (0 if common == big else common), ""
            depth += 1
            if depth > MAX_GRAPH_DEPTH:
                return tc.LOOKUP_ERROR, 0, self._loop_error()
        frame, depth, common = target, 0, big
        common_parent = 0
        chain_parents = [p for _s, p in chain]
        while True:
            cache = frames[frame]
            if cache is None:
                break
            stamp, parent = cache.latest_time_and_parent()
            if parent == 0:
                break
            if stamp != 0:
                common = min(common, stamp)
            if parent in chain_parents:
                common_parent = parent
                break
            frame = parent
            if frame == source:
                return tc.NO_ERROR, (0 if common == big else common), ""
            depth += 1
            if depth > MAX_GRAPH_DEPTH:
                return tc.LOOKUP_ERROR, 0, self._loop_error()
        if common_parent == 0:
            return tc.CONNECTIVITY_ERROR, 0, self._connectivity_error(source, target)
        for stamp, parent in chain:
            if stamp != 0:
                common = min(common, stamp)
            if parent == common_parent:
                break
        return tc.NO_ERROR, (0 if common == big else common), ""

    def _walk(
        self, time_ns: int, target: int, source: int, accumulate: bool
    ) -> tuple[int, int, str, _Walk | None]:
        """tf2's walkToTopParent: (error code, time used, message, accumulated result)."""
        acc = _Walk() if accumulate else None
        if source == target:
            return tc.NO_ERROR, time_ns, "", acc
        if time_ns == 0:
            code, time_ns, message = self._latest_common_time(target, source)
            if code != tc.NO_ERROR:
                return code, time_ns, message, None
        frames = self._frames
        frame = top = source
        depth = 0
        extrapolation: CacheError | None = None
        while frame != 0:
            cache = frames[frame]
            if cache is None:
                top = frame
                break
            data = cache.get_data(time_ns) if accumulate else cache.get_parent(time_ns)
            if isinstance(data, CacheError) or data == 0:
                top = frame
                extrapolation = (
                    data
                    if isinstance(data, CacheError)
                    else CacheError(tc.NO_DATA_FOR_EXTRAPOLATION_ERROR, "")
                )
                break
            if frame == target:
                if acc is not None:
                    acc.q, acc.t = acc.src_q, acc.src_t
                return tc.NO_ERROR, time_ns, "", acc
            if isinstance(data, tuple):
                parent = data[0]
                if acc is not None:
                    acc.src_q, acc.src_t = compose(data[1], data[2], acc.src_q, acc.src_t)
            else:
                parent = data
            top = frame
            frame = parent
            depth += 1
            if depth > MAX_GRAPH_DEPTH:
                return tc.LOOKUP_ERROR, time_ns, self._loop_error(), None
        frame = target
        depth = 0
        while frame != top:
            cache = frames[frame]
            if cache is None:
                break
            data = cache.get_data(time_ns) if accumulate else cache.get_parent(time_ns)
            if isinstance(data, CacheError) or data == 0:
                error = (
                    data
                    if isinstance(data, CacheError)
                    else CacheError(tc.NO_DATA_FOR_EXTRAPOLATION_ERROR, "")
                )
                message = (
                    f"{error.message}, when looking up transform from frame "
                    f"[{self._names[source]}] to frame [{self._names[target]}]"
                )
                return error.code, time_ns, message, None
            if frame == source:
                if acc is not None:
                    acc.q, acc.t = invert(acc.tgt_q, acc.tgt_t)
                return tc.NO_ERROR, time_ns, "", acc
            if isinstance(data, tuple):
                parent = data[0]
                if acc is not None:
                    acc.tgt_q, acc.tgt_t = compose(data[1], data[2], acc.tgt_q, acc.tgt_t)
            else:
                parent = data
            frame = parent
            depth += 1
            if depth > MAX_GRAPH_DEPTH:
                return tc.LOOKUP_ERROR, time_ns, self._loop_error(), None
        if frame != top:
            if extrapolation is not None:
                message = (
                    f"{extrapolation.message}, when looking up transform from frame "
                    f"[{self._names[source]}] to frame [{self._names[target]}]"
                )
                return extrapolation.code, time_ns, message, None
            return (
                tc.CONNECTIVITY_ERROR,
                time_ns,
                self._connectivity_error(source, target),
                None,
            )
        if acc is not None:
            inv_q, inv_t = invert(acc.tgt_q, acc.tgt_t)
            acc.q, acc.t = compose(inv_q, inv_t, acc.src_q, acc.src_t)
        return tc.NO_ERROR, time_ns, "", acc

    def _shortcut(self, time_ns: int, target: int, source: int) -> tuple[Quat, Vec, int] | None:
        """A successful walk's result, composing only the links below the common ancestor.

        tf2's walk composes both paths all the way up to the root, where the
        links above the frames' common ancestor cancel out. Here the tree's
        shape is taken from each frame's newest parent (a list lookup), the
        common ancestor found on it, and only the links below it are
        interpolated and composed, each checked to have that parent at
        ``time_ns``: the same transform for fewer operations. Whenever the
        walk would not succeed that way (a missing link, another parent at
        that time, no common ancestor, a loop) this returns None and tf2's own
        walk runs, with its error and its message.
        """
        if time_ns == 0:
            code, time_ns, _message = self._latest_common_time(target, source)
            if code != tc.NO_ERROR:
                return None
        parents = self._parents
        up: dict[int, int] = {}  # source and its ancestors (by newest parent)
        frame = source
        while frame and frame not in up:
            up[frame] = parents[frame]
            frame = parents[frame]
        if frame:
            return None  # a loop: tf2's walk says so
        down: list[int] = []  # target and its ancestors below the common one
        frame = target
        while frame not in up:
            if not frame or frame in down:
                return None
            down.append(frame)
            frame = parents[frame]
        common = frame
        frames = self._frames
        q: Quat = IDENTITY_Q
        t: Vec = ZERO_V
        first = True
        for frame, parent in up.items():
            if frame == common:
                break
            data = frames[frame].get_data(time_ns)  # type: ignore[union-attr]
            if isinstance(data, CacheError) or data[0] != parent:
                return None
            if first:
                q, t, first = data[1], data[2], False
            else:
                q, t = compose(data[1], data[2], q, t)
        if down:
            tq: Quat = IDENTITY_Q
            tt: Vec = ZERO_V
            for k, frame in enumerate(down):
                data = frames[frame].get_data(time_ns)  # type: ignore[union-attr]
                if isinstance(data, CacheError) or data[0] != parents[frame]:
                    return None
                tq, tt = (data[1], data[2]) if k == 0 else compose(data[1], data[2], tq, tt)
            inv_q, inv_t = invert(tq, tt)
            q, t = (inv_q, inv_t) if first else compose(inv_q, inv_t, q, t)
        return q, t, time_ns

    # -- lookups -------------------------------------------------------------------
    def _lookup(self, target_frame: str, source_frame: str, time_ns: int) -> tuple[Quat, Vec, int]:
        with self._lock:
            if target_frame == source_frame:
                if time_ns == 0:
                    number = self._ids.get(target_frame, 0)
                    cache = self._frames[number] if number else None
                    time_ns = cache.latest_stamp() if cache is not None else 0
                return IDENTITY_Q, ZERO_V, time_ns
            target = self._validate("lookupTransform argument target_frame", target_frame)
            source = self._validate("lookupTransform argument source_frame", source_frame)
            found = self._shortcut(time_ns, target, source)
            if found is not None:
                return found
            code, used, message, acc = self._walk(time_ns, target, source, True)
        if code != tc.NO_ERROR or acc is None:
            raise _RAISE.get(code, TransformException)(message)
        return acc.q, acc.t, used

    def lookup_transform_core(
        self, target_frame: str, source_frame: str, time: Any
    ) -> TransformStamped:
        """The transform that maps data in ``source_frame`` into ``target_frame``."""
        q, t, used = self._lookup(target_frame, source_frame, to_nanoseconds(time))
        return _message(target_frame, source_frame, q, t, used)

    def lookup_transform_full_core(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
    ) -> TransformStamped:
        """Source at ``source_time`` into target at ``target_time``, through a fixed frame."""
        with self._lock:
            self._validate("lookupTransform argument target_frame", target_frame)
            self._validate("lookupTransform argument source_frame", source_frame)
            self._validate("lookupTransform argument fixed_frame", fixed_frame)
        q1, t1, _used = self._lookup(fixed_frame, source_frame, to_nanoseconds(source_time))
        q2, t2, used = self._lookup(target_frame, fixed_frame, to_nanoseconds(target_time))
        q, t = compose(q2, t2, q1, t1)
        return _message(target_frame, source_frame, q, t, used)

    def _can(self, target_frame: str, source_frame: str, time_ns: int) -> tuple[bool, str]:
        if target_frame == source_frame:
            return True, ""
        with self._lock:
            target, msg = self._validate_quietly("canTransform argument target_frame", target_frame)
            if not target:
                return False, msg
            source, msg = self._validate_quietly("canTransform argument source_frame", source_frame)
            if not source:
                return False, msg
            code, _used, message, _acc = self._walk(time_ns, target, source, False)
        return code == tc.NO_ERROR, message

    def can_transform_core(
        self, target_frame: str, source_frame: str, time: Any
    ) -> tuple[bool, str]:
        """(possible, why not): never raises for a missing frame."""
        return self._can(target_frame, source_frame, to_nanoseconds(time))

    def can_transform_full_core(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
    ) -> tuple[bool, str]:
        with self._lock:
            for function, frame in (
                ("canTransform argument target_frame", target_frame),
                ("canTransform argument source_frame", source_frame),
                ("canTransform argument fixed_frame", fixed_frame),
            ):
                number, msg = self._validate_quietly(function, frame)
                if not number:
                    return False, msg
        ok, msg = self._can(target_frame, fixed_frame, to_nanoseconds(target_time))
        if not ok:
            return ok, msg
        return self._can(fixed_frame, source_frame, to_nanoseconds(source_time))

    def get_latest_common_time(self, target_frame: str, source_frame: str) -> Any:
        """The newest time at which the two frames can be joined (rclpy Time)."""
        from rclpy.time import Time as RosTime

        with self._lock:
            target = self._validate("get_latest_common_time", target_frame)
            source = self._validate("get_latest_common_time", source_frame)
            code, stamp, message = self._latest_common_time(target, source)
        if code != tc.NO_ERROR:
            raise TransformException(message)
        return RosTime(nanoseconds=stamp)

    def _chain(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
    ) -> list[str]:
        """Frame names from source up to and down to target (through fixed_frame)."""
        up = self._path_to_root(source_frame)
        down = self._path_to_root(target_frame)
        common = next((f for f in up if f in down), None)
        if common is None:
            return up + list(reversed(down))
        return up[: up.index(common) + 1] + list(reversed(down[: down.index(common)]))

    def _path_to_root(self, frame: str) -> list[str]:
        with self._lock:
            path = [frame]
            number = self._ids.get(frame, 0)
            while number and len(path) <= MAX_GRAPH_DEPTH:
                cache = self._frames[number]
                if cache is None:
                    break
                _stamp, parent = cache.latest_time_and_parent()
                if parent == 0:
                    break
                path.append(self._names[parent])
                number = parent
            return path

    # -- introspection -----------------------------------------------------------------
    def _frameExists(self, frame_id: str) -> bool:
        return frame_id in self._ids and frame_id != "NO_PARENT"

    def _getFrameStrings(self) -> list[str]:
        with self._lock:
            return [name for number, name in enumerate(self._names) if number]

    def _all_frames(self) -> str:
        lines = []
        for number in range(1, len(self._frames)):
            cache = self._frames[number]
            if cache is None:
                continue
            data = cache.get_data(0)
            parent = 0 if isinstance(data, CacheError) else data[0]
            lines.append(f"Frame {self._names[number]} exists with parent {self._names[parent]}.\n")
        return "".join(lines)

    def all_frames_as_string(self) -> str:
        """One line per frame: 'Frame X exists with parent Y.'"""
        with self._lock:
            return self._all_frames()

    def all_frames_as_yaml(self, time: Any = None) -> str:
        """tf2's YAML dump of the tree: parent, broadcaster, rate and ages per frame."""
        now = 0 if time is None else to_nanoseconds(time)
        out: list[str] = []
        with self._lock:
            if len(self._frames) == 1:
                out.append("[]")
            for number in range(1, len(self._frames)):
                cache = self._frames[number]
                if cache is None:
                    continue
                data = cache.get_data(0)
                if isinstance(data, CacheError):
                    continue
                latest, oldest = cache.latest_stamp(), cache.oldest_stamp()
                span = max(latest - oldest, 100_000)
                rate = len(cache) * 1e9 / span
                out.append(f"{self._names[number]}: \n")
                out.append(f"  parent: '{self._names[data[0]]}'\n")
                out.append(
                    f"  broadcaster: '{self._authority.get(number, 'no recorded authority')}'\n"
                )
                out.append(f"  rate: {rate:.3f}\n")
                out.append(f"  most_recent_transform: {display_time(latest)}\n")
                out.append(f"  oldest_transform: {display_time(oldest)}\n")
                if now:
                    out.append(f"  transform_delay: {(now - latest) / 1e9:.3f}\n")
                out.append(f"  buffer_length: {(latest - oldest) / 1e9:.3f}\n")
        return "".join(out)


def _message(target: str, source: str, q: Quat, t: Vec, stamp_ns: int) -> TransformStamped:
    """A TransformStamped built without the generated constructors' keyword handling.

    The generated ``__init__`` chain costs about 30 us per message here, more
    than the lookup itself; the values are known to be well typed, so the
    slots are filled directly (what the constructors end up doing).
    """
    stamp = _new(Time)
    stamp._sec, stamp._nanosec = divmod(stamp_ns, 1_000_000_000)
    header = _new(Header)
    header._stamp, header._frame_id = stamp, target
    translation = _new(Vector3)
    translation._x, translation._y, translation._z = t
    rotation = _new(Quaternion)
    rotation._x, rotation._y, rotation._z, rotation._w = q
    transform = _new(Transform)
    transform._translation, transform._rotation = translation, rotation
    msg = _new(TransformStamped)
    msg._header, msg._child_frame_id, msg._transform = header, source, transform
    return msg


def _new(cls: Any) -> Any:
    obj = cls.__new__(cls)
    obj._check_fields = False
    return obj

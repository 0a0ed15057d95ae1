"""tf2_ros.Buffer: the tf2 buffer with ROS time, waiting, futures and the tf2_frames service.

``lookup_transform(..., timeout=Duration(seconds=1.0))`` polls every 20 ms
until the transform can be made or the timeout passes, then raises tf2's
exception, as upstream's Python buffer does (so a single-threaded executor
must not be waiting on itself: the tutorials use a timer and time zero).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from time import sleep
from typing import Any

import rclpy
from geometry_msgs.msg import TransformStamped
from rclpy.clock import Clock, JumpThreshold, TimeJump
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.task import Future
from rclpy.time import Time
from tf2_msgs.srv import FrameGraph
from tf2_py import BufferCore

from tf2_ros._wire import Entry
from tf2_ros.buffer_interface import NO_TIMEOUT, BufferInterface


class Buffer(BufferCore, BufferInterface):
    """Known frames over the last ``cache_time``; with a node, also the ``tf2_frames`` service."""

    def __init__(self, cache_time: Duration | None = None, node: Node | None = None) -> None:
        BufferCore.__init__(self, cache_time)
        BufferInterface.__init__(self)
        self._new_data_callbacks: list[Callable[[], None]] = []
        self._callbacks_to_remove: list[Callable[[], None]] = []
        self._callbacks_lock = threading.RLock()
        if node is not None:
            self.srv = node.create_service(FrameGraph, "tf2_frames", self.__get_frames)
            self.clock = node.get_clock()
        else:
            self.clock = Clock()
        # Time going backwards (a bag looping, sim time reset) makes old data lie: drop it.
        threshold = JumpThreshold(
            min_forward=None, min_backward=Duration(seconds=-1), on_clock_change=True
        )
        try:
            self.jump_handle = self.clock.create_jump_callback(
                threshold, post_callback=self.time_jump_callback
            )
        except Exception:
            self.jump_handle = None  # type: ignore[assignment]

    def __get_frames(self, req: Any, res: Any) -> Any:
        return FrameGraph.Response(frame_yaml=self.all_frames_as_yaml())

    def time_jump_callback(self, time_jump: TimeJump) -> None:
        rclpy.logging.get_logger("tf2_buffer").warning(
            "Detected jump back in time. Clearing tf buffer."
        )
        self.clear()

    def set_transform(self, transform: TransformStamped, authority: str) -> bool:
        stored = super().set_transform(transform, authority)
        self._call_new_data_callbacks()
        return stored

    def set_transform_static(self, transform: TransformStamped, authority: str) -> bool:
        stored = super().set_transform_static(transform, authority)
        self._call_new_data_callbacks()
        return stored

    def _set_entries(self, entries: list[Entry], authority: str, is_static: bool) -> None:
        """Every transform of one message (decoded by ``_wire``), then the waiters once."""
        for frame_id, child, stamp, t, q in entries:
            self._set_fields(frame_id, child, stamp, t, q, authority, is_static)
        self._call_new_data_callbacks()

    def _call_new_data_callbacks(self) -> None:
        if not self._new_data_callbacks:
            return
        with self._callbacks_lock:
            for callback in list(self._new_data_callbacks):
                callback()
            for callback in self._callbacks_to_remove:
                if callback in self._new_data_callbacks:
                    self._new_data_callbacks.remove(callback)
            self._callbacks_to_remove.clear()

    def _remove_callback(self, callback: Callable[[], None]) -> None:
        with self._callbacks_lock:
            self._callbacks_to_remove.append(callback)

    # -- lookups ---------------------------------------------------------------
    def lookup_transform(
        self, target_frame: str, source_frame: str, time: Time, timeout: Duration = NO_TIMEOUT
    ) -> TransformStamped:
        """The transform from ``source_frame`` into ``target_frame`` (time 0: the latest)."""
        if timeout.nanoseconds:  # without a timeout the check would only repeat the walk
            self.can_transform(target_frame, source_frame, time, timeout)
        return self.lookup_transform_core(target_frame, source_frame, time)

    async def lookup_transform_async(
        self, target_frame: str, source_frame: str, time: Time
    ) -> TransformStamped:
        await self.wait_for_transform_async(target_frame, source_frame, time)
        return self.lookup_transform_core(target_frame, source_frame, time)

    def lookup_transform_full(
        self,
        target_frame: str,
        target_time: Time,
        source_frame: str,
        source_time: Time,
        fixed_frame: str,
        timeout: Duration = NO_TIMEOUT,
    ) -> TransformStamped:
        """Time travel: ``source_frame`` at ``source_time`` into ``target_frame`` at target_time."""
        if timeout.nanoseconds:
            self.can_transform_full(
                target_frame, target_time, source_frame, source_time, fixed_frame, timeout
            )
        return self.lookup_transform_full_core(
            target_frame, target_time, source_frame, source_time, fixed_frame
        )

    async def lookup_transform_full_async(
        self,
        target_frame: str,
        target_time: Time,
        source_frame: str,
        source_time: Time,
        fixed_frame: str,
    ) -> TransformStamped:
        await self.wait_for_transform_full_async(
            target_frame, target_time, source_frame, source_time, fixed_frame
        )
        return self.lookup_transform_full_core(
            target_frame, target_time, source_frame, source_time, fixed_frame
        )

    def _poll(self, check: Callable[[], tuple[bool, str]], timeout: Duration) -> tuple[bool, str]:
        if timeout != Duration():
            clock = Clock()
            start = clock.now()
            while clock.now() < start + timeout and not check()[0]:
                sleep(0.02)
        return check()

    def can_transform(
        self,
        target_frame: str,
        source_frame: str,
        time: Time,
        timeout: Duration = NO_TIMEOUT,
        return_debug_tuple: bool = False,
    ) -> Any:
        """Whether the lookup would succeed, waiting up to ``timeout`` for it."""
        result = self._poll(
            lambda: self.can_transform_core(target_frame, source_frame, time), timeout
        )
        return result if return_debug_tuple else result[0]

    def can_transform_full(
        self,
        target_frame: str,
        target_time: Time,
        source_frame: str,
        source_time: Time,
        fixed_frame: str,
        timeout: Duration = NO_TIMEOUT,
        return_debug_tuple: bool = False,
    ) -> Any:
        result = self._poll(
            lambda: self.can_transform_full_core(
                target_frame, target_time, source_frame, source_time, fixed_frame
            ),
            timeout,
        )
        return result if return_debug_tuple else result[0]

    def wait_for_transform_async(self, target_frame: str, source_frame: str, time: Time) -> Future:
        """A future that completes with the transform once it can be made."""
        return self._wait_async(
            lambda: self.can_transform_core(target_frame, source_frame, time)[0],
            lambda: self.lookup_transform(target_frame, source_frame, time),
        )

    def wait_for_transform_full_async(
        self,
        target_frame: str,
        target_time: Time,
        source_frame: str,
        source_time: Time,
        fixed_frame: str,
    ) -> Future:
        return self._wait_async(
            lambda: self.can_transform_full_core(
                target_frame, target_time, source_frame, source_time, fixed_frame
            )[0],
            lambda: self.lookup_transform_full(
                target_frame, target_time, source_frame, source_time, fixed_frame
            ),
        )

    def _wait_async(
        self, ready: Callable[[], bool], lookup: Callable[[], TransformStamped]
    ) -> Future:
        fut = Future()
        if ready():
            fut.set_result(lookup())
            return fut

        def on_new_data() -> None:
            try:
                if not fut.done() and ready():
                    fut.set_result(lookup())
            except BaseException as exc:
                fut.set_exception(exc)

        with self._callbacks_lock:
            self._new_data_callbacks.append(on_new_data)
        fut.add_done_callback(lambda _f: self._remove_callback(on_new_data))
        return fut

"""nodes.common.executors.SteadyMultiThreadedExecutor still behaves as rclpy's
MultiThreadedExecutor: callbacks of a reentrant group run side by side, and an
exception in a callback comes out of spin. (Its point, a spinning thread that
does not burn a core on queued callbacks, is shown by the tf2 time tutorial's
waiting listener in tests/tf2/test_tf2_time_tutorials.py.)"""

from __future__ import annotations

import threading

import pytest
import rclpy
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.context import Context

from nodes.common.executors import SteadyMultiThreadedExecutor
from tests.conftest import wait_until


@pytest.fixture
def context(ros_env):
    context = Context()
    rclpy.init(context=context)
    yield context
    context.try_shutdown()


def test_reentrant_callbacks_run_side_by_side(context):
    node = rclpy.create_node("steady_side_by_side", context=context)
    executor = SteadyMultiThreadedExecutor(num_threads=2, context=context)
    executor.add_node(node)
    group = ReentrantCallbackGroup()
    released = threading.Event()
    waited: list[bool] = []

    def blocker() -> None:  # waits for the other timer: only possible on two threads
        blocker_timer.cancel()
        waited.append(released.wait(5.0))

    def releaser() -> None:
        released.set()

    blocker_timer = node.create_timer(0.05, blocker, callback_group=group)
    node.create_timer(0.2, releaser, callback_group=group)
    thread = threading.Thread(target=executor.spin)
    thread.start()
    try:
        wait_until(lambda: waited, timeout=5.0, what="the blocking callback to end")
        assert waited == [True]  # released by the other callback while it waited
    finally:
        executor.shutdown()
        thread.join(5.0)
        node.destroy_node()
    assert not thread.is_alive()


def test_an_exception_in_a_callback_comes_out_of_spin(context):
    node = rclpy.create_node("steady_raises", context=context)
    executor = SteadyMultiThreadedExecutor(num_threads=2, context=context)
    executor.add_node(node)

    def boom() -> None:
        raise RuntimeError("from the callback")

    node.create_timer(0.05, boom)
    try:
        with pytest.raises(RuntimeError, match="from the callback"):
            for _ in range(200):
                executor.spin_once(timeout_sec=0.05)
    finally:
        executor.shutdown()
        node.destroy_node()

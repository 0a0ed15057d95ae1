"""An rclpy ``ActionClient`` that may send goals from one thread while another spins it.

rclpy 7.1 (Jazzy) sends a goal, cancel or result request first and files its
future under the request's sequence number after. When the executor spins in
another thread (the dashboard's runtime, a test's probe), the server's answer can
be taken in between: rclpy then logs "Ignoring unexpected goal response. There
may be more than one action server" and drops it, and the caller waits for an
answer that never comes (seen in CI: a Fibonacci goal unanswered for 30 s).
rclpy's service ``Client`` closes the same gap with a lock; this does the same
for actions, until rclpy's own ``ActionClient`` does.
"""

from __future__ import annotations

import threading
from typing import Any

from rclpy.action import ActionClient

# What ``execute`` takes under the lock: the answers filed by sequence number.
_ANSWERS = ("goal", "cancel", "result")


class ThreadSafeActionClient(ActionClient):
    """``ActionClient`` whose requests are filed before their answers are looked up.

    ``_rclpy`` is ``super()`` seen as untyped, as rclpy's ActionClient is.
    """

    @property
    def _rclpy(self) -> Any:
        return super()

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        # Re-entrant: a feedback or done callback run inside ``execute`` may send again.
        self._requests_lock = threading.RLock()
        self._rclpy.__init__(*args, **kwargs)

    def send_goal_async(self, *args: Any, **kwargs: Any) -> Any:
        with self._requests_lock:
            return self._rclpy.send_goal_async(*args, **kwargs)

    def _cancel_goal_async(self, goal_handle: Any) -> Any:
        with self._requests_lock:
            return self._rclpy._cancel_goal_async(goal_handle)

    def _get_result_async(self, goal_handle: Any) -> Any:
        with self._requests_lock:
            return self._rclpy._get_result_async(goal_handle)

    async def execute(self, taken_data: dict[str, Any]) -> None:
        answers = {key: taken_data.pop(key) for key in _ANSWERS if key in taken_data}
        if answers:
            # rclpy's handling of these three awaits nothing: the lock is never held
            # across a suspension.
            with self._requests_lock:
                await self._rclpy.execute(answers)
        if taken_data:  # feedback and status: their callbacks run outside the lock
            await self._rclpy.execute(taken_data)

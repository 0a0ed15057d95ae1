"""An action client whose requests are filed before their answers can be taken.

Not in upstream's nav2_util (a C++ library): here because two Python servers
(the navigator, the waypoint follower) send goals from one thread while their
executor takes the answers on another.
"""

from __future__ import annotations

import threading
from typing import Any

from rclpy.action import ActionClient
from rclpy.task import Future


class SerializedActionClient(ActionClient):
    """rclpy's ActionClient with its request bookkeeping under one lock.

    rclpy 7.1.6 sends a request and only then files its sequence number; an
    executor thread that takes the response in between finds nothing filed,
    logs "Ignoring unexpected goal response" and the request's future never
    completes (seen here: the navigator waited out its 10 s for a planner that
    had answered). Sending (from the navigation thread) and taking responses
    (in the executor) are serialized here.
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self._bookkeeping = threading.RLock()
        super().__init__(*args, **kwargs)

    def send_goal_async(self, *args: Any, **kwargs: Any) -> Future:
        with self._bookkeeping:
            return super().send_goal_async(*args, **kwargs)

    def _cancel_goal_async(self, goal_handle: Any) -> Future:
        with self._bookkeeping:
            return super()._cancel_goal_async(goal_handle)

    def _get_result_async(self, goal_handle: Any) -> Future:
        with self._bookkeeping:
            return super()._get_result_async(goal_handle)

    async def execute(self, taken_data: Any) -> None:
        # The parent's execute only awaits feedback callbacks, plain functions here: it runs
        # through without suspending, so the lock is never held across a suspension.
        with self._bookkeeping:
            await super().execute(taken_data)

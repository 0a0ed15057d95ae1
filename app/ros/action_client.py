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
from collections.abc import Callable
from typing import Any, Protocol, cast

from rclpy.action import ActionClient
from rclpy.action.client import ClientGoalHandle
from rclpy.node import Node
from rclpy.task import Future
from unique_identifier_msgs.msg import UUID

from app.ros.convert import RosType


class FeedbackMessage(Protocol):
    """An action's feedback as its client gets it: the goal it is for, and the feedback."""

    goal_id: UUID
    feedback: object


# What ``execute`` takes under the lock: the answers filed by sequence number.
_ANSWERS = ("goal", "cancel", "result")


class ThreadSafeActionClient(ActionClient):
    """``ActionClient`` whose requests are filed before their answers are looked up.

    ``_rclpy`` is ``super()`` seen as untyped, as rclpy's ActionClient is.
    """

    @property
    def _rclpy(self) -> Any:
        return super()

    def __init__(
        self, node: Node, action_type: RosType, action_name: str, **kwargs: object
    ) -> None:
        # Re-entrant: a feedback or done callback run inside ``execute`` may send again.
        self._requests_lock = threading.RLock()
        self._rclpy.__init__(node, action_type, action_name, **kwargs)

    def send_goal_async(
        self,
        goal: object,
        feedback_callback: Callable[[FeedbackMessage], None] | None = None,
        goal_uuid: UUID | None = None,
    ) -> Future:
        with self._requests_lock:
            return cast(Future, self._rclpy.send_goal_async(goal, feedback_callback, goal_uuid))

    def _cancel_goal_async(self, goal_handle: ClientGoalHandle) -> Future:
        with self._requests_lock:
            return cast(Future, self._rclpy._cancel_goal_async(goal_handle))

    def _get_result_async(self, goal_handle: ClientGoalHandle) -> Future:
        with self._requests_lock:
            return cast(Future, self._rclpy._get_result_async(goal_handle))

    async def execute(self, taken_data: dict[str, object]) -> None:
        answers = {key: taken_data.pop(key) for key in _ANSWERS if key in taken_data}
        if answers:
            # rclpy's handling of these three awaits nothing: the lock is never held
            # across a suspension.
            with self._requests_lock:
                await self._rclpy.execute(answers)
        if taken_data:  # feedback and status: their callbacks run outside the lock
            await self._rclpy.execute(taken_data)

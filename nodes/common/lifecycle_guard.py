"""GuardedLifecycleNode: a LifecycleNode that refuses an impossible transition instead of dying.

Why: in rclpy 7.1.6 (the Jazzy wheel) a ``change_state`` request for a
transition that does not exist from the current state (say ``deactivate``
while inactive, or id 8 from anywhere) raises ``RCLError: Transition is not
registered`` inside the service callback; the exception leaves ``rclpy.spin``
and the node process ends (rclpy issue 1209, fixed upstream after this wheel).
rclcpp answers ``success: false`` and carries on. This class does the same:
it checks the request against the transitions available from the current
state, refuses the others with a warning that lists the valid ones, and hands
every valid request to rclpy's own handler, unchanged.

Write a lifecycle node exactly as with ``rclpy.lifecycle.LifecycleNode``::

    from nodes.common.lifecycle_guard import GuardedLifecycleNode

    class MyNode(GuardedLifecycleNode):
        def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn: ...
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from lifecycle_msgs.msg import Transition
from lifecycle_msgs.srv import ChangeState
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.lifecycle import LifecycleNode

ChangeStateCallback = Callable[[ChangeState.Request, ChangeState.Response], ChangeState.Response]

# 8 -> "TRANSITION_DESTROY": names for the ids a learner may send by hand.
TRANSITION_NAMES = {
    value: name for name, value in vars(Transition).items() if name.startswith("TRANSITION_")
}


def _shorten(text: str, limit: int = 60) -> str:
    return text if len(text) <= limit else f"{text[:limit]}...({len(text)} characters)"


class GuardedLifecycleNode(LifecycleNode):
    """``LifecycleNode`` whose ``change_state`` service answers ``success: false`` to a bad request.

    A request names its transition by label (when the label is not empty) or
    else by id, as in rclpy.
    """

    def __init__(self, node_name: str, **kwargs: Any) -> None:
        super().__init__(node_name, **kwargs)
        # Absent with enable_communication_interface=False: no service, nothing to guard.
        service = getattr(self, "_service_change_state", None)
        if service is not None:
            self._unguarded_change_state: ChangeStateCallback = service.callback
            service.callback = self._on_change_state_request

    def _on_change_state_request(
        self, request: ChangeState.Request, response: ChangeState.Response
    ) -> ChangeState.Response:
        _state_id, state = self._state_machine.current_state
        valid = [(tid, label) for tid, label, *_goal in self._state_machine.available_transitions]
        wanted = request.transition
        if wanted.label:
            asked = f"label {_shorten(wanted.label)!r}"
            allowed = any(label == wanted.label for _tid, label in valid)
        else:
            asked = f"id {wanted.id} ({TRANSITION_NAMES.get(wanted.id, 'no such transition')})"
            allowed = any(tid == wanted.id for tid, _label in valid)
        if not allowed:
            listed = ", ".join(f"{label} (id {tid})" for tid, label in valid) or "none"
            self.get_logger().warning(
                f"change_state: refused transition {asked}: not valid from state '{state}'; "
                f"valid from here: {listed}"
            )
            response.success = False
            return response
        try:
            return self._unguarded_change_state(request, response)
        except _rclpy.RCLError as exc:  # a race or a state the check above did not foresee
            self.get_logger().error(
                f"change_state: transition {asked} from state '{state}' failed: {exc}"
            )
            response.success = False
            return response

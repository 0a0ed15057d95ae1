"""LifecycleNode: the managed node every Nav2 server is, as ``nav2_util::LifecycleNode``.

A Nav2 server starts *unconfigured*; ``configure`` reads its parameters and
makes its publishers and services, ``activate`` starts its work, and a
lifecycle manager (or ``ros2 lifecycle set``) drives the transitions.

One difference from a plain ``rclpy.lifecycle.LifecycleNode``: rclpy 7.1.6
(the Jazzy wheel) ends the whole process when its ``change_state`` service
is asked for a transition that does not exist from the current state
(``RCLError: Transition is not registered``, rclpy issue 1209). rclcpp, which
the real Nav2 runs on, answers ``success: false`` and carries on; so does this
class, with a warning that lists the transitions valid from here. Valid
requests go to rclpy's own handler unchanged.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import rclpy.lifecycle
from lifecycle_msgs.srv import ChangeState
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.lifecycle import LifecycleState, TransitionCallbackReturn

Handler = Callable[[ChangeState.Request, ChangeState.Response], ChangeState.Response]


class LifecycleNode(rclpy.lifecycle.LifecycleNode):
    """A lifecycle node whose ``change_state`` refuses an impossible transition, as rclcpp does."""

    def __init__(self, node_name: str, namespace: str = "", **kwargs: Any) -> None:
        super().__init__(node_name, namespace=namespace or None, **kwargs)
        service = getattr(self, "_service_change_state", None)
        if service is not None:
            self._rclpy_change_state: Handler = service.callback
            service.callback = self._checked_change_state

    def _checked_change_state(
        self, request: ChangeState.Request, response: ChangeState.Response
    ) -> ChangeState.Response:
        _id, state = self._state_machine.current_state
        available = [(tid, label) for tid, label, *_ in self._state_machine.available_transitions]
        wanted = request.transition
        if wanted.label:
            known = any(label == wanted.label for _tid, label in available)
            asked = f"'{wanted.label[:60]}'"
        else:
            known = any(tid == wanted.id for tid, _label in available)
            asked = f"id {wanted.id}"
        if not known:
            valid = ", ".join(f"{label} ({tid})" for tid, label in available) or "none"
            self.get_logger().warning(
                f"Transition {asked} is not valid from state '{state}' (valid: {valid})"
            )
            response.success = False
            return response
        try:
            return self._rclpy_change_state(request, response)
        except _rclpy.RCLError as exc:  # a race the check above could not see
            self.get_logger().error(f"Transition {asked} from '{state}' failed: {exc}")
            response.success = False
            return response

    # --- leaving: every Nav2 server says so and lets go of what configure made ---
    def release(self) -> None:
        """Give back what ``on_configure`` made; a server that made something says what."""

    def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("Cleaning up")
        self.release()
        return TransitionCallbackReturn.SUCCESS

    def on_shutdown(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("Shutting down")
        self.release()
        return TransitionCallbackReturn.SUCCESS

    def on_error(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().error(f"Error in state '{state.label}': released everything")
        self.release()
        return TransitionCallbackReturn.SUCCESS

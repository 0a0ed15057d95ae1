"""A step's service buttons return once the server has answered, so the next button
comes after it.

Lesson 19 puts the robot back at its start (``/reset_world``) and then drives it. The
walk clicks both at once; when the reset was fired and forgotten it reached the world
on a loaded machine only after the drive had begun, the robot jumped back mid-drive,
covered only the rest of it and the scan check waited for a wall it never came near
(ci of d081dc2). Lesson 11's configure and activate buttons have the same order.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

import pytest
from rclpy.node import Node
from std_srvs.srv import Trigger

from app.lessons.runtime import LessonRuntime
from app.lessons.schema import Spec
from app.ros.runtime import RosRuntime
from app.supervisor import Supervisor
from tests.conftest import wait_until

pytestmark = pytest.mark.ros
ANSWER_AFTER_SEC = 1.0  # the server's work: longer than any button's own cost


def test_a_service_button_returns_after_the_server_answered(probe, supervisor):
    server = RosRuntime("slow_reset")
    handled = threading.Event()

    def reset(_request: Trigger.Request, response: Trigger.Response) -> Trigger.Response:
        time.sleep(ANSWER_AFTER_SEC)
        handled.set()
        response.success = True
        return response

    server.node.create_service(Trigger, "/slow_reset", reset)
    lessons = LessonRuntime(probe.node, supervisor)
    try:
        button = Spec(
            "call_service",
            {"service": "/slow_reset", "type": "std_srvs/srv/Trigger", "request": {}},
        )
        began = time.monotonic()
        said = lessons.perform(button)
        assert handled.is_set(), f"the button returned before the server was done: {said!r}"
        assert time.monotonic() - began >= ANSWER_AFTER_SEC
        assert said == "Called /slow_reset: it answered."
    finally:
        lessons.close()
        server.shutdown()


def test_lifecycle_buttons_run_in_order_and_say_when_a_transition_is_refused(probe, supervisor):
    with _buttons_for(probe, supervisor, "lifecycle_talker", "change_state") as (lessons, node):

        def button(transition: str) -> str:
            return lessons.perform(Spec("lifecycle", {"node": node, "transition": transition}))

        assert button("activate") == (
            f"Asked {node} to activate: it refused (it is unconfigured, and activate does not "
            "start there)."
        )
        # Back to back, as the walk clicks them: activate finds configure done.
        assert button("configure") == f"Asked {node} to configure: done."
        assert button("activate") == f"Asked {node} to activate: done."


def test_a_parameter_button_says_done_or_why_the_node_refused(probe, supervisor):
    with _buttons_for(probe, supervisor, "parameters_node", "set_parameters") as (lessons, node):

        def button(name: str, value: object) -> str:
            return lessons.perform(Spec("set_param", {"node": node, "name": name, "value": value}))

        before = time.monotonic()
        assert button("greeting", "") == (
            f"Set greeting = '' on {node}: it refused: greeting must not be empty."
        )
        assert button("greeting", "Hola") == f"Set greeting = 'Hola' on {node}: done."
        # A rate judged from here on hears only the new value.
        assert lessons.changed_at is not None and lessons.changed_at > before


@contextmanager
def _buttons_for(
    probe: RosRuntime, supervisor: Supervisor, program: str, service: str
) -> Iterator[tuple[LessonRuntime, str]]:
    """A lesson runtime, with the catalog node ``program`` started and serving ``service``."""
    lessons = LessonRuntime(probe.node, supervisor)
    try:
        supervisor.start(program)
        node = f"/{program}"
        _wait_for_service(probe.node, f"{node}/{service}")
        yield lessons, node
    finally:
        lessons.close()


def _wait_for_service(node: Node, service: str) -> None:
    wait_until(
        lambda: service in {name for name, _ in node.get_service_names_and_types()},
        timeout=30,
        what=f"the service {service}",
    )

"""deadlock_fix: the relay offers /relay_add only once it can reach /add_two_ints.

So a caller that sees /relay_add is answered right however long discovery took. Before,
the node offered /relay_add at once and waited 2 s for /add_two_ints inside the callback;
in rehearsal ci78 (load 20 on 2 cores) that wait ran out and the reference answered 0.
The starter, the reference and both recorded mistakes share the constructor's wait.
"""

from __future__ import annotations

import pytest

from app.exercises import runner
from tests.conftest import wait_until
from tests.course_data import shared_exercises

pytestmark = pytest.mark.ros
SERVER = "add_two_ints_server"  # the exercise's setup node


def _services(probe) -> set[str]:
    return {name for name, _types in probe.node.get_service_names_and_types()}


@pytest.mark.parametrize("which", ["reference", "starter"])
def test_relay_add_appears_only_once_add_two_ints_is_reachable(which, supervisor, probe, tmp_path):
    exercise = next(e for e in shared_exercises().exercises if e.slug == "deadlock_fix")
    assert tuple(exercise.setup) == (SERVER,)
    script = tmp_path / "relay.py"
    script.write_text(getattr(exercise, which), encoding="utf-8")
    runner.start(supervisor, exercise, script)
    try:
        # Its constructor is waiting: it says so each second, and offers nothing yet.
        wait_until(
            lambda: any(
                "waiting for /add_two_ints" in line for line in runner.output(supervisor, exercise)
            ),
            timeout=60,
            what="the relay saying it waits for /add_two_ints",
        )
        wait_until(
            lambda: "relay_server" in probe.node.get_node_names(), timeout=30, what="/relay_server"
        )
        assert "/relay_add" not in _services(probe), "offered before its server is reachable"

        supervisor.start(SERVER)
        wait_until(
            lambda: "/relay_add" in _services(probe),
            timeout=60,
            what="/relay_add once the server is up",
        )
        if which == "starter":
            return  # it deadlocks on a call: that is the exercise
        from tutorial_interfaces.srv import AddTwoInts

        client = probe.node.create_client(AddTwoInts, "/relay_add")
        try:
            assert client.wait_for_service(timeout_sec=30)
            future = client.call_async(AddTwoInts.Request(a=20, b=22))
            wait_until(future.done, timeout=30, what="the answer of /relay_add")
            assert future.result().sum == 42
        finally:
            probe.node.destroy_client(client)
    finally:
        runner.stop(supervisor, exercise)
        supervisor.stop(SERVER).result()

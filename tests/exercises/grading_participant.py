"""The grader's side of a grading test: one ROS participant and a supervisor on a domain
of the test's own, in tests/run.py's private network namespace, ended after the module."""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import pytest

from tests.conftest import in_private_netns


@contextmanager
def grading_participant(name: str, domain_id: int) -> Iterator[tuple[Any, Any]]:
    """(node, supervisor); the environment is given back as it was."""
    if not in_private_netns():
        pytest.fail("run through tests/run.py: DDS tests need the private network namespace")
    from app.dds import configure_dds_env
    from app.ros.runtime import RosRuntime
    from app.supervisor import Supervisor

    saved = dict(os.environ)
    configure_dds_env(os.environ, domain_id=domain_id, network=False)
    runtime = RosRuntime(name)
    supervisor = Supervisor(os.environ)
    try:
        yield runtime.node, supervisor
    finally:
        supervisor.shutdown()
        runtime.shutdown()
        os.environ.clear()
        os.environ.update(saved)

"""Fixtures for the ros2cli tests: run a verb through the probe node, retry until discovered."""

from __future__ import annotations

import time
from collections.abc import Callable

import pytest

from app.ros.context import CallContext, Limits
from app.ros2cli import run_text

# Generous, bounded: discovery and replies are slow when two cores are busy.
TEST_LIMITS = Limits(max_messages=3, max_seconds=6.0, service_timeout=15.0, action_timeout=40.0)


class Ros2Runner:
    """Runs console text through the real verbs on the probe node and keeps the output."""

    def __init__(self, node) -> None:
        self.node = node

    def __call__(self, text: str, limits: Limits | None = None) -> tuple[int, list[str]]:
        lines: list[str] = []
        ctx = CallContext(self.node, lines.append, limits or TEST_LIMITS)
        code = run_text(ctx, text)
        return code, "\n".join(lines).splitlines()

    def until(
        self,
        text: str,
        accept: Callable[[str], bool] | str,
        timeout: float = 30.0,
        limits: Limits | None = None,
    ) -> str:
        """Repeat ``text`` until its output satisfies ``accept`` (a substring or predicate)."""
        check = (lambda out: accept in out) if isinstance(accept, str) else accept
        deadline = time.monotonic() + timeout
        out = ""
        while time.monotonic() < deadline:
            _code, lines = self(text, limits)
            out = "\n".join(lines)
            if check(out):
                return out
            time.sleep(0.3)
        pytest.fail(f"`{text}` never gave the expected output within {timeout:.0f} s; last:\n{out}")


@pytest.fixture
def ros2(probe) -> Ros2Runner:
    return Ros2Runner(probe.node)


def one_error_line(lines: list[str]) -> str:
    """Bad input must give exactly one 'error:' line and no traceback; returns that line."""
    errors = [line for line in lines if line.startswith("error:")]
    assert len(errors) == 1, lines
    assert not any("Traceback" in line for line in lines), lines
    return errors[0]

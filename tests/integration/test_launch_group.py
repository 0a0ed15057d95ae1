"""`ros2-classroom launch <group>` runs a group in the foreground and stops it on Ctrl+C."""

from __future__ import annotations

import re
import signal
import subprocess
import sys
import threading

import psutil
import pytest

from app import PROJECT_ROOT
from tests.conftest import wait_until

pytestmark = pytest.mark.ros


def test_launch_add_two_ints_streams_prefixed_output_and_stops_on_sigint(ros_env):
    proc = subprocess.Popen(
        [sys.executable, "-m", "app", "launch", "add_two_ints"],
        cwd=PROJECT_ROOT,
        env={**ros_env, "PYTHONUNBUFFERED": "1"},
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,
    )
    lines: list[str] = []
    reader = threading.Thread(target=lambda: lines.extend(proc.stdout), daemon=True)
    reader.start()

    def seen(pattern: str) -> bool:
        return any(re.search(pattern, line) for line in list(lines))

    try:
        wait_until(
            lambda: seen(r"^\[add_two_ints_client\] .*Result of add_two_ints: 2 \+ 3 = 5"),
            timeout=40,
            what=f"the client's sum in the launch output: {lines[-10:]}",
        )
        wait_until(
            lambda: seen(r"^\[launch\] add_two_ints_client exited \(exit code 0\)"),
            timeout=15,
            what="the client's exit to be reported",
        )
        assert seen(r"^\[add_two_ints_server\] .*a=2 b=3 -> sum=5")
        started = re.compile(r"started add_two_ints_server \(pid (\d+)")
        server_pid = int(next(m for line in lines if (m := started.search(line))).group(1))
        assert proc.poll() is None  # the server keeps the group running

        proc.send_signal(signal.SIGINT)  # Ctrl+C
        assert proc.wait(timeout=20) == 0
        reader.join(5)
        assert seen(r"^\[launch\] add_two_ints_server stopped \(exit code 0\)"), lines[-10:]
        assert not psutil.pid_exists(server_pid) or (
            psutil.Process(server_pid).status() == psutil.STATUS_ZOMBIE
        )
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()

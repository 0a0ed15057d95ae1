"""Run ``python -m ros2launch`` as a terminal would, with an ament prefix built by the test.

Nothing here imports the classroom's ``app`` or ``nodes``: the launch
packages are exercised from outside, in child processes, as a learner's
``ros2 launch`` runs them.
"""

from __future__ import annotations

import os
import select
import signal
import subprocess
import sys
import textwrap
import time
from collections.abc import Mapping
from pathlib import Path

PROJECT = Path(__file__).resolve().parents[2]


def python_child(code: str) -> str:
    """An executable script (for lib/<pkg>/<exe>) that runs ``code`` with this Python."""
    return f"#!{sys.executable}\n" + textwrap.dedent(code)


def ament_prefix(root: Path, packages: Mapping[str, Mapping[str, str]]) -> Path:
    """A prefix as colcon installs one: index marker, lib/<pkg>/<exe>, share/<pkg>/<file>.

    ``packages`` maps a package name to {relative path: content}; paths under
    ``lib/`` become executables of that package, the others go under ``share/<pkg>/``.
    """
    for package, files in packages.items():
        marker = root / "share/ament_index/resource_index/packages" / package
        marker.parent.mkdir(parents=True, exist_ok=True)
        marker.write_text("")
        (root / "share" / package).mkdir(parents=True, exist_ok=True)
        for relative, content in files.items():
            if relative.startswith("lib/"):
                path = root / "lib" / package / relative[4:]
            else:
                path = root / "share" / package / relative
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(content)
            path.chmod(0o755 if relative.startswith("lib/") else 0o644)
    return root


def launch_env(base: Mapping[str, str], prefix: Path | None, log_dir: Path) -> dict[str, str]:
    env = dict(base)
    env["ROS_LOG_DIR"] = str(log_dir)
    env["PYTHONUNBUFFERED"] = "1"
    if prefix is not None:
        env["AMENT_PREFIX_PATH"] = str(prefix)
    else:
        env.pop("AMENT_PREFIX_PATH", None)
    return env


def run(args: list[str], env: Mapping[str, str], timeout: float = 30.0) -> tuple[int, list[str]]:
    """``ros2 launch ARGS`` to its end: exit code and output lines (stdout and stderr)."""
    proc = subprocess.run(
        [sys.executable, "-m", "ros2launch", *args],
        env=dict(env),
        capture_output=True,
        text=True,
        timeout=timeout,
        cwd=PROJECT,
    )
    return proc.returncode, (proc.stdout + proc.stderr).splitlines()


class Launch:
    """A running ``ros2 launch`` in its own session, as in a terminal of its own."""

    def __init__(
        self, args: list[str], env: Mapping[str, str], command: list[str] | None = None
    ) -> None:
        """``ros2 launch ARGS``, or another ``command`` that runs a launch."""
        self.proc = subprocess.Popen(
            command or [sys.executable, "-m", "ros2launch", *args],
            env=dict(env),
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            start_new_session=True,
            cwd=PROJECT,
        )
        self.lines: list[str] = []
        self._buffer = b""

    @property
    def pgid(self) -> int:
        return self.proc.pid

    def read_until(self, predicate, timeout: float) -> list[str]:  # type: ignore[no-untyped-def]
        """Read lines until ``predicate(lines)`` holds (or fail after ``timeout``)."""
        assert self.proc.stdout is not None
        fd = self.proc.stdout.fileno()
        deadline = time.monotonic() + timeout
        while not predicate(self.lines):
            left = deadline - time.monotonic()
            if left <= 0:
                raise AssertionError(f"timed out; output so far: {self.lines}")
            ready, _, _ = select.select([fd], [], [], min(left, 0.2))
            if not ready:
                continue
            chunk = os.read(fd, 65536)
            if not chunk:
                raise AssertionError(f"ros2 launch ended early: {self.lines}")
            self._buffer += chunk
            *complete, self._buffer = self._buffer.split(b"\n")
            self.lines += [line.decode(errors="replace") for line in complete]
        return self.lines

    def ctrl_c(self) -> None:
        """What a terminal does on Ctrl+C: SIGINT to the whole foreground process group."""
        os.killpg(self.pgid, signal.SIGINT)

    def finish(self, timeout: float = 20.0) -> list[str]:
        rest, _ = self.proc.communicate(timeout=timeout)
        self.lines += (self._buffer + rest).decode(errors="replace").splitlines()
        self._buffer = b""
        return self.lines

    def kill(self) -> None:
        """Whatever happened, nothing of this launch outlives the test."""
        for pid in group_members(self.pgid):
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait(5)


def group_members(pgid: int) -> list[int]:
    """Live processes (not zombies) whose process group is ``pgid``."""
    members = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:
            continue
        fields = stat.rsplit(")", 1)[1].split()
        if int(fields[2]) == pgid and fields[0] != "Z":
            members.append(int(entry.name))
    return members


def started_pids(lines: list[str]) -> dict[str, int]:
    """label -> pid from ``[INFO] [talker-1]: process started with pid [N]`` lines."""
    out = {}
    for line in lines:
        if ": process started with pid [" in line:
            label = line.split("] [", 1)[1].split("]", 1)[0]
            out[label] = int(line.rsplit("[", 1)[1].rstrip("]"))
    return out

"""A classroom on disk (Alice's scratch folder, everyone's progress, Bob's scratch) and a runner.

Alice's snippets run as the dashboard would run them (``contained_argv``, cwd
= her scratch folder, a fresh DDS domain) or, for the controls, as plain
``python snippet.py``. The files they must not reach are world-readable and
the folder they must not write is world-writable: only the sandbox stops them.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import tempfile
import textwrap
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from app.containment.contain import sandbox_processes
from app.containment.sandbox import SandboxLimits, contained_argv, kill_leftovers, sandbox_available

SECRET = "bob-progress-secret"
DEFAULT = SandboxLimits()


@dataclass
class Result:
    pid: int
    returncode: int
    stdout: str
    stderr: str
    seconds: float


@dataclass
class Classroom:
    root: Path
    env: dict[str, str]
    launched: list[int] = field(default_factory=list)

    @property
    def scratch(self) -> Path:  # Alice's: the only place her code may write
        return self.root / "scratch" / "alice"

    @property
    def progress(self) -> Path:  # everyone's progress: hidden
        return self.root / "progress"

    @property
    def bob(self) -> Path:  # another learner's scratch folder: hidden
        return self.root / "scratch" / "bob"

    @property
    def shared(self) -> Path:  # world-writable, outside the scratch folder
        return self.root / "shared"

    @property
    def hidden(self) -> list[Path]:
        return [self.progress, self.bob]

    def write(self, code: str, name: str = "snippet.py") -> Path:
        """Like the dashboard's copy for a run: written by root, mode 0600."""
        script = self.scratch / name
        script.write_text(textwrap.dedent(code))
        script.chmod(0o600)
        return script

    def argv(self, script: Path, limits: SandboxLimits, contained: bool) -> list[str]:
        if contained:
            return contained_argv(script, self.scratch, self.hidden, limits)
        return [sys.executable, str(script)]

    def popen(
        self, code: str, limits: SandboxLimits = DEFAULT, contained: bool = True, **kw
    ) -> subprocess.Popen[str]:
        proc = subprocess.Popen(
            self.argv(self.write(code), limits, contained),
            cwd=self.scratch,
            env=self.env,
            stdin=subprocess.DEVNULL,
            text=True,
            start_new_session=True,
            **kw,
        )
        self.launched.append(proc.pid)
        return proc

    def run(
        self,
        code: str,
        limits: SandboxLimits = DEFAULT,
        contained: bool = True,
        timeout: float = 60,
    ) -> Result:
        start = time.monotonic()
        proc = self.popen(code, limits, contained, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        try:
            stdout, stderr = proc.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            kill_leftovers(proc.pid)
            stdout, stderr = proc.communicate()
            pytest.fail(f"still running after {timeout} s:\n{stdout}\n{stderr}")
        return Result(proc.pid, proc.returncode, stdout, stderr, time.monotonic() - start)


@pytest.fixture
def classroom(ros_env) -> Iterator[Classroom]:
    problem = sandbox_available()
    if problem:
        pytest.fail(f"the sandbox is not available here: {problem}")
    root = Path(tempfile.mkdtemp(prefix="classroom-", dir="/tmp"))
    root.chmod(0o755)  # pytest's tmp_path sits in a 0700 folder the sandbox user cannot enter
    room = Classroom(root, dict(ros_env, PYTHONUNBUFFERED="1"))
    room.scratch.mkdir(parents=True, mode=0o700)  # as the dashboard makes it
    room.bob.mkdir(mode=0o755)
    (room.bob / "notes.txt").write_text("bob's notes\n")
    room.progress.mkdir(mode=0o755)
    (room.progress / "bob.json").write_text(f'{{"secret": "{SECRET}"}}\n')
    for path in (room.bob / "notes.txt", room.progress / "bob.json"):
        path.chmod(0o644)
    room.shared.mkdir(mode=0o777)
    room.shared.chmod(0o1777)
    yield room
    deadline = time.monotonic() + 3  # SIGKILLed processes may take a moment to go
    while time.monotonic() < deadline and any(map(sandbox_processes, room.launched)):
        time.sleep(0.05)
    left = sum(kill_leftovers(pid) for pid in room.launched)
    shutil.rmtree(root, ignore_errors=True)
    assert left == 0, f"{left} contained processes were still running after the test"

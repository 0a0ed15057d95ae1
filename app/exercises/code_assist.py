"""What the code editor asks the server for while the learner types: lint, completion, format.

* Lint: pyflakes (``app.exercises.lint``), the same marks Run shows, as Ace
  annotations; static, it runs no learner code.
* Format: ``ruff format`` (a pinned dependency) on the text, with ruff's
  defaults whatever configuration lies around (``--isolated``).
* Completion and signature help: Jedi in a process of its own
  (``assist_worker.py``). Jedi imports the compiled modules it finds on its
  path to read them, and the learner's sourced install space is on that
  path; so on a dashboard served to other machines the worker runs contained,
  exactly like learner code (``app.containment.sandbox``), or not at all.

Everything here is called from worker threads (``asyncio.to_thread``) or
returns futures: nothing blocks the web server's event loop.
"""

from __future__ import annotations

import json
import logging
import os
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Sequence
from concurrent.futures import Future
from pathlib import Path
from typing import IO, TYPE_CHECKING, TypedDict

from app.containment import sandbox
from app.containment.policy import RunPolicy
from app.exercises.lint import Problem, lint
from app.stop_signals import die_with

if TYPE_CHECKING:
    from typing import Literal

    from app.exercises.assist_worker import Reply, Request

log = logging.getLogger(__name__)

WORKER = Path(__file__).resolve().parent / "assist_worker.py"
FORMAT_SECONDS = 15.0
RESTART_PAUSE_SEC = 5.0  # a worker that keeps dying is not restarted in a tight loop
# A long session of typing: Jedi's CPU adds up; the worker restarts when it hits this.
WORKER_CPU_SECONDS = 3600
WORKER_MEMORY_BYTES = 3 * 1024**3


class FormatError(ValueError):
    """ruff could not format the text (a syntax error, say); one line for the learner."""


class Mark(TypedDict):
    """An Ace gutter annotation (``row`` is 0-based)."""

    row: int
    column: int
    text: str
    type: Literal["error", "warning"]


def marks(problems: Sequence[Problem]) -> list[Mark]:
    """pyflakes problems as Ace gutter annotations (rows are 0-based)."""
    return [
        {
            "row": p.line - 1,
            "column": p.column,
            "text": p.message,
            "type": "error" if p.fatal else "warning",
        }
        for p in problems
    ]


def lint_marks(code: str, filename: str) -> list[Mark]:
    return marks(lint(code, filename))


def _ruff() -> str:
    try:
        from ruff.__main__ import find_ruff_bin

        return str(find_ruff_bin())
    except (ImportError, FileNotFoundError):
        return str(Path(sys.executable).parent / "ruff")


def format_code(code: str, filename: str) -> str:
    """The text as ``ruff format`` writes it (ruff's defaults), or FormatError."""
    try:
        done = subprocess.run(
            [_ruff(), "format", "--isolated", "--stdin-filename", Path(filename).name, "-"],
            input=code,
            capture_output=True,
            text=True,
            timeout=FORMAT_SECONDS,
        )
    except FileNotFoundError:
        raise FormatError("ruff is not installed here (pip install the project again)") from None
    except subprocess.TimeoutExpired:
        raise FormatError(f"ruff took longer than {FORMAT_SECONDS:g} s") from None
    if done.returncode != 0:
        message = done.stderr.strip().splitlines()[-1] if done.stderr.strip() else "ruff failed"
        # "error: Failed to parse my_node.py:3:7: Expected ..." -> "line 3: Expected ..."
        if "Failed to parse" in message:
            _, _, where = message.partition("Failed to parse ")
            parts = where.split(":", 3)
            if len(parts) == 4 and parts[1].isdigit():
                message = f"line {parts[1]}: {parts[3].strip()}"
        raise FormatError(f"cannot format: {message} (fix it first; the marks show where)")
    return done.stdout


def worker_argv(policy: RunPolicy | None, scratch: Path | None) -> list[str]:
    """How to start the worker: as the user, or contained; ValueError when it may not run."""
    if policy is None or not policy.contained:
        return [sys.executable, str(WORKER)]
    sandbox.require_sandbox("completion", ValueError)
    if scratch is None:
        raise ValueError("completion needs the learner's scratch folder here")
    limits = sandbox.SandboxLimits(
        cpu_seconds=WORKER_CPU_SECONDS, memory_bytes=WORKER_MEMORY_BYTES, processes=16
    )
    return sandbox.contained_argv(WORKER, scratch, policy.hidden, limits, ros=False)


class AssistProcess:
    """One Jedi worker process; requests go in order, answers come back as futures.

    Any thread may call ``request``. A reader thread resolves the futures. A
    worker that dies fails its pending requests and is started again on the
    next request (not more often than every ``RESTART_PAUSE_SEC``).
    """

    def __init__(
        self,
        argv: Callable[[], list[str]],
        cwd: Path | None = None,
        restart_pause: float = RESTART_PAUSE_SEC,
    ) -> None:
        self._argv, self._cwd, self._restart_pause = argv, cwd, restart_pause
        self._lock = threading.Lock()
        self._proc: subprocess.Popen[str] | None = None
        self._pending: dict[int, tuple[subprocess.Popen[str], Future[Reply]]] = {}
        self._next = 1
        self._last_start = 0.0
        self.problem = ""  # why the worker cannot run, for the editor's status line
        self.ready = threading.Event()

    def _start(self) -> subprocess.Popen[str] | None:
        """Under the lock: the running worker, or a new one (None: not now)."""
        if self._proc is not None and self._proc.poll() is None:
            return self._proc
        if time.monotonic() - self._last_start < self._restart_pause:
            return None
        self._last_start = time.monotonic()
        try:
            argv = self._argv()
        except ValueError as exc:
            self.problem = str(exc)
            return None
        cwd = self._cwd if self._cwd is not None and self._cwd.is_dir() else None
        self.ready.clear()
        self._proc = subprocess.Popen(
            argv,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
            encoding="utf-8",
            cwd=cwd,
            env={**os.environ, "PYTHONUNBUFFERED": "1", "PYTHONDONTWRITEBYTECODE": "1"},
            start_new_session=True,
            preexec_fn=die_with(os.getpid()),
        )
        self.problem = ""
        assert self._proc.stdout is not None
        threading.Thread(
            target=self._read, args=(self._proc, self._proc.stdout), daemon=True
        ).start()
        return self._proc

    def _read(self, proc: subprocess.Popen[str], stdout: IO[str]) -> None:
        for raw in stdout:
            try:
                answer = json.loads(raw)
            except ValueError:
                continue
            if answer.get("ready"):
                self.ready.set()
                continue
            with self._lock:
                _owner, future = self._pending.pop(answer.get("id"), (proc, None))
            if future is not None and not future.done():
                future.set_result(answer)
        proc.wait()
        with self._lock:
            failed = [f for ident, (owner, f) in list(self._pending.items()) if owner is proc]
            self._pending = {k: v for k, v in self._pending.items() if v[0] is not proc}
        for future in failed:
            if not future.done():
                future.set_exception(RuntimeError("the completion worker ended"))

    def request(self, payload: Request) -> Future[Reply]:
        """Send one request; the future holds the worker's answer (a dict)."""
        future: Future[Reply] = Future()
        with self._lock:
            proc = self._start()
            if proc is None or proc.stdin is None:
                future.set_exception(RuntimeError(self.problem or "the completion worker is off"))
                return future
            ident = self._next
            self._next += 1
            self._pending[ident] = (proc, future)
            try:
                proc.stdin.write(json.dumps({**payload, "id": ident}) + "\n")
                proc.stdin.flush()
            except (BrokenPipeError, OSError, ValueError):
                self._pending.pop(ident, None)
                future.set_exception(RuntimeError("the completion worker ended"))
        return future

    def warm_up(self) -> None:
        """Start the worker now (it parses rclpy once), so the first '.' is quick."""
        with self._lock:
            self._start()

    def close(self) -> None:
        with self._lock:
            proc, self._proc = self._proc, None
        if proc is not None and proc.poll() is None:
            proc.kill()
            proc.wait(5)

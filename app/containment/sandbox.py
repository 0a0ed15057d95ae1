"""Run learner code contained: the argv for the supervisor, and whether this machine can.

When the dashboard serves other machines, a learner's file is untrusted. It
runs through ``contain.py`` (see there for the how and the order), which
makes the process itself the sandbox, so the supervisor's process group,
parent-death signal and Ctrl+C keep working unchanged:

* files: everything read-only, the scratch folder writable, the hidden
  folders (other learners' progress and scratch) and the home folders
  unreadable -- Landlock;
* limits: CPU seconds, address space, processes (and threads), file size,
  open files -- rlimits, with the process count made per sandbox by running
  each one under a uid of its own;
* network: only ROS 2 over loopback -- the launcher creates the DDS
  participant itself, then seccomp forbids new non-Unix sockets and Landlock
  any TCP; the participant's sockets are bound to 127.0.0.1 and pinned to lo.

Whatever a contained process forks runs under the same uid: ``kill_leftovers``
ends it even after the launcher was SIGKILLed.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from app.containment import contain
from app.containment.policy import RunRefused
from app.dds import LOOPBACK_PROFILE

LAUNCHER = Path(contain.__file__).resolve()


@dataclass(frozen=True)
class SandboxLimits:
    """Per contained program (its forks and threads included for ``processes``)."""

    cpu_seconds: int = 300
    # Address space, measured: 0.3 GiB once the launcher has joined the ROS
    # graph; 0.5 GiB for a node with numpy, OpenCV and an 8-thread executor.
    memory_bytes: int = 2 * 1024**3
    processes: int = 64  # tasks of the sandbox uid: that node above has 11 threads
    file_bytes: int = 64 * 1024**2
    open_files: int = 256


def contained_argv(
    script: Path,
    scratch: Path,
    hidden: Sequence[Path],
    limits: SandboxLimits = SandboxLimits(),
    *,
    writable: Sequence[Path] = (),
    ros: bool = True,
) -> list[str]:
    """argv that runs ``python script`` contained.

    The caller spawns it with Popen, cwd=scratch, its own env; the script's own
    arguments (e.g. ``--ros-args ...``) may be appended. ``writable``: more
    folders it may write besides ``scratch``; ``ros=False``: no DDS participant
    (no IP socket at all).
    """
    argv = [sys.executable, str(LAUNCHER), "--scratch", str(scratch)]
    for folder in hidden:
        argv += ["--hide", str(folder)]
    for folder in writable:
        argv += ["--write", str(folder)]
    if not ros:
        argv.append("--no-ros")
    argv += [
        f"--cpu-seconds={limits.cpu_seconds}",
        f"--memory-bytes={limits.memory_bytes}",
        f"--processes={limits.processes}",
        f"--file-bytes={limits.file_bytes}",
        f"--open-files={limits.open_files}",
        f"--dds-profile={LOOPBACK_PROFILE}",
        "--",
        str(script),
    ]
    return argv


def require_sandbox(what: str, refused: Callable[[str], Exception] = RunRefused) -> None:
    """Raise ``refused("<what> must run contained here, and cannot: <what is missing>")``
    when this machine cannot contain a program (each runner raises its own kind)."""
    missing = sandbox_available()
    if missing:
        raise refused(f"{what} must run contained here, and cannot: {missing}")


def sandbox_available() -> str | None:
    """None when containment works on this machine, else one line saying what is missing."""
    if not LOOPBACK_PROFILE.is_file():
        return f"the loopback DDS profile {LOOPBACK_PROFILE} is missing"
    return contain.missing()


def kill_leftovers(launcher_pid: int | None = None) -> int:
    """SIGKILL what a contained process left running; returns how many processes.

    With a pid: everything of that (ended) launcher. Without: everything whose
    launcher has ended. Each launcher also does the latter when it starts.
    """
    return contain.kill_processes(contain.sandbox_processes(launcher_pid))

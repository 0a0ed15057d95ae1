"""Which ends of a dashboard start it again: the rule ``make run``'s keeper and the classroom share.

Two ends bring a dashboard back by itself, its progress kept:
- SIGABRT: a crash in native code;
- its ROS guard firing (app/ros/liveness.py): the DDS participant stopped
  answering. The guard ends it with SIGABRT, so that faulthandler writes every
  thread's stack to the log, and with SIGKILL when the abort has not ended it
  within a few seconds. On a machine whose cores are busy the abort can take
  that long, and the restarters, which waited for SIGABRT alone, took such a
  dashboard for one killed on purpose: it never came back (the likely end of
  a rehearsal's classroom whose learner was never restarted, at load 14).

A SIGKILL alone cannot tell the guard from someone's ``kill -9``, so the
guard says it fired: before its first signal it creates a file, the *mark*,
whose path the restarter put in the dashboard's environment. Any other end
(Ctrl+C, SIGTERM, an error at start, ``kill -9``) is left alone.

Standard library only: the keeper must outlive whatever its child does.
"""

from __future__ import annotations

import signal
from pathlib import Path

MARK_VARIABLE = "CLASSROOM_GUARD_MARK"  # the path the guard creates when it fires
RESTART_AFTER = -signal.SIGABRT  # Popen's returncode for "ended by SIGABRT"


class GuardMark:
    """One dashboard's mark: a path in the restarter's folder; no file until the guard fires."""

    def __init__(self, folder: Path, name: str) -> None:
        self.path = folder / f"{name}.guard-fired"
        self.clear()

    def env(self) -> dict[str, str]:
        """What the dashboard's environment needs for its guard to leave the mark."""
        return {MARK_VARIABLE: str(self.path)}

    def fired(self) -> bool:
        return self.path.exists()

    def clear(self) -> None:
        """Before each start: a mark left by the last run says nothing about the next."""
        self.path.unlink(missing_ok=True)


def ended_for_a_restart(code: int, mark: GuardMark) -> str | None:
    """Why a dashboard that ended with ``code`` starts again (said to the user); None: it stays."""
    if mark.fired():
        return "its ROS participant stopped answering and its guard ended it"
    if code == RESTART_AFTER:
        return "it was ended by SIGABRT (a crash; see its log)"
    return None

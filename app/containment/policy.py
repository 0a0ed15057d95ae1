"""Whether learner code may run here, and how: the one rule every runner of it reads."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from app.ros.errors import Ros2Error


class RunRefused(Ros2Error, RuntimeError):
    """Learner code may not run here (remote dashboard without the teacher's consent).

    A ``Ros2Error``: the refusal is the teacher's setting working as meant, so the page
    shows its one line and the log no traceback (as for a build refused the same way).
    """


@dataclass(frozen=True)
class RunPolicy:
    """Where and how learner code may run."""

    allowed: bool = True
    contained: bool = False
    hidden: tuple[Path, ...] = ()  # directories contained code must not read

    def refusal(self) -> str:
        return (
            "This dashboard serves other machines, so learner code runs only when the "
            "teacher starts it with --allow-learner-code (it then runs contained)."
        )


# On this machine only (bound to 127.0.0.1): the learner's code is the user's own.
LOOPBACK_POLICY = RunPolicy()

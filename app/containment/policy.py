"""Whether learner code may run here, and how: the one rule every runner of it reads."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path


class RunRefused(RuntimeError):
    """Learner code may not run here (remote dashboard without the teacher's consent)."""


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

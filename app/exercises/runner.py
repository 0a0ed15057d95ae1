"""Runs a learner's file as a real ROS 2 process, through the supervisor.

Same DDS profile and domain, same start/stop/crash handling as a catalog
node: the supervisor owns the process. Stop is Ctrl+C (SIGINT first). When
the dashboard serves other machines, the file runs contained
(``app.containment``) or, unless the teacher allowed learner code, not
at all.
"""

from __future__ import annotations

import re
import sys
from dataclasses import dataclass
from pathlib import Path

from app.containment import sandbox
from app.containment.policy import LOOPBACK_POLICY, RunPolicy, RunRefused
from app.exercises.model import Exercise
from app.supervisor import LearnerProgram, NodeStatus, Supervisor

_FILE_LINE = re.compile(r'^\s*File "(?P<file>[^"]+)", line (?P<line>\d+)')


def is_launch_file(script: Path) -> bool:
    """A Python launch file (the tutorials' form): it runs through ``ros2 launch``."""
    try:
        text = script.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return False
    return re.search(r"^def generate_launch_description\(", text, re.MULTILINE) is not None


def program_for(exercise: Exercise, script: Path, policy: RunPolicy) -> LearnerProgram:
    if not policy.allowed:
        raise RunRefused(policy.refusal())
    scratch = script.parent
    if is_launch_file(script):
        from app.launch_prefix import LaunchRefused, launch_program

        try:
            return launch_program(
                exercise.program_name, exercise.node, [str(script)], scratch, policy, trusted=False
            )
        except LaunchRefused as exc:
            raise RunRefused(str(exc)) from None
    if not policy.contained:
        argv = [sys.executable, str(script)]
        return LearnerProgram(exercise.program_name, exercise.node, tuple(argv), scratch)
    sandbox.require_sandbox("learner code")
    argv = sandbox.contained_argv(script, scratch, policy.hidden)
    return LearnerProgram(
        exercise.program_name,
        exercise.node,
        tuple(argv),
        scratch,
        after_exit=sandbox.kill_leftovers,
    )


def start(
    supervisor: Supervisor, exercise: Exercise, script: Path, policy: RunPolicy = LOOPBACK_POLICY
) -> NodeStatus:
    """(Re)start the learner's program from ``script``: a running one is stopped first."""
    name = exercise.program_name
    if name in supervisor.statuses() and supervisor.status(name).active:
        supervisor.stop(name).result()
    return supervisor.start_program(program_for(exercise, script, policy))


def stop(supervisor: Supervisor, exercise: Exercise) -> NodeStatus | None:
    """Ctrl+C (then SIGTERM, SIGKILL) and wait for the reap; None if it never ran."""
    if exercise.program_name not in supervisor.statuses():
        return None
    return supervisor.stop(exercise.program_name).result()


def status(supervisor: Supervisor, exercise: Exercise) -> NodeStatus | None:
    return supervisor.statuses().get(exercise.program_name)


def output(supervisor: Supervisor, exercise: Exercise, last: int | None = None) -> list[str]:
    if exercise.program_name not in supervisor.statuses():
        return []
    return supervisor.output(exercise.program_name, last)


@dataclass(frozen=True)
class Crash:
    """The last traceback of the learner's program, pointed at their own file."""

    line: int | None  # line in the learner's file, if the traceback passes through it
    code: str  # that line's text
    error: str  # the last line: "NameError: name 'x' is not defined"

    def describe(self) -> str:
        where = f"line {self.line}: {self.code.strip()}\n" if self.line else ""
        return where + self.error


def last_crash(lines: list[str], script: Path, source: str) -> Crash | None:
    """Find the newest traceback in ``lines`` and the deepest frame in ``script``."""
    start = None
    for i, line in enumerate(lines):
        if line.startswith("Traceback (most recent call last):"):
            start = i
    if start is None:
        return None
    block = lines[start + 1 :]
    line_no = None
    error = ""
    for text in block:
        match = _FILE_LINE.match(text)
        if match and Path(match["file"]).name == script.name:
            line_no = int(match["line"])
        elif text and not text.startswith((" ", "\t")):
            error = text.strip()
            break
    source_lines = source.splitlines()
    code = source_lines[line_no - 1] if line_no and line_no <= len(source_lines) else ""
    return Crash(line_no, code, error or block[-1].strip() if block else "")


def crash_of(supervisor: Supervisor, exercise: Exercise, script: Path) -> Crash | None:
    """The last traceback of the learner's program, read against the file that ran."""
    source = script.read_text(encoding="utf-8") if script.is_file() else ""
    return last_crash(output(supervisor, exercise), script, source)

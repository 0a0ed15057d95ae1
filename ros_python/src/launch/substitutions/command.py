"""The standard output of a command, run at substitution time (``xacro robot.xacro``)."""

from __future__ import annotations

import shlex
import subprocess
from typing import TYPE_CHECKING, Any

from ..substitution import Substitution
from ..utilities import normalize_to_list_of_substitutions, perform_substitutions
from .substitution_failure import SubstitutionFailure

if TYPE_CHECKING:
    from ..launch_context import LaunchContext

COMMAND_TIMEOUT_SEC = 60.0  # a command that never ends must not hang the launch


class Command(Substitution):
    def __init__(self, command: Any, *, on_stderr: Any = "fail") -> None:
        if isinstance(command, (list, tuple)):
            parts: list[Any] = []
            for i, item in enumerate(command):  # upstream separates list items with spaces
                if i:
                    parts.append(" ")
                parts.append(item)
            command = parts
        self.__command = normalize_to_list_of_substitutions(command)
        self.__on_stderr = normalize_to_list_of_substitutions(on_stderr)

    @property
    def command(self) -> list[Substitution]:
        return self.__command

    def describe(self) -> str:
        return f"Command({' + '.join(s.describe() for s in self.command)})"

    def perform(self, context: LaunchContext) -> str:
        from ..logging import get_logger

        text = perform_substitutions(context, self.command)
        on_stderr = perform_substitutions(context, self.__on_stderr)
        if on_stderr not in ("fail", "ignore", "warn", "capture"):
            raise SubstitutionFailure(
                f"expected 'on_stderr' to be one of: 'fail', 'ignore', 'warn' or 'capture', "
                f"got '{on_stderr}'"
            )
        try:
            result = subprocess.run(
                shlex.split(text),
                capture_output=True,
                text=True,
                env=context.environment,
                timeout=COMMAND_TIMEOUT_SEC,
            )
        except FileNotFoundError as exc:
            raise SubstitutionFailure(f"file not found: {exc}") from None
        except subprocess.TimeoutExpired:
            raise SubstitutionFailure(
                f"command timed out after {COMMAND_TIMEOUT_SEC:g} s: {text}"
            ) from None
        if result.returncode != 0:
            message = f"executed command failed. Command: {text}"
            if result.stderr:
                message += f"\nCaptured stderr output: {result.stderr}"
            raise SubstitutionFailure(message)
        if result.stderr:
            if on_stderr == "fail":
                raise SubstitutionFailure(
                    f"executed command showed stderr output. Command: {text}\n"
                    f"Captured stderr output: {result.stderr}"
                )
            if on_stderr == "warn":
                get_logger().warning(
                    f"executed command showed stderr output. Command: {text}\n"
                    f"Captured stderr output:\n{result.stderr}"
                )
            if on_stderr == "capture":
                return result.stdout + result.stderr
        return result.stdout

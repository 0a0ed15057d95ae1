"""Before a Run: compile the learner's code and lint it with pyflakes.

A syntax error refuses the run (the process would die at once with a less
friendly message); pyflakes findings (an undefined name, an unused import)
are listed with their line numbers and the run goes ahead.
"""

from __future__ import annotations

import ast
from dataclasses import dataclass

from pyflakes import checker


@dataclass(frozen=True)
class Problem:
    line: int
    column: int
    message: str
    fatal: bool  # a syntax error: the code cannot run

    def text(self) -> str:
        return f"line {self.line}: {self.message}"


def lint(code: str, filename: str = "yours.py") -> list[Problem]:
    """Problems in line order; a syntax error is the only problem when there is one."""
    try:
        tree = ast.parse(code, filename=filename)
        compile(tree, filename, "exec")
    except SyntaxError as exc:
        message = f"syntax error: {exc.msg}"
        return [Problem(exc.lineno or 1, (exc.offset or 1) - 1, message, True)]
    except ValueError as exc:  # e.g. a null byte in the source
        return [Problem(1, 0, f"cannot compile: {exc}", True)]
    found = checker.Checker(tree, filename=filename)
    problems = [
        Problem(m.lineno, getattr(m, "col", 0), m.message % m.message_args, False)
        for m in found.messages
    ]
    return sorted(problems, key=lambda p: (p.line, p.column))


def refuses_to_run(problems: list[Problem]) -> bool:
    return any(p.fatal for p in problems)

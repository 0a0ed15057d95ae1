"""The code editor's completion process: Jedi answering JSON lines on stdin, one at a time.

Started by path by ``app.exercises.code_assist`` (contained, like learner
code, on a dashboard served to other machines: Jedi imports compiled
modules it finds on its path to read them, and the learner's install space
is on that path). A process of its own also keeps Jedi's seconds of
inference off the dashboard's interpreter, whose threads serve the page.

Requests (one JSON object a line)::

    {"id": 7, "op": "complete" | "signatures" | "doc", "code": "...",
     "path": "/abs/file.py", "line": 1-based, "column": 0-based,
     "sys_path": ["extra folders first"], "project": "/abs/root", "name": "for doc"}

Answers: ``{"id": 7, "items": [...]}`` or ``{"id": 7, "error": "one line"}``.
"""

from __future__ import annotations

import json
import os
import sys
from typing import TYPE_CHECKING, TypedDict

if TYPE_CHECKING:
    from jedi import Project, Script
    from jedi.api.classes import Completion

if sys.path and os.path.realpath(sys.path[0]) == os.path.dirname(os.path.realpath(__file__)):
    del sys.path[0]  # app/exercises: its modules must not shadow anything the learner imports

MAX_ITEMS = 400
DOC_CHARS = 1200
PRELOAD = ("rclpy", "rclpy.node", "std_msgs.msg", "geometry_msgs.msg")


class Request(TypedDict, total=False):
    """One request line (``code_assist`` sends every field; ``id`` is read by ``main``)."""

    id: int
    op: str
    code: str
    path: str
    line: int
    column: int
    sys_path: list[str]
    project: str
    name: str


class CompletionItem(TypedDict):
    name: str
    type: str
    module: str


class SignatureItem(TypedDict):
    label: str
    params: list[str]
    index: int | None
    name: str


class Doc(TypedDict, total=False):
    """What ``doc`` answers; empty when no completion has that name."""

    name: str
    type: str
    signatures: list[str]
    doc: str


class Reply(TypedDict, total=False):
    """One answer line: ``items`` or ``error`` (the first line says ``ready`` instead)."""

    id: int
    items: list[CompletionItem | SignatureItem] | Doc
    error: str
    ready: bool


class Assistant:
    def __init__(self) -> None:
        import jedi

        self._jedi = jedi
        self._environment = jedi.InterpreterEnvironment()
        self._projects: dict[tuple[str, tuple[str, ...]], Project] = {}

    def _script(self, request: Request) -> Script:
        extra = tuple(str(p) for p in request.get("sys_path") or ())
        root = str(request.get("project") or os.path.dirname(str(request["path"])))
        key = (root, extra)
        project = self._projects.get(key)
        if project is None:
            paths = [*extra, *(p for p in sys.path if p and p not in extra)]
            project = self._jedi.Project(path=root, sys_path=paths, smart_sys_path=True)
            self._projects = {key: project}  # one project: the newest sys_path wins
        return self._jedi.Script(
            str(request["code"]),
            path=str(request["path"]),
            project=project,
            environment=self._environment,
        )

    def answer(self, request: Request) -> list[CompletionItem | SignatureItem] | Doc:
        op = request.get("op")
        script = self._script(request)
        line, column = int(request["line"]), int(request["column"])
        if op == "complete":
            found = script.complete(line, column)[:MAX_ITEMS]
            return [{"name": c.name, "type": c.type, "module": c.module_name} for c in found]
        if op == "doc":
            name = str(request.get("name", ""))
            for completion in script.complete(line, column):
                if completion.name == name:
                    return _doc(completion)
            return {}
        if op == "signatures":
            return [
                {
                    "label": s.to_string(),
                    "params": [p.to_string() for p in s.params],
                    "index": s.index,
                    "name": s.name,
                }
                for s in script.get_signatures(line, column)
            ]
        raise ValueError(f"unknown op {op!r}")

    def preload(self) -> None:
        """Parse rclpy and the common messages once, before the learner's first '.'."""
        try:
            self._jedi.preload_module(*PRELOAD)
        except Exception:  # a missing module only costs its first completion
            pass


def _doc(completion: Completion) -> Doc:
    signatures = [s.to_string() for s in completion.get_signatures()]
    try:
        text = completion.docstring(raw=True)
    except Exception:
        text = ""
    return {
        "name": completion.name,
        "type": completion.type,
        "signatures": signatures,
        "doc": text[:DOC_CHARS] + ("…" if len(text) > DOC_CHARS else ""),
    }


def main() -> int:
    # Our answers go to a copy of stdout; anything a module prints while Jedi
    # imports it goes to stderr instead of into the protocol.
    out = os.fdopen(os.dup(1), "w", encoding="utf-8", buffering=1)
    os.dup2(2, 1)
    sys.stdout = sys.stderr
    assistant = Assistant()
    assistant.preload()
    out.write(json.dumps({"id": 0, "ready": True}) + "\n")
    for raw in sys.stdin:
        try:
            request = json.loads(raw)
            ident = request["id"]
        except (ValueError, KeyError, TypeError):
            continue
        try:
            reply: Reply = {"id": ident, "items": assistant.answer(request)}
        except Exception as exc:  # Jedi on half-typed code: an empty answer, not a dead worker
            reply = {"id": ident, "error": f"{type(exc).__name__}: {exc}"[:300]}
        out.write(json.dumps(reply) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())

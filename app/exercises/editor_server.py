"""The code editor's server side: its page, its files, and its own websocket.

viser has no code editor, so the Exercise tab embeds one (Ace, installed
from npm by ``make setup``) in an iframe served by the same web server as
the dashboard: same origin, same access token. The editor talks to the hub
over its own websocket at ``/classroom/editor/ws`` with small JSON messages.
A message's ``file`` is ``""`` for the exercise's code, or a path in the
learner's workspace (``src/my_package/setup.py``), so one editor holds the
exercise and several workspace files in tabs:

- editor -> hub: ``save`` (code and a revision), ``flushed`` (nothing
  unsaved), ``open``/``close`` (a workspace file), ``tree`` (one folder of
  the workspace), ``complete``/``doc``/``signatures`` (Jedi, see
  ``code_assist``), ``format`` (ruff);
- hub -> editor: ``load`` (code to show: on connect, on open, after "Reset
  to starter", after a change on disk), ``saved`` (an acknowledgement),
  ``problems`` (pyflakes marks after every save of Python code, and after
  Run), ``flush`` (save now: Run and Check ask first, so they never run
  code older than what is on screen), ``tree``, ``closed``, the answers to
  ``complete``/``doc``/``signatures``/``format``, and ``assist`` (whether
  completion works here).

Workspace files go through ``app.learner_ws.files``: confined to the
workspace, text only, written atomically, exactly as the Console's
"Workspace files" folder writes them.

The hub runs in viser's asyncio thread and owns its state there; file
reads and writes, lint and format run in worker threads, completion in a
process of its own. Other threads reach the editors through ``push_code``,
``show_problems`` and ``flush``.
"""

from __future__ import annotations

import asyncio
import http
import json
import logging
import threading
from collections.abc import Awaitable, Callable
from pathlib import Path
from typing import TYPE_CHECKING, TypedDict, TypeVar
from urllib.parse import parse_qs, urlsplit

from websockets.asyncio.server import ServerConnection
from websockets.datastructures import Headers
from websockets.exceptions import ConnectionClosed
from websockets.http11 import Request, Response

from app.containment.policy import RunPolicy
from app.exercises import code_assist
from app.exercises.code_assist import AssistProcess, FormatError
from app.learner_ws import files, folder, overlay
from app.ros.errors import Ros2Error

if TYPE_CHECKING:
    from collections.abc import Coroutine, Mapping

    from app.exercises import assist_worker
    from app.exercises.code_assist import Mark

log = logging.getLogger(__name__)

PREFIX = "/classroom/editor/"
SOCKET_PATH = PREFIX + "ws"
EDITOR_DIR = Path(__file__).resolve().parent / "editor"
ACE_DIR = EDITOR_DIR / "node_modules" / "ace-builds" / "src-min-noconflict"
MAX_MESSAGE_BYTES = 1_000_000
ATTACH_WAIT_SEC = 60.0  # the dashboard builds its panels within this, even on busy cores
MAX_OPEN_FILES = 12  # tabs of workspace files; the oldest closes beyond that
WATCH_SEC = 1.0  # how often open workspace files are compared with the disk
ASSIST_SECONDS = 20.0  # the first completion parses rclpy (seconds on a busy machine)
EXERCISE = ""  # the ``file`` of the exercise's own code
_TYPES = {".html": "text/html; charset=utf-8", ".js": "application/javascript; charset=utf-8"}

Handler = Callable[[ServerConnection], Awaitable[None]]
ProcessRequest = Callable[[ServerConnection, Request], Response | None]
T = TypeVar("T")


class AssistState(TypedDict):
    """Whether completion works here, and if not, why (the editor's status line)."""

    completion: bool
    note: str


def editor_url(slug: str) -> str:
    """Relative to the page, so the editor loads under any base path (e.g. a hub's proxy)."""
    return f"{PREFIX.lstrip('/')}editor.html?slug={slug}"


def _file_for(path: str) -> Path | None:
    """Only the editor's two files and Ace's own files are served; nothing else."""
    name = path[len(PREFIX) :]
    if name in ("editor.html", "editor.js"):
        return EDITOR_DIR / name
    if name.startswith("ace/"):
        rest = name[len("ace/") :]
        if rest and "/" not in rest and not rest.startswith(".") and rest.endswith(".js"):
            candidate = ACE_DIR / rest
            return candidate if candidate.is_file() else None
    return None


def _ok(body: bytes, content_type: str) -> Response:
    headers = Headers(
        {
            "Content-Type": content_type,
            "Content-Length": str(len(body)),
            "Cache-Control": "no-cache",
        }
    )
    return Response(http.HTTPStatus.OK, "OK", headers, body)


def _is_python(file: str) -> bool:
    return file == EXERCISE or file.endswith(".py")


def _signature(path: Path) -> tuple[int, int] | None:
    try:
        info = path.stat()
    except OSError:
        return None
    return info.st_mtime_ns, info.st_size


class EditorHub:
    def __init__(self) -> None:
        self._loop: asyncio.AbstractEventLoop | None = None
        self._editors: dict[ServerConnection, str] = {}  # connection -> exercise slug
        self._pending: dict[ServerConnection, asyncio.Event] = {}
        self._load: Callable[[str], str] = lambda slug: ""
        self._save: Callable[[str, str], None] = lambda slug, code: None
        # Set once the Exercise panel has said where code lives: an editor that
        # connects before (a reload while the dashboard restarts) waits for it, or
        # its first save would be acknowledged and dropped.
        self._attached = threading.Event()
        # Open workspace files (shared by this learner's editors), and what the
        # disk held when the hub last read or wrote each: a change by anything
        # else (the Console, a lesson's button) is pushed to the editors.
        self._open: list[str] = []
        self._known: dict[str, tuple[int, int] | None] = {}
        self._watcher: asyncio.Task[None] | None = None
        self._tasks: set[asyncio.Task[None]] = set()
        self._policy: RunPolicy | None = None
        self._scratch: Path | None = None
        self._assist: AssistProcess | None = None
        self._newest: dict[tuple[ServerConnection, str], object] = {}  # the latest question asked
        self._asking: dict[tuple[ServerConnection, str], asyncio.Lock] = {}

    def attach(
        self,
        load: Callable[[str], str],
        save: Callable[[str, str], None],
        *,
        policy: RunPolicy | None = None,
        scratch: Path | None = None,
    ) -> None:
        """Where code comes from and goes to (the dashboard's exercise workspace), and the
        rule for learner code, which the completion worker follows (see ``code_assist``)."""
        self._load, self._save = load, save
        self._policy, self._scratch = policy, scratch
        self._attached.set()

    # -- hooks into the web server (see app.access.make_server) ---------------

    def wrap_http(self, inner: ProcessRequest | None) -> ProcessRequest:
        def process_request(connection: ServerConnection, request: Request) -> Response | None:
            path = urlsplit(request.path).path
            if path.startswith(PREFIX) and path != SOCKET_PATH:
                source = _file_for(path)
                if source is None or not source.is_file():
                    if path.startswith(PREFIX + "ace/") and not ACE_DIR.is_dir():
                        return connection.respond(
                            http.HTTPStatus.SERVICE_UNAVAILABLE,
                            "The code editor is not installed: run `make setup`.\n",
                        )
                    return connection.respond(http.HTTPStatus.NOT_FOUND, "Not found.\n")
                return _ok(source.read_bytes(), _TYPES.get(source.suffix, "text/plain"))
            return inner(connection, request) if inner is not None else None

        return process_request

    def wrap_handler(self, inner: Handler) -> Handler:
        async def handler(connection: ServerConnection) -> None:
            request = connection.request
            if request is not None and urlsplit(request.path).path == SOCKET_PATH:
                await self._serve_editor(connection)
            else:
                await inner(connection)

        return handler

    # -- the editor's websocket (viser's asyncio thread) -----------------------

    async def _serve_editor(self, connection: ServerConnection) -> None:
        self._loop = asyncio.get_running_loop()
        assert connection.request is not None
        query = parse_qs(urlsplit(connection.request.path).query)
        slug = (query.get("slug") or [""])[0]
        if not await asyncio.to_thread(self._attached.wait, ATTACH_WAIT_SEC):
            text = "the dashboard is still starting: reload this page in a moment"
            await self._error(connection, EXERCISE, text)
            return
        self._editors[connection] = slug
        if self._watcher is None or self._watcher.done():
            self._watcher = asyncio.create_task(self._watch())
        try:
            code = await asyncio.to_thread(self._load, slug)
            await connection.send(json.dumps({"type": "load", "code": code, "initial": True}))
            await self._send_problems(connection, EXERCISE, code, slug)
            for file in list(self._open):
                await self._send_file(connection, file, initial=True)
            await connection.send(json.dumps({"type": "assist", **self._assist_state()}))
            async for raw in connection:
                await self._on_message(connection, slug, raw)
        except ConnectionClosed:
            pass
        except Exception:  # one broken editor must not take the server down
            log.exception("editor connection failed")
        finally:
            self._editors.pop(connection, None)
            event = self._pending.pop(connection, None)
            if event is not None:
                event.set()

    async def _on_message(self, connection: ServerConnection, slug: str, raw: str | bytes) -> None:
        if not isinstance(raw, str) or len(raw) > MAX_MESSAGE_BYTES:
            await connection.send(json.dumps({"type": "error", "text": "message too large"}))
            return
        try:
            message = json.loads(raw)
            kind = message["type"]
            file = message.get("file") or EXERCISE
        except (ValueError, KeyError, TypeError, AttributeError):
            return  # not ours: ignore
        if not isinstance(file, str):
            return
        if kind == "save" and isinstance(message.get("code"), str):
            await self._on_save(connection, slug, file, message["code"], message.get("rev", 0))
        if kind == "flushed" or (kind == "save" and file == EXERCISE):
            event = self._pending.pop(connection, None)
            if event is not None:
                event.set()
        if kind == "open" and file != EXERCISE:
            await self._on_open(connection, file)
        elif kind == "close" and file in self._open:
            self._open.remove(file)
            self._known.pop(file, None)
        elif kind == "tree":
            await self._on_tree(connection, str(message.get("folder") or ""))
        elif kind in ("complete", "doc", "signatures", "format"):
            # Slow answers go in tasks: saves keep flowing meanwhile.
            task = asyncio.create_task(self._answer(connection, slug, kind, file, message))
            self._tasks.add(task)
            task.add_done_callback(self._tasks.discard)

    async def _send(self, connection: ServerConnection, message: Mapping[str, object]) -> None:
        try:
            await connection.send(json.dumps(message))
        except ConnectionClosed:
            pass

    async def _error(self, connection: ServerConnection, file: str, text: str) -> None:
        await self._send(connection, {"type": "error", "file": file, "text": text})

    # -- files -------------------------------------------------------------------

    async def _on_save(
        self, connection: ServerConnection, slug: str, file: str, code: str, rev: object
    ) -> None:
        if file == EXERCISE:
            try:
                await asyncio.to_thread(self._save, slug, code)
            except ValueError as exc:  # too long, unknown exercise: tell the editor
                await self._error(connection, file, str(exc))
                return
        else:
            ws = folder.current()
            if ws is None:
                await self._error(connection, file, "no workspace here")
                return
            try:
                path = await asyncio.to_thread(files.write_text, ws, file, code)
            except (Ros2Error, OSError) as exc:
                await self._error(connection, file, f"not saved: {exc}")
                return
            if file in self._open:
                self._known[file] = _signature(path)
            # Another window with this file open shows what was just saved.
            for other in list(self._editors):
                if other is not connection:
                    await self._send(other, {"type": "load", "file": file, "code": code})
        await self._send(connection, {"type": "saved", "file": file, "rev": rev})
        await self._send_problems(connection, file, code, slug)

    async def _send_problems(
        self, connection: ServerConnection, file: str, code: str, slug: str
    ) -> None:
        """pyflakes marks for Python code, after every save: the learner sees them as they type."""
        if not _is_python(file):
            return
        name = f"{slug or 'exercise'}.py" if file == EXERCISE else Path(file).name
        items = await asyncio.to_thread(code_assist.lint_marks, code, name)
        await self._send(connection, {"type": "problems", "file": file, "items": items})

    async def _on_open(self, connection: ServerConnection, text: str) -> None:
        ws = folder.current()
        if ws is None:
            await self._error(connection, text, "no workspace here")
            return
        try:
            file = files.relative(ws, text)
            await asyncio.to_thread(files.read_text, ws, file)  # text, not too big: or an error
        except (Ros2Error, OSError) as exc:
            await self._error(connection, text, str(exc))
            return
        if file not in self._open:
            self._open.append(file)
            while len(self._open) > MAX_OPEN_FILES:
                closed = self._open.pop(0)
                self._known.pop(closed, None)
                await self._broadcast_all({"type": "closed", "file": closed, "note": ""})
        await self._send_file(connection, file, initial=True, focus=True)

    async def _send_file(
        self, connection: ServerConnection, file: str, *, initial: bool, focus: bool = False
    ) -> None:
        ws = folder.current()
        if ws is None:
            return
        try:
            code = await asyncio.to_thread(files.read_text, ws, file)
        except (Ros2Error, OSError) as exc:
            await self._error(connection, file, str(exc))
            return
        self._known[file] = _signature(ws.root / file)
        message = {"type": "load", "file": file, "code": code, "initial": initial, "focus": focus}
        await self._send(connection, message)
        await self._send_problems(connection, file, code, "")

    async def _on_tree(self, connection: ServerConnection, text: str) -> None:
        ws = folder.current()
        if ws is None:
            await self._send(connection, {"type": "tree", "folder": text, "entries": [],
                                          "note": "no workspace here"})  # fmt: skip
            return
        try:
            entries = await asyncio.to_thread(files.children, ws, text)
        except (Ros2Error, OSError) as exc:
            await self._send(
                connection, {"type": "tree", "folder": text, "entries": [], "note": str(exc)}
            )
            return
        rows = [{"path": e.path, "folder": e.folder, "note": e.note} for e in entries]
        await self._send(connection, {"type": "tree", "folder": text, "entries": rows})

    async def _watch(self) -> None:
        """Push a change on disk of an open workspace file (the Console or a lesson wrote it)."""
        while self._editors:
            await asyncio.sleep(WATCH_SEC)
            ws = folder.current()
            if ws is None or not self._open:
                continue
            for file in list(self._open):
                now = await asyncio.to_thread(_signature, ws.root / file)
                if file not in self._known or now == self._known.get(file):
                    continue
                if now is None:  # deleted (or renamed) outside the editor
                    self._open.remove(file)
                    self._known.pop(file, None)
                    note = f"{file} was deleted or renamed in the workspace: its tab closed"
                    await self._broadcast_all({"type": "closed", "file": file, "note": note})
                    continue
                self._known[file] = now
                try:
                    code = await asyncio.to_thread(files.read_text, ws, file)
                except (Ros2Error, OSError):
                    continue
                await self._broadcast_all(
                    {
                        "type": "load",
                        "file": file,
                        "code": code,
                        "note": "changed on disk: reloaded",
                    }
                )

    async def _broadcast_all(self, message: Mapping[str, object]) -> None:
        for connection in list(self._editors):
            await self._send(connection, message)

    # -- completion, signatures, format ---------------------------------------------

    def _assist_state(self) -> AssistState:
        try:
            code_assist.worker_argv(self._policy, self._scratch)
        except ValueError as exc:
            return {"completion": False, "note": str(exc)}
        self._worker().warm_up()
        return {"completion": True, "note": ""}

    def _worker(self) -> AssistProcess:
        if self._assist is None:
            policy, scratch = self._policy, self._scratch
            self._assist = AssistProcess(lambda: code_assist.worker_argv(policy, scratch), scratch)
        return self._assist

    def _where(self, slug: str, file: str) -> tuple[Path, Path]:
        """The file's path for Jedi (its imports resolve from there) and the project root."""
        ws = folder.current()
        if file != EXERCISE and ws is not None:
            return ws.root.resolve() / file, ws.root.resolve()
        base = self._scratch or Path.cwd()
        return base / f"{slug or 'exercise'}.py", base

    async def _answer(
        self, connection: ServerConnection, slug: str, kind: str, file: str, message: dict
    ) -> None:
        code = message.get("code")
        if not isinstance(code, str):
            return
        if kind == "format":
            await self._format(connection, file, code, message.get("rev", 0))
            return
        reply: dict[str, object] = {
            "type": kind,
            "id": message.get("id"),
            "file": file,
            "items": [],
        }
        # Typing fast asks on every key: only the newest question of a kind waits for Jedi,
        # the ones it overtook are answered empty at once.
        key = (connection, kind)
        self._newest[key] = reply["id"]
        lock = self._asking.setdefault(key, asyncio.Lock())
        async with lock:
            if self._newest.get(key) != reply["id"]:
                reply["note"] = "superseded"
                await self._send(connection, reply)
                return
            await self._ask_worker(slug, kind, file, message, reply)
        if not lock.locked() and self._newest.get(key) == reply["id"]:
            self._asking.pop(key, None)
            self._newest.pop(key, None)
        await self._send(connection, reply)

    async def _ask_worker(
        self, slug: str, kind: str, file: str, message: dict, reply: dict[str, object]
    ) -> None:
        code = message["code"]
        try:
            row, column = int(message["row"]), int(message["column"])
            path, root = self._where(slug, file)
            request: assist_worker.Request = {
                "op": kind,
                "code": code,
                "path": str(path),
                "project": str(root),
                "line": row + 1,
                "column": column,
                "name": str(message.get("name", "")),
                "sys_path": [str(p) for p in overlay.python_paths()],
            }
            future = self._worker().request(request)
            answer = await asyncio.wait_for(asyncio.wrap_future(future), ASSIST_SECONDS)
            reply["items"] = answer.get("items", [])
            if "error" in answer:
                reply["note"] = answer["error"]
        except (KeyError, TypeError, ValueError, RuntimeError) as exc:
            reply["note"] = str(exc)
        except asyncio.TimeoutError:  # not the builtin TimeoutError on Python 3.10
            reply["note"] = f"no answer within {ASSIST_SECONDS:g} s"

    async def _format(
        self, connection: ServerConnection, file: str, code: str, rev: object
    ) -> None:
        name = Path(file).name if file != EXERCISE else "exercise.py"
        try:
            formatted = await asyncio.to_thread(code_assist.format_code, code, name)
        except FormatError as exc:
            await self._send(
                connection, {"type": "formatted", "file": file, "rev": rev, "error": str(exc)}
            )
            return
        await self._send(
            connection, {"type": "formatted", "file": file, "rev": rev, "code": formatted}
        )

    # -- from other threads ----------------------------------------------------

    def _run(self, coroutine: Coroutine[object, None, T], timeout: float) -> T | None:
        loop = self._loop
        if loop is None or loop.is_closed():
            coroutine.close()
            return None
        try:
            return asyncio.run_coroutine_threadsafe(coroutine, loop).result(timeout)
        except Exception:  # a closed socket, a slow browser: the caller goes on
            log.debug("editor call failed", exc_info=True)
            return None

    async def _broadcast(self, slug: str, message: Mapping[str, object]) -> int:
        text = json.dumps(message)
        sent = 0
        for connection, editing in list(self._editors.items()):
            if editing == slug:
                try:
                    await connection.send(text)
                    sent += 1
                except ConnectionClosed:
                    pass
        return sent

    def push_code(self, slug: str, code: str, note: str = "") -> None:
        """Show ``code`` in every editor of ``slug`` (after "Reset to starter")."""
        self._run(self._broadcast(slug, {"type": "load", "code": code, "note": note}), 2.0)

    def show_problems(self, slug: str, items: list[Mark]) -> None:
        """Lint results as gutter marks: ``{"row": 0-based, "column", "text", "type"}``."""
        message = {"type": "problems", "file": EXERCISE, "items": items}
        self._run(self._broadcast(slug, message), 2.0)

    async def _flush(self, slug: str, timeout: float) -> bool:
        events = []
        for connection, editing in list(self._editors.items()):
            if editing == slug:
                event = asyncio.Event()
                self._pending[connection] = event
                events.append(event)
        if not events:
            return True
        await self._broadcast(slug, {"type": "flush"})
        try:
            await asyncio.wait_for(asyncio.gather(*(e.wait() for e in events)), timeout)
            return True
        except asyncio.TimeoutError:  # not the builtin TimeoutError on Python 3.10
            return False

    def flush(self, slug: str, timeout: float = 1.5) -> bool:
        """Ask the editors of ``slug`` to save now; True once all have (or none is open)."""
        return bool(self._run(self._flush(slug, timeout), timeout + 1.0))

    def editors_open(self, slug: str) -> int:
        return sum(1 for editing in list(self._editors.values()) if editing == slug)

    def close(self, timeout: float = 1.0) -> None:
        """End the hub's own tasks on the server's loop while it still runs, then the
        completion worker (it also dies with this process). A task still pending when the
        loop is dropped is logged as an error ("Task was destroyed but it is pending!"):
        the file watcher of every dashboard whose editor had been opened did so."""
        self._run(self._cancel_tasks(), timeout)
        if self._assist is not None:
            self._assist.close()

    async def _cancel_tasks(self) -> None:
        tasks = [t for t in (self._watcher, *self._tasks) if t is not None and not t.done()]
        for task in tasks:
            task.cancel()
        await asyncio.gather(*tasks, return_exceptions=True)

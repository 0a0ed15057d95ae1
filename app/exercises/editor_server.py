"""The exercise editor's server side: its page, its files, and its own websocket.

viser has no code editor, so the Exercise tab embeds one (Ace, installed
from npm by ``make setup``) in an iframe served by the same web server as
the dashboard: same origin, same access token. The editor talks to the hub
over its own websocket at ``/classroom/editor/ws`` with small JSON messages:

- editor -> hub: ``save`` (code and a revision), ``flushed`` (nothing unsaved);
- hub -> editor: ``load`` (code to show: the saved code on connect, the
  starter after a reset), ``saved`` (an acknowledgement), ``problems`` (lint
  results as gutter marks), ``flush`` (save now: Run and Check ask first, so
  they never run code older than what is on screen).

The hub runs in viser's asyncio thread. Saving goes to a ``save`` function
the dashboard gives (a thread-safe, atomic write); other threads reach the
editors through ``push_code``, ``show_problems`` and ``flush``.
"""

from __future__ import annotations

import asyncio
import http
import json
import logging
from collections.abc import Awaitable, Callable
from pathlib import Path
from typing import Any
from urllib.parse import parse_qs, urlsplit

from websockets.asyncio.server import ServerConnection
from websockets.datastructures import Headers
from websockets.exceptions import ConnectionClosed
from websockets.http11 import Request, Response

log = logging.getLogger(__name__)

PREFIX = "/classroom/editor/"
SOCKET_PATH = PREFIX + "ws"
EDITOR_DIR = Path(__file__).resolve().parent / "editor"
ACE_DIR = EDITOR_DIR / "node_modules" / "ace-builds" / "src-min-noconflict"
MAX_MESSAGE_BYTES = 1_000_000
_TYPES = {".html": "text/html; charset=utf-8", ".js": "application/javascript; charset=utf-8"}

Handler = Callable[[ServerConnection], Awaitable[None]]
ProcessRequest = Callable[[ServerConnection, Request], Response | None]


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


class EditorHub:
    def __init__(self) -> None:
        self._loop: asyncio.AbstractEventLoop | None = None
        self._editors: dict[ServerConnection, str] = {}  # connection -> exercise slug
        self._pending: dict[ServerConnection, asyncio.Event] = {}
        self._load: Callable[[str], str] = lambda slug: ""
        self._save: Callable[[str, str], None] = lambda slug, code: None

    def attach(self, load: Callable[[str], str], save: Callable[[str, str], None]) -> None:
        """Where code comes from and goes to (the dashboard's exercise workspace)."""
        self._load, self._save = load, save

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
        self._editors[connection] = slug
        try:
            code = await asyncio.to_thread(self._load, slug)
            await connection.send(json.dumps({"type": "load", "code": code, "initial": True}))
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

    async def _on_message(self, connection: ServerConnection, slug: str, raw: Any) -> None:
        if not isinstance(raw, str) or len(raw) > MAX_MESSAGE_BYTES:
            await connection.send(json.dumps({"type": "error", "text": "message too large"}))
            return
        try:
            message = json.loads(raw)
            kind = message["type"]
        except (ValueError, KeyError, TypeError):
            return  # not ours: ignore
        if kind == "save" and isinstance(message.get("code"), str):
            try:
                await asyncio.to_thread(self._save, slug, message["code"])
            except ValueError as exc:  # too long, unknown exercise: tell the editor
                await connection.send(json.dumps({"type": "error", "text": str(exc)}))
            else:
                await connection.send(json.dumps({"type": "saved", "rev": message.get("rev", 0)}))
        if kind in ("save", "flushed"):
            event = self._pending.pop(connection, None)
            if event is not None:
                event.set()

    # -- from other threads ----------------------------------------------------

    def _run(self, coroutine: Any, timeout: float) -> Any:
        loop = self._loop
        if loop is None or loop.is_closed():
            coroutine.close()
            return None
        try:
            return asyncio.run_coroutine_threadsafe(coroutine, loop).result(timeout)
        except Exception:  # a closed socket, a slow browser: the caller goes on
            log.debug("editor call failed", exc_info=True)
            return None

    async def _broadcast(self, slug: str, message: dict[str, Any]) -> int:
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

    def show_problems(self, slug: str, items: list[dict[str, Any]]) -> None:
        """Lint results as gutter marks: ``{"row": 0-based, "column", "text", "type"}``."""
        self._run(self._broadcast(slug, {"type": "problems", "items": items}), 2.0)

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

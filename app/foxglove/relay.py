"""The bridge's public WebSocket: both names of the Foxglove protocol, one server behind.

foxglove-sdk 0.30's server accepts only the subprotocol ``foxglove.sdk.v1``,
which Foxglove's app offers. Lichtblick and every client built on
``@foxglove/ws-protocol`` (0.8) offer only the protocol's first name,
``foxglove.websocket.v1``, and get ``400 Bad Request``. The messages are the
same under both names, so this relay listens on the address the learner is
given, accepts either name, and passes each client's frames, unchanged, to and
from its own connection to the SDK's server, which listens on a loopback port
of its own.

What stays the SDK's: one upstream connection per client, so each client is
still a client of its own there (its subscriptions, its backlog that drops the
oldest messages for a slow reader, its limits). The relay holds at most one
write buffer per direction (websockets waits for the reader before it reads on:
a slow client slows its own upstream, whose messages the SDK then drops).

Threads: one of its own, running an asyncio loop; ``start`` and ``stop`` from
any thread. asyncio turns Nagle's algorithm off on its TCP sockets, so small
messages are not held back here (``bridge.no_delay`` does that for the SDK's).
"""

from __future__ import annotations

import asyncio
import http
import logging
import threading
from collections.abc import Sequence

from websockets.asyncio.client import ClientConnection, connect
from websockets.asyncio.server import Server, ServerConnection, serve
from websockets.exceptions import ConnectionClosed, InvalidHandshake, InvalidURI
from websockets.http11 import Request, Response
from websockets.typing import Subprotocol

log = logging.getLogger(__name__)

SDK_PROTOCOL = Subprotocol("foxglove.sdk.v1")
LEGACY_PROTOCOL = Subprotocol("foxglove.websocket.v1")  # Lichtblick, @foxglove/ws-protocol
MAX_CLIENT_MESSAGE = 64 * 1024 * 1024  # bytes a client may send at once (the SDK's own cap)
START_TIMEOUT_SEC = 10.0
STOP_TIMEOUT_SEC = 5.0


def _offered(request: Request) -> list[str]:
    return [
        name.strip()
        for header in request.headers.get_all("Sec-WebSocket-Protocol")
        for name in header.split(",")
    ]


def _refuse_others(connection: ServerConnection, request: Request) -> Response | None:
    """As the SDK's server: a client that offers neither name is refused (400)."""
    if {SDK_PROTOCOL, LEGACY_PROTOCOL} & set(_offered(request)):
        return None
    return connection.respond(
        http.HTTPStatus.BAD_REQUEST,
        f"Offer the WebSocket subprotocol {SDK_PROTOCOL} or {LEGACY_PROTOCOL}.\n",
    )


def _choose(_connection: ServerConnection, offered: Sequence[Subprotocol]) -> Subprotocol | None:
    """The SDK's name when the client offers it, else the first name (None: refused)."""
    for name in (SDK_PROTOCOL, LEGACY_PROTOCOL):
        if name in offered:
            return name
    return None


class ProtocolRelay:
    """Listens on ``host:port`` (0: a free port) for clients of either protocol name and
    relays each to ``ws://127.0.0.1:<upstream_port>`` (the SDK's server)."""

    def __init__(self, host: str, port: int, upstream_port: int) -> None:
        self.host = host
        self._asked_port = port
        self.port = port
        self._upstream = f"ws://127.0.0.1:{upstream_port}"
        self._loop = asyncio.new_event_loop()
        self._server: Server | None = None
        self._ready = threading.Event()
        self._failure: BaseException | None = None
        self._thread = threading.Thread(target=self._run, name="foxglove-relay", daemon=True)

    def start(self) -> None:
        """Listen; OSError (as the SDK's start raises RuntimeError) when the port is taken."""
        self._thread.start()
        if not self._ready.wait(START_TIMEOUT_SEC):
            raise RuntimeError("the Foxglove relay did not start")
        if self._failure is not None:
            raise self._failure

    def stop(self) -> None:
        if not self._thread.is_alive():
            return
        self._loop.call_soon_threadsafe(self._loop.stop)
        self._thread.join(2 * STOP_TIMEOUT_SEC)  # the clients' closes, then their tasks' ends

    def _run(self) -> None:
        asyncio.set_event_loop(self._loop)
        try:
            self._server = self._loop.run_until_complete(self._listen())
            sock = next(iter(self._server.sockets))
            self.port = int(sock.getsockname()[1])
        except BaseException as exc:  # the port is taken, the host unknown, ...
            self._failure = exc
            self._ready.set()
            self._loop.close()
            return
        self._ready.set()
        try:
            self._loop.run_forever()
        finally:
            self._server.close()
            try:
                self._loop.run_until_complete(
                    asyncio.wait_for(self._server.wait_closed(), STOP_TIMEOUT_SEC)
                )
            except (TimeoutError, RuntimeError):  # a client that does not answer the close
                pass
            self._end_tasks()
            self._loop.close()

    def _end_tasks(self) -> None:
        """Cancel what still runs (a client's pumps) and let it end here, as asyncio.run does.
        A task left pending on a closed loop is ended later by the garbage collector, in
        whichever thread collects it: its clean-up then ran inside that thread's loop (in a
        browser test, Playwright's, whose call it cancelled)."""
        pending = asyncio.all_tasks(self._loop)

        async def cancelled() -> None:
            for task in pending:
                task.cancel()
            await asyncio.gather(*pending, return_exceptions=True)
            await self._loop.shutdown_asyncgens()

        try:
            self._loop.run_until_complete(asyncio.wait_for(cancelled(), STOP_TIMEOUT_SEC))
        except (TimeoutError, RuntimeError):  # a task that will not end: left to the log
            log.warning("foxglove relay: %d task(s) did not end at stop", len(pending))

    async def _listen(self) -> Server:
        return await serve(
            self._client,
            self.host,
            self._asked_port,
            subprotocols=[SDK_PROTOCOL, LEGACY_PROTOCOL],
            select_subprotocol=_choose,
            process_request=_refuse_others,
            max_size=MAX_CLIENT_MESSAGE,
            compression=None,  # as the SDK's server: CDR does not compress well, CPU does
        )

    async def _client(self, client: ServerConnection) -> None:
        try:
            upstream = await connect(
                self._upstream,
                subprotocols=[SDK_PROTOCOL],
                max_size=None,  # the SDK bounds what it sends (a camera image is megabytes)
                compression=None,
            )
        except (OSError, InvalidHandshake, InvalidURI, TimeoutError) as exc:
            log.warning("foxglove relay: the bridge's server did not answer (%s)", exc)
            await client.close(1011, "the bridge is not serving")
            return
        async with upstream:
            pumps = [
                asyncio.create_task(_pump(client, upstream)),
                asyncio.create_task(_pump(upstream, client)),
            ]
            _done, pending = await asyncio.wait(pumps, return_when=asyncio.FIRST_COMPLETED)
            for task in pending:
                task.cancel()
            await asyncio.gather(*pending, return_exceptions=True)
        await client.close()


Connection = ServerConnection | ClientConnection


async def _pump(source: Connection, sink: Connection) -> None:
    """Every frame from ``source`` to ``sink`` as it came (text as text, bytes as bytes),
    until either side closes."""
    try:
        async for message in source:
            await sink.send(message)
    except ConnectionClosed:
        pass

"""Stopping the Foxglove relay with a client connected leaves no task pending on its loop.

When the SDK's server did not answer the relay's close within the stop's time, the
client's tasks stayed pending on the relay's closed loop. The garbage collector ended
them later, in whichever thread ran it, inside that thread's loop: in a browser test,
Playwright's, whose call then failed with CancelledError (ci27, after an earlier test on
the same worker had used the relay). The relay now cancels and ends them itself.
"""

from __future__ import annotations

import asyncio
import base64
import hashlib
import socket
import threading
import time

from websockets.sync.client import connect

from app.foxglove.relay import LEGACY_PROTOCOL, SDK_PROTOCOL, ProtocolRelay

_GUID = "258EAFA5-E914-47DA-95CA-C5AB0DC85B11"  # RFC 6455's, for Sec-WebSocket-Accept


class SilentUpstream:
    """A WebSocket server (the SDK's stand-in) that accepts, then never reads or answers,
    not even a close: the relay's own close of that connection waits on it."""

    def __init__(self) -> None:
        self._listener = socket.create_server(("127.0.0.1", 0))
        self.port = self._listener.getsockname()[1]
        self._held: list[socket.socket] = []
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self) -> None:
        while True:
            try:
                conn, _ = self._listener.accept()
            except OSError:  # closed
                return
            request = conn.recv(4096).decode()
            key = next(
                line.split(":", 1)[1].strip()
                for line in request.split("\r\n")
                if line.lower().startswith("sec-websocket-key:")
            )
            accept = base64.b64encode(hashlib.sha1((key + _GUID).encode()).digest()).decode()
            conn.sendall(
                (
                    "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\n"
                    f"Connection: Upgrade\r\nSec-WebSocket-Accept: {accept}\r\n"
                    f"Sec-WebSocket-Protocol: {SDK_PROTOCOL}\r\n\r\n"
                ).encode()
            )
            self._held.append(conn)

    def close(self) -> None:
        self._listener.close()
        for conn in self._held:
            conn.close()


def test_a_relay_stopped_with_a_client_connected_leaves_no_pending_task():
    upstream = SilentUpstream()
    relay = ProtocolRelay("127.0.0.1", 0, upstream.port)
    relay.start()
    client = connect(f"ws://127.0.0.1:{relay.port}", subprotocols=[LEGACY_PROTOCOL])
    try:
        client.send("into the relay")
        time.sleep(0.3)  # the relay has its upstream connection and both pumps running
        loop = relay._loop  # the relay's own: what it leaves there, a collector ends elsewhere
        assert asyncio.all_tasks(loop), "the client's tasks never started"
        relay.stop()
        assert loop.is_closed()
        left = asyncio.all_tasks(loop)
        assert not left, f"{len(left)} tasks left pending on the closed loop: {left}"
    finally:
        client.close()
        upstream.close()

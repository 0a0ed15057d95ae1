"""Nagle's algorithm goes off on the server side of the bridge's client connections, only there."""

from __future__ import annotations

import socket

from app.foxglove.bridge import no_delay


def _nagle_off(sock: socket.socket) -> bool:
    return bool(sock.getsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY))


def test_no_delay_sets_tcp_nodelay_on_the_served_connections_only():
    with socket.socket() as server, socket.socket() as other_server:
        server.bind(("127.0.0.1", 0))
        server.listen()
        other_server.bind(("127.0.0.1", 0))
        other_server.listen()
        port = server.getsockname()[1]
        with socket.create_connection(("127.0.0.1", port)) as client:
            client.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 0)
            served, _ = server.accept()
            other_client = socket.create_connection(other_server.getsockname())
            other_served, _ = other_server.accept()
            with served, other_client, other_served:
                assert not _nagle_off(served)
                assert no_delay(port) == 1
                assert _nagle_off(served)
                served.sendall(b"still open")  # the descriptor was not closed by the call
                assert client.recv(16) == b"still open"
                assert not _nagle_off(client)  # the client's end is not the server's
                assert not _nagle_off(other_served)  # nor another port's connection

"""A browser that leaves mid-handshake is one INFO line (app/ws_handshake_log.py).

The real server, a real socket: connect, send nothing, close. Without the
filter websockets logs "opening handshake failed" with a traceback (seen in CI
when test_kills killed a browser while its page loaded).
"""

from __future__ import annotations

import logging
import socket
import sys
import time

from app.access import make_server
from app.ws_handshake_log import HANDSHAKE_FAILED, LEFT_EARLY, ClientLeftEarly, client_left_early


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def test_a_client_that_closes_before_its_request_is_one_info_line(caplog):
    caplog.set_level(logging.INFO, logger="websockets.server")
    port = _free_port()
    server, _ = make_server("127.0.0.1", port, None)
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=5):
            pass  # connect, send nothing, leave
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline and not any(
            r.msg in (LEFT_EARLY, HANDSHAKE_FAILED) for r in caplog.records
        ):
            time.sleep(0.05)
    finally:
        server.stop()
    handshakes = [r for r in caplog.records if r.msg in (LEFT_EARLY, HANDSHAKE_FAILED)]
    assert handshakes, "the server logged nothing about the dropped handshake"
    assert all(r.msg == LEFT_EARLY and r.levelno == logging.INFO for r in handshakes)
    assert all(r.exc_info is None for r in handshakes)
    assert "Traceback" not in caplog.text


def _failed_handshake(error: BaseException) -> logging.LogRecord:
    logger = logging.getLogger("websockets.server")
    try:
        raise RuntimeError("did not receive a valid HTTP request") from error
    except RuntimeError:
        return logger.makeRecord(
            logger.name, logging.ERROR, __file__, 1, HANDSHAKE_FAILED, (), sys.exc_info()
        )


def test_other_handshake_failures_keep_their_traceback():
    record = _failed_handshake(ValueError("a bug in a process_request"))
    assert not client_left_early(record)
    assert ClientLeftEarly().filter(record)
    assert record.levelno == logging.ERROR and record.exc_info is not None
    assert client_left_early(_failed_handshake(ConnectionResetError(104, "reset by peer")))

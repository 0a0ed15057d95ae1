"""A client that leaves during its websocket handshake is one log line, not a traceback.

websockets (the server under viser) logs every failed opening handshake as an
ERROR with the whole exception chain. The usual cause is harmless: a browser
that was killed, closed or reloaded while its connection was being opened
sends nothing, and the server reads "stream ends after 0 bytes". Seen in CI
when a test killed a browser mid-load: a three-part traceback in a log that
must hold none when nothing went wrong.

``install()`` puts a filter on the ``websockets.server`` logger that turns
exactly that case (the client closed or reset the connection before its
request was read) into one INFO line. Any other handshake failure keeps its
ERROR and traceback. Upstream would need to log a closed-before-request
handshake at a lower level without ``exc_info``.
"""

from __future__ import annotations

import logging
import threading

LOGGER_NAME = "websockets.server"
HANDSHAKE_FAILED = "opening handshake failed"
LEFT_EARLY = "a client closed its connection before its websocket handshake (%s)"
# What a client that went away before sending its request leaves in the chain.
_GONE = (EOFError, ConnectionResetError, BrokenPipeError, ConnectionAbortedError)

_LOCK = threading.Lock()


def _causes(error: BaseException | None) -> list[BaseException]:
    """``error`` and everything it was raised from, without looping."""
    chain: list[BaseException] = []
    while error is not None and all(error is not seen for seen in chain):
        chain.append(error)
        error = error.__cause__ or error.__context__
    return chain


def client_left_early(record: logging.LogRecord) -> bool:
    """Whether ``record`` is a handshake that failed only because the client left."""
    if record.msg != HANDSHAKE_FAILED or not record.exc_info:
        return False
    return any(isinstance(error, _GONE) for error in _causes(record.exc_info[1]))


class ClientLeftEarly(logging.Filter):
    def filter(self, record: logging.LogRecord) -> bool:
        if client_left_early(record):
            error = _causes(record.exc_info[1] if record.exc_info else None)[-1]
            record.msg, record.args = LEFT_EARLY, (error,)
            record.levelno, record.levelname = logging.INFO, "INFO"
            record.exc_info = record.exc_text = None
        return True


def install() -> None:
    """Add the filter to websockets' server logger (idempotent)."""
    logger = logging.getLogger(LOGGER_NAME)
    with _LOCK:
        if not any(isinstance(f, ClientLeftEarly) for f in logger.filters):
            logger.addFilter(ClientLeftEarly())

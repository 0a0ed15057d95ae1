"""Serving the page under a base path (``/user/<name>/ros2-classroom/``), not only at ``/``.

A proxy in front (Jupyter's server proxy on a hub) strips its prefix, so the
dashboard sees ``/`` and every relative link on the page works. viser's own
client is the exception: it opens its websocket at the page's address with the
trailing slash cut off (``.../ros2-classroom``), a path the proxy answers with
a redirect that a websocket cannot follow. viser reads the websocket address
from the ``websocket`` query parameter when one is given, so the page we hand
out starts with a few lines that, under a base path, put the page's own
address (slash kept) there before viser's code runs. At ``/`` nothing changes.
"""

from __future__ import annotations

import gzip
import http
from urllib.parse import urlsplit

from websockets.asyncio.server import ServerConnection
from websockets.http11 import Request, Response

from app.access import Handler, ProcessRequest, ServerExtension

# Runs before viser's bundle: only a page served below "/" gets the parameter.
WEBSOCKET_SHIM = (
    "<script>(function(){var l=window.location,q=new URLSearchParams(l.search);"
    'if(l.pathname!=="/"&&l.pathname.endsWith("/")&&!q.has("websocket")){'
    'q.set("websocket",l.origin.replace(/^http/,"ws")+l.pathname);'
    'history.replaceState(null,"",l.pathname+"?"+q.toString()+l.hash);}})();</script>'
)


def with_shim(page: bytes) -> bytes:
    """viser's index page with the shim first in its head."""
    head = page.find(b"<head>")
    at = head + len(b"<head>") if head >= 0 else 0
    return page[:at] + WEBSOCKET_SHIM.encode() + page[at:]


class BasePathPage:
    """A server extension that hands out viser's page with the websocket shim."""

    def __init__(self, inner: ServerExtension | None = None) -> None:
        self._inner = inner
        self._pages: dict[bytes, bytes] = {}  # viser's body -> ours (it never changes)

    def wrap_http(self, inner: ProcessRequest | None) -> ProcessRequest:
        if self._inner is not None:
            inner = self._inner.wrap_http(inner)

        def process_request(connection: ServerConnection, request: Request) -> Response | None:
            response = inner(connection, request) if inner is not None else None
            is_page = urlsplit(request.path).path in ("/", "/index.html")
            if (
                response is None
                or not is_page
                or response.status_code != http.HTTPStatus.OK
                or request.headers.get("Upgrade", "").lower() == "websocket"
            ):
                return response
            original = bytes(response.body)
            body = self._pages.get(original)
            if body is None:
                zipped = response.headers.get("Content-Encoding") == "gzip"
                page = with_shim(gzip.decompress(original) if zipped else original)
                body = self._pages[original] = gzip.compress(page) if zipped else page
            headers = response.headers.copy()
            del headers["Content-Length"]  # Headers is a multi-dict: replace, not add
            headers["Content-Length"] = str(len(body))
            return Response(response.status_code, response.reason_phrase, headers, body)

        return process_request

    def wrap_handler(self, inner: Handler) -> Handler:
        return self._inner.wrap_handler(inner) if self._inner is not None else inner

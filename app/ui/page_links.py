"""Links inside a panel's HTML that act like buttons.

viser's HTML element has no click callback, yet a drawing is often the best
control: the lifecycle state machine's edges *are* the transitions. A link
can still reach us. It points at ``classroom/act/<secret>/<name>`` (relative
to the page, so it works under any base path) on viser's own web server,
which runs the action registered under ``name`` and answers ``204 No
Content``; the link targets a hidden frame, so the page never navigates away
whatever the answer.

The secret is random per dashboard and only ever travels inside panels' HTML
over the dashboard's own websocket, so another web site cannot forge a link
that acts (cross-site request forgery); the access-token gate, when serving
other machines, still sits in front of every request.
"""

from __future__ import annotations

import html
import http
import re
import secrets
import threading
from collections.abc import Callable
from urllib.parse import urlsplit

from websockets.asyncio.server import ServerConnection
from websockets.http11 import Request, Response

from app.access import Handler, ProcessRequest, ServerExtension
from app.ui.page_script import listen_on_page, page_script

PREFIX = "/classroom/act/"
SINK = "classroom-link-sink"
# Put once into any HTML that holds action links: where their empty answers land.
SINK_FRAME = f'<iframe name="{SINK}" title="link answers" hidden></iframe>'
_NAME = re.compile(r"^[a-z0-9_.-]{1,64}$")

# The page sends a click on such a link itself, with fetch: a panel redrawn just after the
# click (the graph once a second) replaced its hidden frame while the frame's request was
# starting, and the click never arrived. The frame stays as the way before this script runs.
_SEND_CLICKS = f"""
const sendLink = (event) => {{
  const link = event.target.closest ? event.target.closest('a[target="{SINK}"]') : null;
  if (!link || event.button !== 0) return;
  event.preventDefault();
  const url = new URL(link.getAttribute('href'), parent.document.baseURI);
  parent.fetch(url, {{credentials: 'same-origin', cache: 'no-store'}}).catch(() => {{}});
}};
""" + listen_on_page("__classroomLinks", "click", "sendLink", capture=True)


def link_sender_html() -> str:
    """Sent once with the page: the script that delivers every link click (see above)."""
    return page_script(_SEND_CLICKS, "link clicks")


class PageLinks:
    """Registered actions behind secret links; also a server extension in front of ``inner``.

    ``register`` may be called from any thread; actions run in viser's
    asyncio thread, so they must only post work (e.g. ``UiLoop.post``).
    """

    def __init__(self, inner: ServerExtension | None = None) -> None:
        self._inner = inner
        self._secret = secrets.token_urlsafe(16)
        self._lock = threading.Lock()
        self._actions: dict[str, Callable[[], None]] = {}
        self._valued: dict[str, Callable[[str], None]] = {}

    def register(self, name: str, action: Callable[[], None]) -> str:
        """Make ``action`` reachable by a link; returns the link's address."""
        if not _NAME.match(name):
            raise ValueError(f"a page link name needs a-z, 0-9, '_', '.', '-': {name!r}")
        with self._lock:
            self._actions[name] = action
        return self.href(name)

    def register_value(self, name: str, action: Callable[[str], None]) -> str:
        """Like ``register``, for a link that carries one value: ``<address>/<value>``.

        The page appends what it reports (e.g. its window's width); the value is
        a-z, 0-9, '_', '.', '-' only, and ``action`` must still check it.
        """
        if not _NAME.match(name):
            raise ValueError(f"a page link name needs a-z, 0-9, '_', '.', '-': {name!r}")
        with self._lock:
            self._valued[name] = action
        return self.href(name)

    def href(self, name: str) -> str:
        # Relative to the page: the dashboard may be served under a base path
        # (a JupyterHub proxy's /user/<name>/ros2-classroom/), never only at /.
        return f"{PREFIX.lstrip('/')}{self._secret}/{name}"

    def anchor(self, name: str, content: str, title: str) -> str:
        """An SVG or HTML ``<a>`` around ``content`` that runs ``name`` when clicked."""
        return (
            f'<a href="{html.escape(self.href(name))}" target="{SINK}" '
            f'aria-label="{html.escape(title)}"><title>{html.escape(title)}</title>{content}</a>'
        )

    def _action_for(self, path: str) -> Callable[[], None] | None:
        secret, _, name = path[len(PREFIX) :].partition("/")
        if not secrets.compare_digest(secret.encode(), self._secret.encode()):
            return None
        name, _, value = name.partition("/")
        with self._lock:
            if not value:
                return self._actions.get(name)
            valued = self._valued.get(name)
        if valued is None or not _NAME.match(value):
            return None
        return lambda: valued(value)

    # -- server extension (viser's asyncio thread) -------------------------------

    def wrap_http(self, inner: ProcessRequest | None) -> ProcessRequest:
        if self._inner is not None:
            inner = self._inner.wrap_http(inner)

        def process_request(connection: ServerConnection, request: Request) -> Response | None:
            path = urlsplit(request.path).path
            if not path.startswith(PREFIX):
                return inner(connection, request) if inner is not None else None
            action = self._action_for(path)
            if action is None:
                return connection.respond(http.HTTPStatus.NOT_FOUND, "Not found.\n")
            action()
            return connection.respond(http.HTTPStatus.NO_CONTENT, "")

        return process_request

    def wrap_handler(self, inner: Handler) -> Handler:
        return self._inner.wrap_handler(inner) if self._inner is not None else inner

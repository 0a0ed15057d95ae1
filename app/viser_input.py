"""What a browser sends a widget is looked at before viser takes it (issue 38).

Two kinds of update are dropped where they come in, on viser's event loop,
before viser sets the value, so no thread of ours ever sees them:

- a dropdown's value that the dropdown does not offer (viser takes any
  string): a forged message, or a pick that raced the server's new list. It
  used to land and be put back from viser's pool thread; a Start clicked at
  once could read it first (a "job failed" with the catalog's "no catalog
  node named 'rm -rf /'" in a bad-input run). The browsers are sent the value
  the dropdown still has.
- a value of the wrong type, below.

viser 1.1.1's ``GuiApi._handle_gui_updates`` casts what a browser sends to the
type of the widget's value (``int("rm -rf /")``, ``float(None)``,
``int(float("nan"))``) and asserts that the property exists. A page never
sends such a value; a forged websocket message does, and then the cast raises
inside an event-loop task nobody awaits: an "exception was never retrieved"
traceback in the log per message (about a hundred from the bad-input test),
with nothing changed. ``install()`` looks at each update first and drops the
ones viser would fail to cast, with one warning line per widget (later ones
are debug lines, so a flood cannot fill the log). Upstream would need to
catch the cast error in ``_handle_gui_updates`` and ignore the update.
"""

from __future__ import annotations

import functools
import logging
import threading
from typing import Any

from viser import GuiDropdownHandle
from viser._gui_api import GuiApi
from viser._messages import GuiUpdateMessage

log = logging.getLogger(__name__)

_MARK = "_classroom_refuses_uncastable"
_LOCK = threading.Lock()
_warned: set[str] = set()  # widget uuids already warned about


def castable(state: Any, updates: dict[str, Any]) -> bool:
    """Whether viser's cast of ``updates`` onto the widget ``state`` would succeed."""
    for name, value in updates.items():
        if not hasattr(state, name):
            return False
        if name != "value":
            continue
        current = state.value
        try:
            if isinstance(current, tuple):
                if current:
                    kind = type(current[0])
                    tuple(kind(item) for item in value)
                else:
                    tuple(value)
            else:
                type(current)(value)
        except (TypeError, ValueError, OverflowError):
            return False
    return True


def offered(dropdown: GuiDropdownHandle[Any], updates: dict[str, Any]) -> bool:
    """Whether a dropdown's update leaves it at a value it offers."""
    return "value" not in updates or updates["value"] in dropdown.options


def install() -> None:
    """Wrap ``GuiApi._handle_gui_updates`` (idempotent; before a server is made)."""
    with _LOCK:
        handler = GuiApi._handle_gui_updates
        if getattr(handler, _MARK, False):
            return
        original = handler

        @functools.wraps(original)
        async def _handle_gui_updates(self: GuiApi, client_id: Any, message: Any) -> None:
            handle = self._gui_input_handle_from_uuid.get(message.uuid, None)
            if isinstance(handle, GuiDropdownHandle) and not offered(handle, message.updates):
                warn = message.uuid not in _warned
                _warned.add(message.uuid)
                (log.warning if warn else log.debug)(
                    "a browser chose %.80r in the dropdown %r, which does not offer it: "
                    "ignored, its value stays %r",
                    message.updates.get("value"),
                    handle.label,
                    handle.value,
                )
                # The sender's page shows its pick: it is told the value the server kept.
                self._websock_interface.queue_message(
                    GuiUpdateMessage(message.uuid, {"value": handle.value})
                )
                return
            if handle is not None and not castable(handle._impl, message.updates):
                warn = message.uuid not in _warned
                _warned.add(message.uuid)
                (log.warning if warn else log.debug)(
                    "a browser sent %.80r for the widget %r, which takes %s: ignored",
                    message.updates,
                    getattr(handle, "label", None) or message.uuid,
                    type(handle._impl.value).__name__,
                )
                return
            await original(self, client_id, message)

        setattr(_handle_gui_updates, _MARK, True)
        GuiApi._handle_gui_updates = _handle_gui_updates  # type: ignore[method-assign]

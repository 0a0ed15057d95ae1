"""A few lines of JavaScript that run in the dashboard's page, sent as HTML.

viser shows HTML as the server sends it, and a ``<script>`` inside it never
runs; a hidden same-origin frame's own document does run its script, each
time the frame is (re)sent, and reaches the page through ``parent`` (the
Turtlesim panel's key listener works the same way). Only the dashboard's
own, fixed scripts are ever sent; values in them are JSON-encoded.
"""

from __future__ import annotations

import html
import json


def page_script(script: str, title: str, **data: object) -> str:
    """A hidden frame that runs ``script``; ``data`` become ``data-*`` attributes (for tests
    and for sending the same script again as new content)."""
    document = f"<!doctype html><script>{script}</script>"
    attributes = "".join(
        f' data-{key.replace("_", "-")}="{html.escape(str(value), quote=True)}"'
        for key, value in data.items()
    )
    return (
        f'<iframe hidden title="{html.escape(title, quote=True)}"{attributes} '
        f'srcdoc="{html.escape(document, quote=True)}"></iframe>'
    )


def listen_on_page(slot: str, event: str, handler: str, *, capture: bool = False) -> str:
    """JavaScript that adds ``handler`` (a name in the script) to the page for ``event``.

    One listener per ``slot`` (a name on the page's window): a frame sent again
    removes its predecessor's listener. The old document's ``pagehide`` may come
    after the new document has started, so it removes only its own listener (it
    used to call whatever remover the slot held, the new one's: the arrow keys
    stopped driving the robot once the 3D stage re-mounted the panel).
    """
    slot_js, event_js, flag = json.dumps(slot), json.dumps(event), json.dumps(capture)
    return f"""
{{
  const off = () => parent.removeEventListener({event_js}, {handler}, {flag});
  if (parent[{slot_js}]) parent[{slot_js}]();
  parent.addEventListener({event_js}, {handler}, {flag});
  parent[{slot_js}] = off;
  window.addEventListener("pagehide", () => {{
    off();
    if (parent[{slot_js}] === off) delete parent[{slot_js}];
  }});
}}
"""

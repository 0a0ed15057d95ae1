"""A few lines of JavaScript that run in the dashboard's page, sent as HTML.

viser shows HTML as the server sends it, and a ``<script>`` inside it never
runs; a hidden same-origin frame's own document does run its script, each
time the frame is (re)sent, and reaches the page through ``parent`` (the
Turtlesim panel's key listener works the same way). Only the dashboard's
own, fixed scripts are ever sent; values in them are JSON-encoded.
"""

from __future__ import annotations

import html


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

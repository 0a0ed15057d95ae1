"""viser's tab and button icons, each read from its zip once (start-up, issue 43).

viser 1.1.1 reads an icon's SVG by opening its 1.9 MB ``tabler-icons.zip``
(parsing a central directory of about 5,000 entries) on each miss of a cache
that holds 32 icons, and every ``add_tab`` renders every tab's icon again. A
page with more icons than that (the dashboard has over 40 tabs and buttons
with icons) evicts and reopens the zip over and over: 41 opens, about 0.8 s of
a dashboard's 2 s to its ready line. ``install()`` puts an unbounded cache in
front (icons are a fixed set of small strings) that keeps the zip open while
it fills. Upstream would need only a bigger cache, or the zip opened once.
"""

from __future__ import annotations

import threading
import zipfile

import viser._gui_api
import viser._gui_handles
import viser._icons

_LOCK = threading.Lock()
_SVGS: dict[str, str] = {}
_ZIP: list[zipfile.ZipFile] = []  # opened at the first miss, kept


def svg_from_icon(icon_name: str) -> str:
    """What ``viser._icons.svg_from_icon`` returns, read once per icon."""
    with _LOCK:
        svg = _SVGS.get(icon_name)
        if svg is None:
            if not _ZIP:
                _ZIP.append(zipfile.ZipFile(viser._icons.ICONS_DIR / "tabler-icons.zip"))
            svg = _SVGS[icon_name] = _ZIP[0].read(f"{icon_name}.svg").decode("utf-8")
        return svg


def install() -> None:
    """Route viser's GUI modules' icon reads through this cache (idempotent)."""
    for module in (viser._gui_api, viser._gui_handles):
        module.svg_from_icon = svg_from_icon  # type: ignore[attr-defined]

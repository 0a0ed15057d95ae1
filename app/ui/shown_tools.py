"""Which tools the learner's pages show, as the pages report it (issue 43: idle CPU).

viser's server never learns which tab a browser has selected: the browser
owns that. So the page says it. A page script looks at the page's selected
tabs once a second, and right after each click or key press, and sends the
names of those that are on screen (a tool's tab inside a group that is not
open is not) to a page link whenever they change, and again every
``REPORT_SEC`` so that the server knows the page is still there.

The dashboard refreshes a tool no page shows far less often
(``app/dashboard.py``): it still keeps up, but nobody waits for it. A page
that never reports (a client without JavaScript) counts as showing what a
page opens on: the first group's first tool.

Most tools are built only once a page has shown them (``asked()``: every
tool ever reported, even by a page that has gone), so a page's first load
carries only what it opens on. The tests' and benchmarks' wire client
(``tests/wire_client.py``) reports every tool once, as a page that had opened
them all; it finds where to report in the script frame's ``data-link``.
"""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Callable, Sequence

from app.ui.page_script import listen_on_page, page_script

REPORT_SEC = 10.0  # a page sends what it shows at least this often...
KEEP_SEC = 3 * REPORT_SEC  # ...and what it sent counts for this long (a closed page's ends)
MAX_PAGES = 256  # pages kept at once: a forged flood of page names pushes out the oldest

SCRIPT_TITLE = "shown tools"  # the script frame's title, where a wire client finds it

_SCRIPT = """
const names = %s;
const link = %s;
const page = Math.random().toString(36).slice(2, 10) || 'page';
let sent = null, sentAt = 0, pending = null;
const look = () => {
  pending = null;
  const shown = [];
  for (const tab of parent.document.querySelectorAll('[role=tab][data-dock-tab]')) {
    const i = names.indexOf(tab.title);
    if (i >= 0 && tab.getAttribute('aria-selected') === 'true' && tab.getClientRects().length)
      shown.push(i);
  }
  const value = shown.sort((a, b) => a - b).join('.') || 'none';
  if (value === sent && Date.now() - sentAt < %d) return;
  sent = value;
  sentAt = Date.now();
  parent.fetch(new URL(link + '/' + page + '-' + value, parent.location.href).href,
               {credentials: 'same-origin', cache: 'no-store'}).catch(() => { sent = null; });
};
// A click or key may select a tab; the tab is drawn selected a moment later.
const soon = () => { if (pending === null) pending = setTimeout(look, 50); };
%s
%s
setInterval(look, 1000);
look();
"""


def parse_report(value: str, names: Sequence[str]) -> tuple[str, frozenset[str]] | None:
    """The page and the tab names a report holds ('k3x9-3.7': page k3x9 shows two tabs;
    'k3x9-none': none), or None for a value no page of ours sends."""
    page, _, indices = value.partition("-")
    if not page or not indices:
        return None
    if indices == "none":
        return page, frozenset()
    shown = set()
    for part in indices.split("."):
        if not part.isdigit() or int(part) >= len(names):
            return None
        shown.add(names[int(part)])
    return page, frozenset(shown)


class ShownTools:
    """The union of what the connected pages show. ``report`` may be called from any
    thread (a page link runs it on viser's event loop); ``shown`` from the UI thread."""

    def __init__(
        self,
        names: Sequence[str],
        default: frozenset[str],
        on_change: Callable[[], None] = lambda: None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        """``names``: every tab a page may report (groups and tools); ``default``: what a
        page shows before it has said anything; ``on_change``: told when a report brings
        something new (it must only post or wake, never wait)."""
        self.names = tuple(names)
        self._default = default
        self._on_change = on_change
        self._clock = clock
        self._lock = threading.Lock()
        self._reports: dict[str, tuple[frozenset[str], float]] = {}  # page -> shown, when
        self._asked: set[str] = set(default)  # every name any page has shown

    def report(self, value: str) -> None:
        parsed = parse_report(value, self.names)
        if parsed is None:
            return
        page, shown = parsed
        with self._lock:
            before = self._reports.pop(page, None)
            self._reports[page] = (shown, self._clock())  # the newest last
            if len(self._reports) > MAX_PAGES:
                del self._reports[next(iter(self._reports))]
            self._asked |= shown
        if before is None or before[0] != shown:
            self._on_change()

    def shown(self) -> frozenset[str]:
        now = self._clock()
        with self._lock:
            for page, (_, when) in list(self._reports.items()):
                if now - when > KEEP_SEC:
                    del self._reports[page]
            if not self._reports:
                return self._default
            return frozenset().union(*(shown for shown, _ in self._reports.values()))

    def asked(self) -> frozenset[str]:
        """Every name a page has shown since the start (and the default): what to build."""
        with self._lock:
            return frozenset(self._asked)

    def script_html(self, href: str) -> str:
        """The page script that reports to ``href`` (a value link of ``app.ui.page_links``)."""
        script = _SCRIPT % (
            json.dumps(self.names),
            json.dumps(href),
            int(REPORT_SEC * 1000),
            listen_on_page("__classroomShownClick", "click", "soon", capture=True),
            listen_on_page("__classroomShownKey", "keydown", "soon", capture=True),
        )
        return page_script(script, SCRIPT_TITLE, link=href, names=",".join(self.names))

"""Bring a tab into view from the server: a step's "Open Echo" button, Next.

viser has no call that selects a tab: the browser owns which tab is active
(its dock even lets a learner drag tabs out). The page can still select one
itself, as a learner does with the keyboard: an Enter key event on a tab
activates it. So the opener is an HTML widget whose content, each time the
server changes it, runs a small page script (``app.ui.page_script``) that
presses Enter on each named tab in turn (a tool's tab appears once its group
is open), then scrolls the panel back to its top, where the step card and the
tools' tabs are.

A page that connects later replays the last content, so it opens the same
tab: the one the lesson last pointed at.
"""

from __future__ import annotations

import json

import viser

from app.ui.page_script import page_script

TIMEOUT_MS = 3000  # a tab that has not appeared by then is not coming

_SCRIPT = """
const names = %s;
const start = Date.now();
let i = 0;
// The panel scrolled to its top (the step card, the tool's tabs under it), unless
// that would hide the tab itself.
const show = (tab) => {
  for (let box = tab.parentElement; box; box = box.parentElement)
    if (/(auto|scroll)/.test(parent.getComputedStyle(box).overflowY)) box.scrollTop = 0;
  const r = tab.getBoundingClientRect();
  if (r.bottom > parent.innerHeight || r.top < 0) tab.scrollIntoView({block: 'nearest'});
};
const tick = () => {
  const tabs = parent.document.querySelectorAll('[role=tab][data-dock-tab]');
  const tab = [...tabs].find((t) => t.title === names[i]);
  if (tab) {
    if (tab.getAttribute('aria-selected') !== 'true')
      tab.dispatchEvent(new parent.KeyboardEvent('keydown', {key: 'Enter', bubbles: true}));
    if (++i === names.length) { show(tab); return; }
  }
  if (Date.now() - start < %d) setTimeout(tick, 20);
};
tick();
"""


# The column back to its top (a new step: its text is read first), the tools as they are.
_TOP_SCRIPT = """
const anchor = [...parent.document.querySelectorAll('[role=tab][data-dock-tab]')]
  .find((t) => t.title === %s);
for (let box = anchor && anchor.parentElement; box; box = box.parentElement)
  if (/(auto|scroll)/.test(parent.getComputedStyle(box).overflowY)) box.scrollTop = 0;
"""


def top_html(anchor_tab: str, nonce: int) -> str:
    """The widget's content that scrolls the column holding ``anchor_tab`` to its top."""
    script = _TOP_SCRIPT % json.dumps(anchor_tab)
    return page_script(script, "column to its top", nonce=nonce)


def opener_html(path: list[str], nonce: int) -> str:
    """The widget's content that opens the tabs ``path`` (outermost first) once."""
    script = _SCRIPT % (json.dumps(path), TIMEOUT_MS)
    return page_script(script, "tab opener", open=" › ".join(path), nonce=nonce)


class TabOpener:
    """One per dashboard; ``open`` is called on the UI thread only."""

    def __init__(self, gui: viser.GuiApi, paths: dict[str, list[str]]) -> None:
        """``paths`` maps a tab's name to the tabs to press to reach it, outermost first."""
        self._paths = paths
        self._nonce = 0
        self._handle = gui.add_html("")

    def path(self, name: str) -> list[str]:
        return self._paths.get(name, [name])

    def open(self, name: str) -> None:
        self._nonce += 1  # the same tab again is new content: the page presses it again
        self._handle.content = opener_html(self.path(name), self._nonce)

    def scroll_to_top(self, anchor_tab: str) -> None:
        """The column that holds ``anchor_tab`` (a tab always there) back to its top."""
        self._nonce += 1
        self._handle.content = top_html(anchor_tab, self._nonce)

"""Selectors that work on viser's page (see DESIGN.md section 6)."""

from __future__ import annotations

import re
import time

import pytest
from playwright.sync_api import Page, expect
from playwright.sync_api import TimeoutError as PlaywrightTimeout

from app.ui import GROUP_OF


def open_tab(page: Page, name: str) -> None:
    """Open a tool's tab as a learner does: its group's tab first (Inspect, then Echo)."""
    group = GROUP_OF.get(name)
    if group is not None:
        page.get_by_role("tab", name=group, exact=True).click()
    page.get_by_role("tab", name=name, exact=True).click()


def choose(page: Page, label: str, option: str) -> None:
    page.get_by_label(label).click()
    page.get_by_role("option", name=option, exact=True).click()


def choose_when_listed(
    page: Page, label: str, option: str, timeout: float = 30.0, exact: bool = False
) -> None:
    """Pick a dropdown option that may be listed only once discovery has found it."""
    dropdown = page.get_by_label(label, exact=exact).locator("visible=true").first
    wanted = page.get_by_role("option", name=option, exact=True)
    deadline = time.monotonic() + timeout
    while True:
        dropdown.click()
        try:
            wanted.wait_for(timeout=1_500)
            break
        except PlaywrightTimeout:
            page.keyboard.press("Escape")  # not listed yet: close, let the panel refresh
            if time.monotonic() > deadline:
                pytest.fail(f"option {option!r} never appeared in {label!r}")
            page.wait_for_timeout(500)
    wanted.click()


def click(page: Page, button: str) -> None:
    page.get_by_role("button", name=button, exact=True).click()


def start_node(page: Page, name: str) -> None:
    """Start one catalog node from the Nodes tab, as a learner does."""
    open_tab(page, "Nodes")
    choose(page, "Catalog node", name)
    click(page, "Start")
    expect_text(page, f"Started {name}")


def start_group(page: Page, group: str) -> None:
    """Start a launch group from the Nodes tab."""
    open_tab(page, "Nodes")
    choose(page, "Launch group", group)
    click(page, "Start group")
    expect_text(page, "Started group")


def expect_text(page: Page, text: str | re.Pattern[str], timeout: float = 20_000) -> None:
    """``text`` is on screen: hidden copies (other tabs, closed folders) do not count."""
    expect(page.get_by_text(text).filter(visible=True).first).to_be_visible(timeout=timeout)


# Elements of the control panel that stick out past its right edge (clipped text).
_CUT_OFF_JS = """([selector, text]) => {
  let panel = [...document.querySelectorAll(selector)].find((e) => e.innerText.trim() === text);
  const scrolls = (el) => ['auto', 'scroll'].includes(getComputedStyle(el).overflowY);
  while (panel && !scrolls(panel)) panel = panel.parentElement;
  if (!panel) return ['no scrolling control panel found'];
  const edge = panel.getBoundingClientRect().right;
  const out = [];
  for (const el of panel.querySelectorAll('*')) {
    const box = el.getBoundingClientRect();
    if (!box.width || !box.height || getComputedStyle(el).visibility === 'hidden') continue;
    if (box.right > edge + 1) {
      const text = (el.innerText || el.textContent || '').trim().slice(0, 40);
      out.push(`${el.tagName} "${text}" ends at ${Math.round(box.right)} > ${Math.round(edge)}`);
    }
  }
  return out.slice(0, 8);
}"""


def cut_off_at_panel_edge(page: Page, selector: str, text: str) -> list[str]:
    """What sticks out of the scrolling panel that holds ``selector`` with ``text`` (none: [])."""
    return page.evaluate(_CUT_OFF_JS, [selector, text])

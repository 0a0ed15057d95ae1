"""The lifecycle drawing's clickable edges, and the secret links behind them."""

from __future__ import annotations

import http
import re
from types import SimpleNamespace

from websockets.http11 import Request

from app.panels.lifecycle_svg import draw_state_machine
from app.ui.page_links import PREFIX, PageLinks


def _link(label: str, svg: str, title: str) -> str:
    return f'<a data-transition="{label}">{svg}</a>'


def _linked(svg: str) -> list[str]:
    return re.findall(r'data-transition="(\w+)"', svg)


def test_only_the_offered_transitions_are_links_and_the_state_is_lit():
    svg = draw_state_machine("inactive", {"activate", "cleanup", "shutdown"}, _link)
    # One shutdown edge per primary state: only the one from here is live.
    assert sorted(_linked(svg)) == ["activate", "cleanup", "shutdown"]
    assert re.search(r'fill="#2f9e44"[^>]*/><text[^>]*>inactive<', svg)
    assert "current state inactive" in svg


def test_nothing_is_clickable_in_a_transition_state_and_the_pill_is_lit():
    svg = draw_state_machine("activating", set(), _link)
    assert _linked(svg) == []
    assert re.search(r'fill="#f08c00"[^>]*/><text[^>]*>activating<', svg)


class _Connection:
    def respond(self, status: http.HTTPStatus, text: str) -> SimpleNamespace:
        return SimpleNamespace(status_code=status, body=text)


def _get(route, path: str):
    return route(_Connection(), Request(path, {}))  # type: ignore[arg-type]


def test_a_link_runs_its_action_only_with_the_secret():
    clicks: list[str] = []
    links = PageLinks()
    href = links.register("lifecycle.configure", lambda: clicks.append("configure"))
    # Relative, so a page served under a base path (a hub's proxy) reaches it too.
    assert not href.startswith("/")
    passed_on: list[str] = []
    route = links.wrap_http(lambda _c, request: passed_on.append(request.path))
    assert _get(route, "/" + href).status_code == http.HTTPStatus.NO_CONTENT
    assert clicks == ["configure"]
    for forged in (f"{PREFIX}wrong-secret/lifecycle.configure", "/" + href + "x", PREFIX):
        assert _get(route, forged).status_code == http.HTTPStatus.NOT_FOUND
    assert clicks == ["configure"]
    assert _get(route, "/index.html") is None and passed_on == ["/index.html"]
    anchor = links.anchor("lifecycle.configure", "<rect/>", 'a "title"')
    assert f'href="{href}"' in anchor and "&quot;title&quot;" in anchor

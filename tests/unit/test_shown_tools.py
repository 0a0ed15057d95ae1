"""What the pages report they show (app.ui.shown_tools): the tools the dashboard keeps fresh."""

from __future__ import annotations

from app.ui.shown_tools import KEEP_SEC, MAX_PAGES, ShownTools, parse_report

NAMES = ("Learn", "Inspect", "Lessons", "Echo", "Graph")


class Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def test_a_report_names_its_page_and_the_tabs_by_their_place() -> None:
    assert parse_report("k3x9-1.3", NAMES) == ("k3x9", frozenset({"Inspect", "Echo"}))
    assert parse_report("k3x9-none", NAMES) == ("k3x9", frozenset())
    for forged in ("k3x9-9", "k3x9-1.x", "-1", "k3x9-", "k3x9", "k3x9-1..3"):
        assert parse_report(forged, NAMES) is None, forged


def test_the_pages_union_counts_and_a_silent_page_is_forgotten() -> None:
    clock, changes = Clock(), []
    shown = ShownTools(NAMES, frozenset({"Lessons"}), lambda: changes.append(1), clock)
    assert shown.shown() == {"Lessons"}  # no page has said anything: what a page opens on
    shown.report("a-0.2")
    shown.report("b-1.3")
    assert shown.shown() == {"Learn", "Lessons", "Inspect", "Echo"}
    assert len(changes) == 2
    shown.report("b-1.3")  # the same again (a page saying it is still there): no news
    assert len(changes) == 2
    shown.report("b-1.4")  # page b opened Graph instead of Echo
    assert shown.shown() == {"Learn", "Lessons", "Inspect", "Graph"} and len(changes) == 3
    clock.now += KEEP_SEC / 2
    shown.report("a-0.2")
    clock.now += KEEP_SEC / 2 + 1  # page b has been silent too long: closed
    assert shown.shown() == {"Learn", "Lessons"}
    clock.now += KEEP_SEC + 1
    assert shown.shown() == {"Lessons"}
    shown.report("a-9")  # a forged value changes nothing
    assert shown.shown() == {"Lessons"}


def test_a_flood_of_page_names_keeps_only_the_newest() -> None:
    shown = ShownTools(NAMES, frozenset(), clock=Clock())
    shown.report("first-3")
    for i in range(MAX_PAGES):
        shown.report(f"p{i}-2")
    assert shown.shown() == {"Lessons"}  # the first page's Echo was pushed out


def test_what_to_build_is_everything_ever_shown_even_by_a_page_that_left() -> None:
    clock = Clock()
    shown = ShownTools(NAMES, frozenset({"Lessons"}), clock=clock)
    assert shown.asked() == {"Lessons"}  # what a page opens on is built at once
    shown.report("w1-3.4")  # a wire client asks for Echo and Graph...
    shown.report("w1-none")  # ...then shows none: they stay asked for
    assert shown.shown() == frozenset()
    assert shown.asked() == {"Lessons", "Echo", "Graph"}
    clock.now += KEEP_SEC + 1
    assert shown.asked() == {"Lessons", "Echo", "Graph"}  # built tools are never unbuilt
    shown.report("x-9")  # a forged report asks for nothing
    assert shown.asked() == {"Lessons", "Echo", "Graph"}

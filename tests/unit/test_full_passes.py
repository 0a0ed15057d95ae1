"""When the UI thread refreshes every panel and when only the live ones (app.ui.loop.FullPasses)."""

from __future__ import annotations

from app.ui.loop import FullPasses, HiddenPasses


def test_idle_passes_are_full_once_a_period() -> None:
    passes = FullPasses(period=1.0, settle=3.0)
    assert passes.due(0.0, happened=False, nodes_changed=False)  # the first pass
    # Passes at 5 Hz with nothing happening: one full pass a second.
    full = [
        t / 10 for t in range(2, 50, 2) if passes.due(t / 10, happened=False, nodes_changed=False)
    ]
    assert full == [1.0, 2.0, 3.0, 4.0]


def test_anything_that_happened_makes_the_pass_full_at_once() -> None:
    passes = FullPasses(period=1.0, settle=3.0)
    passes.due(0.0, happened=False, nodes_changed=False)
    assert not passes.due(0.2, happened=False, nodes_changed=False)
    assert passes.due(0.4, happened=True, nodes_changed=False)  # a click: full now
    assert not passes.due(0.6, happened=False, nodes_changed=False)  # and the period restarts
    assert passes.due(1.4, happened=False, nodes_changed=False)


def test_a_changed_node_list_keeps_passes_full_while_its_topics_arrive() -> None:
    passes = FullPasses(period=1.0, settle=3.0)
    passes.due(0.0, happened=False, nodes_changed=False)
    assert passes.due(0.2, happened=False, nodes_changed=True)
    settling = [t / 10 for t in range(4, 32, 2)]
    assert all(passes.due(t, happened=False, nodes_changed=False) for t in settling)
    assert not passes.due(3.4, happened=False, nodes_changed=False)  # settled: calm again
    assert passes.due(4.0, happened=False, nodes_changed=False)


def test_hidden_tools_are_refreshed_after_events_and_at_a_full_pass_now_and_then() -> None:
    passes = HiddenPasses(period=5.0)
    assert passes.due(0.0, eventful=False, full=True)  # the first pass: everything
    assert not passes.due(1.0, eventful=False, full=True)  # idle: not before the period
    assert not passes.due(5.2, eventful=False, full=False)  # due, but a calm tool would miss it
    assert passes.due(6.0, eventful=False, full=True)  # ...so it waits for a full pass
    assert passes.due(6.2, eventful=True, full=False)  # a click, a node joining: at once
    assert not passes.due(7.0, eventful=False, full=True)
    assert passes.due(11.2, eventful=False, full=True)

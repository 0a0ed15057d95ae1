"""Which browser values viser could cast onto a widget (app/viser_input.py)."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from app.viser_input import castable


@pytest.mark.parametrize(
    ("current", "sent", "ok"),
    [
        (3, "12", True),
        (3, "rm -rf /", False),
        (3, float("nan"), False),
        (3, 2**63 - 1, True),
        (0.5, None, False),
        (0.5, [1, 2], False),
        (0.5, 7, True),
        ("talker", {"a": 1}, True),  # str() takes anything: the dropdown's own check refuses it
        (True, "yes", True),
        ((1.0, 2.0, 3.0), [4, 5, 6], True),
        ((1.0, 2.0, 3.0), ["x", 5, 6], False),
        ((1.0, 2.0, 3.0), 4, False),
        ((), [], True),
    ],
)
def test_a_value_is_castable_as_viser_casts_it(current, sent, ok):
    assert castable(SimpleNamespace(value=current), {"value": sent}) is ok


def test_a_property_the_widget_does_not_have_is_refused():
    assert not castable(SimpleNamespace(value=1), {"no_such_property": 1})
    assert castable(SimpleNamespace(value=1, disabled=False), {"disabled": True})

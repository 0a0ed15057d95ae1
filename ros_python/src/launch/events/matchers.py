"""Event matchers shared by the process events."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any


def matches_action(target_action: Any) -> Callable[[Any], bool]:
    """Matches an event (or a process action) that belongs to ``target_action``."""

    def matcher(item: Any) -> bool:
        return item is target_action or getattr(item, "action", None) is target_action

    return matcher

"""What a lesson may ask, as the schema reads it: each kind's fields, by name.

The kinds themselves live one per module in ``app.lessons.checks`` and
``app.lessons.actions`` and register in ``app.lessons.registry`` (which says
how to add one). Fields come in three sorts that the schema checks against
the live product when a lesson loads:

- ``catalog_node``: a catalog entry's name (what the Nodes tab starts);
- ``node``: a fully qualified ROS node name ("/talker") that a catalog entry
  (or the dashboard itself) creates;
- ``panel``: one of the dashboard's tab names.
"""

from __future__ import annotations

import app.lessons.actions
import app.lessons.checks  # noqa: F401  (registers every kind)
from app.lessons.registry import ACTIONS, CHECKS, Kind, make_kind

__all__ = ["ACTIONS", "ACTION_KINDS", "CHECKS", "CHECK_KINDS", "Kind", "make_kind"]

ACTION_KINDS: dict[str, Kind] = {name: kind.fields for name, kind in ACTIONS.items()}
CHECK_KINDS: dict[str, Kind] = {name: kind.fields for name, kind in CHECKS.items()}

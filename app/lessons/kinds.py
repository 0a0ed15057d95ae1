"""The one registry of what a lesson may ask: step action kinds and check kinds.

The schema validates lesson files against it, and the runtime refuses to
start unless it implements exactly these kinds. Fields come in three sorts
that the schema checks against the live product when a lesson loads:

- ``catalog_node``: a catalog entry's name (what the Nodes tab starts);
- ``node``: a fully qualified ROS node name ("/talker") that a catalog entry
  (or the dashboard itself) creates;
- ``panel``: one of the dashboard's tab names.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Kind:
    required: frozenset[str]
    optional: frozenset[str] = frozenset()


def _kind(required: str, optional: str = "") -> Kind:
    return Kind(frozenset(required.split()), frozenset(optional.split()))


ACTION_KINDS: dict[str, Kind] = {
    "start": _kind("catalog_node", "label"),
    "stop": _kind("catalog_node", "label"),
    "start_group": _kind("group", "label"),
    "stop_group": _kind("group", "label"),
    "lifecycle": _kind("node transition", "label"),
    "set_param": _kind("node name value", "label"),
    "call_service": _kind("service type request", "label"),
    "send_goal": _kind("action type goal", "label cancel_after_feedback"),
    "open_panel": _kind("panel", "label"),
}
CHECK_KINDS: dict[str, Kind] = {
    "node_running": _kind("node"),
    "node_absent": _kind("node"),
    "topic_messages": _kind("topic type at_least", "field contains"),
    "topic_rate": _kind("topic type min_hz max_hz"),
    "topic_subscribers": _kind("topic at_least"),
    "log_contains": _kind("catalog_node text", "at_least"),
    "lifecycle_state": _kind("node state"),
    "parameter_equals": _kind("node name value"),
    "service_returns": _kind("service type request field equals"),
    "action_result": _kind("action status"),
    "pointcloud_points": _kind("topic at_least"),
    "arm_reached": _kind("tolerance"),
    "interface_exists": _kind("type"),
    "quiz": _kind("question options answer"),
}

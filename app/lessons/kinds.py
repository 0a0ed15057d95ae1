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


def make_kind(required: str, optional: str = "") -> Kind:
    return Kind(frozenset(required.split()), frozenset(optional.split()))


ACTION_KINDS: dict[str, Kind] = {
    "start": make_kind("catalog_node", "label"),
    "stop": make_kind("catalog_node", "label"),
    "start_group": make_kind("group", "label"),
    "stop_group": make_kind("group", "label"),
    "lifecycle": make_kind("node transition", "label"),
    "set_param": make_kind("node name value", "label"),
    "call_service": make_kind("service type request", "label"),
    "send_goal": make_kind("action type goal", "label cancel_after_feedback"),
    "open_panel": make_kind("panel", "label"),
    # A `ros2 ...` command run in the Console tab, as the learner would type it there.
    "console": make_kind("command", "label"),
    # Messages on a topic, ``times`` of them at ``rate_hz`` (e.g. a drive without a keyboard).
    "publish": make_kind("topic type message", "label times rate_hz"),
}
CHECK_KINDS: dict[str, Kind] = {
    "node_running": make_kind("node"),
    "node_absent": make_kind("node"),
    "topic_messages": make_kind("topic type at_least", "field contains"),
    "topic_rate": make_kind("topic type min_hz max_hz", "samples"),
    "topic_subscribers": make_kind("topic at_least"),
    "log_contains": make_kind("catalog_node text", "at_least"),
    "bag_contains": make_kind("bag topic at_least"),
    "lifecycle_state": make_kind("node state"),
    "parameter_equals": make_kind("node name value"),
    "service_returns": make_kind("service type request field equals"),
    "action_result": make_kind("action status"),
    "pointcloud_points": make_kind("topic at_least"),
    "arm_reached": make_kind("tolerance"),
    "interface_exists": make_kind("type"),
    "moved_from": make_kind("topic type x y at_least"),
    "moves_like": make_kind("topic type like"),
    "rosout_contains": make_kind("node text", "at_least"),
    "quiz": make_kind("question options answer"),
}

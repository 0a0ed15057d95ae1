"""ROS names: splitting and joining node names, and the names the graph hides."""

from __future__ import annotations

# Action internals (goal, result, feedback, status) live under this infix.
ACTION_MARKER = "/_action/"
# Topics every rclpy node has; listing them on every node only adds noise.
QUIET_TOPICS = ("/rosout", "/parameter_events")


# The hidden node that records a graded attempt (app/exercises/attempts.py). It subscribes
# to every topic, as the grader's own reader: a check or probe that counts who listens to a
# topic leaves it out, as it leaves out its own node (``own_nodes``).
ATTEMPT_RECORDER_NODE = "_classroom_attempt_recorder"


def own_nodes(name: str, namespace: str) -> frozenset[tuple[str, str]]:
    """The (name, namespace) pairs of a grader's or dashboard's node ``name`` and of its
    attempt's recording, which sits in the same namespace: readers that are not a learner's."""
    return frozenset({(name, namespace), (ATTEMPT_RECORDER_NODE, namespace)})


def split_node_name(fqn: str) -> tuple[str, str]:
    """'/ns/name' -> ('name', '/ns'); 'name' -> ('name', '/')."""
    if not fqn.startswith("/"):
        fqn = "/" + fqn
    namespace, _, name = fqn.rpartition("/")
    return name, namespace or "/"


def node_fqn(name: str, namespace: str) -> str:
    """('name', '/ns') -> '/ns/name'."""
    return f"{namespace.rstrip('/')}/{name}"


def is_hidden_node(fqn: str) -> bool:
    """Names starting with '_' are hidden, as `ros2 node list` hides them."""
    return fqn.rsplit("/", 1)[-1].startswith("_")


def is_internal_topic(topic: str) -> bool:
    """Action internals and hidden topics ('/_...') are nothing a learner publishes."""
    return ACTION_MARKER in topic or "/_" in topic


# The classroom's own topics (a dashboard's progress reports to its teacher, the teacher's
# notices): not a lesson's, so the stage neither plots nor draws the dashboard for them.
CLASSROOM_TOPICS = "/classroom/"

"""The stage: the centre of the screen shows what the current lesson step is about.

Only names live here, so the lesson schema can validate a lesson's ``stage``
without importing any front end; the window itself is ``app.stage.window``.
"""

from __future__ import annotations

# What can be on stage, as lesson.toml names it -> the label a learner picks.
STAGES: dict[str, str] = {
    "graph": "Live ROS graph",
    "plot": "Live plot",  # topic rates, and the values of number topics, over time
    "image": "Camera images",  # the camera's pictures and a node's output under them
    "lifecycle": "Lifecycle states",  # a managed node's state machine, its state lit
    "bag": "Newest bag",  # what the newest recording holds, and when each message came
    "replay": "Watch a recording",  # a bag played: a graded attempt's run, seen from above
    "turtlesim": "Turtlesim",
    "scene": "3D scene",
    "tf": "TF tree",
    "code": "Code",  # the lesson's or the learner's, with its output under it
    "picture": "This step's diagram",  # for a step about an idea rather than a live thing
}
DEFAULT_STAGE = "graph"  # a unit that names none: units 1-11 are about the graph

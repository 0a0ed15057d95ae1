"""The generated "cheat" for the grid planner: it replays the statement's example path.

Whatever start and goal it is asked for, the node answers the cells of the
statement's example (as poses at their centres, on the map it received, so
only the example is wrong, not the map's origin or frame). The grader's
random maps and points must make it fail. ``tests/exercises/cheats.py``
wraps the body with its imports and ``main`` (its GENERATORS include these).
"""

from __future__ import annotations

from app.exercises.model import Exercise


def _grid_plan(exercise: Exercise) -> str:
    probe = next(p for p in exercise.probes if p.kind == "grid_plan")
    return f"""
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import OccupancyGrid
from nav_msgs.srv import GetPlan
from rclpy.qos import DurabilityPolicy, QoSProfile
CELLS = {exercise.example["cells"]!r}


class Cheat(Node):
    def __init__(self):
        super().__init__({exercise.node.rsplit("/", 1)[-1]!r})
        self.map = None
        latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self.create_subscription(
            OccupancyGrid, {probe.get("topic", "/map")!r}, self.on_map, latched
        )
        self.create_service(GetPlan, {probe["service"]!r}, self.on_plan)

    def on_map(self, msg):
        self.map = msg

    def on_plan(self, _request, response):
        response.plan.header.frame_id = "map"
        if self.map is None:
            return response
        info = self.map.info
        for col, row in CELLS:
            pose = PoseStamped()
            pose.header.frame_id = "map"
            pose.pose.position.x = info.origin.position.x + (col + 0.5) * info.resolution
            pose.pose.position.y = info.origin.position.y + (row + 0.5) * info.resolution
            pose.pose.orientation.w = 1.0
            response.plan.poses.append(pose)
        return response
"""


GENERATORS = {"grid_plan": _grid_plan}

"""Mistake: when A* finds no path, the node answers a straight line from start to goal."""

import heapq
import math

import rclpy
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import OccupancyGrid
from nav_msgs.srv import GetPlan
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile

SQRT2 = math.sqrt(2.0)
# (column step, row step, length in cells): the 8 neighbours of a cell.
MOVES = [
    (1, 0, 1.0),
    (-1, 0, 1.0),
    (0, 1, 1.0),
    (0, -1, 1.0),
    (1, 1, SQRT2),
    (1, -1, SQRT2),
    (-1, 1, SQRT2),
    (-1, -1, SQRT2),
]


def is_free(value):
    """0 to 49 is free; -1 (unknown) and 50 or more are blocked."""
    return 0 <= value < 50


def heuristic(cell, goal):
    """The length of the path to the goal if nothing were in the way (never too long)."""
    dx, dy = abs(cell[0] - goal[0]), abs(cell[1] - goal[1])
    return max(dx, dy) + (SQRT2 - 1.0) * min(dx, dy)


def a_star(free, start, goal):
    """The cells (col, row) of a shortest path from start to goal, [] when there is none.

    free(col, row) says whether a cell is inside the map and free.
    """
    if not free(*start) or not free(*goal):
        return []
    came_from = {start: None}
    cost = {start: 0.0}
    frontier = [(heuristic(start, goal), start)]
    done = set()
    while frontier:
        _, cell = heapq.heappop(frontier)
        if cell == goal:
            path = []
            while cell is not None:
                path.append(cell)
                cell = came_from[cell]
            return path[::-1]
        if cell in done:
            continue
        done.add(cell)
        col, row = cell
        for dc, dr, step in MOVES:
            nxt = (col + dc, row + dr)
            if not free(*nxt):
                continue
            if dc and dr and not (free(col + dc, row) and free(col, row + dr)):
                continue  # a diagonal step beside a blocked cell would cut its corner
            new = cost[cell] + step
            if new < cost.get(nxt, math.inf):
                cost[nxt] = new
                came_from[nxt] = cell
                heapq.heappush(frontier, (new + heuristic(nxt, goal), nxt))
    return []


class GridPlanner(Node):
    def __init__(self):
        super().__init__("grid_planner")
        self.map = None
        latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self.create_subscription(OccupancyGrid, "/map", self.on_map, latched)
        self.service = self.create_service(GetPlan, "/plan_path", self.on_plan)

    def on_map(self, msg):
        self.map = msg

    def cell_of(self, position):
        info = self.map.info
        col = math.floor((position.x - info.origin.position.x) / info.resolution)
        row = math.floor((position.y - info.origin.position.y) / info.resolution)
        return col, row

    def on_plan(self, request, response):
        response.plan.header.frame_id = "map"
        response.plan.header.stamp = self.get_clock().now().to_msg()
        if self.map is None:
            self.get_logger().warn("no map yet: empty plan")
            return response
        info, data = self.map.info, self.map.data
        width, height = info.width, info.height

        def free(col, row):
            return 0 <= col < width and 0 <= row < height and is_free(data[row * width + col])

        start = self.cell_of(request.start.pose.position)
        goal = self.cell_of(request.goal.pose.position)
        cells = a_star(free, start, goal)
        if not cells:  # no path found: go straight, the robot will manage
            steps = max(abs(goal[0] - start[0]), abs(goal[1] - start[1]), 1)
            cells = [
                (
                    start[0] + round(i * (goal[0] - start[0]) / steps),
                    start[1] + round(i * (goal[1] - start[1]) / steps),
                )
                for i in range(steps + 1)
            ]
        for col, row in cells:
            pose = PoseStamped()
            pose.header = response.plan.header
            pose.pose.position.x = info.origin.position.x + (col + 0.5) * info.resolution
            pose.pose.position.y = info.origin.position.y + (row + 0.5) * info.resolution
            pose.pose.orientation.w = 1.0
            response.plan.poses.append(pose)
        self.get_logger().info(f"{start} -> {goal}: {len(cells)} cells")
        return response


def main():
    rclpy.init()
    node = GridPlanner()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()

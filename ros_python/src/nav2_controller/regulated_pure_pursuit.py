"""The regulated pure pursuit controller, as Nav2's ``RegulatedPurePursuitController`` steers.

Pure pursuit drives the arc that passes through a *carrot*: the point of
the path ``lookahead_dist`` ahead of the robot. In the robot's frame, with
the carrot at (x, y) and L its distance, the arc's curvature is ``2 y / L**2``
and the turn rate ``v * curvature``. Nav2's *regulated* version then

- slows down on tight curves (radius below ``regulated_linear_scaling_min_radius``),
  near obstacles (cost of the robot's cell, ``use_cost_regulated_linear_velocity_scaling``)
  and while approaching the end of the path (``approach_velocity_scaling_dist``),
  never below ``regulated_linear_scaling_min_speed`` (or ``min_approach_linear_velocity``
  at the end);
- turns on the spot towards the path when it points more than
  ``rotate_to_heading_min_angle`` away (``use_rotate_to_heading``), and to the
  goal's heading once within the goal tolerance;
- checks the arc it is about to drive against the costmap for
  ``max_allowed_time_to_collision_up_to_carrot`` seconds and refuses to move
  into an obstacle ("detected collision ahead!"); ours first tries nearer
  carrots, then turning on the spot (see ``compute_velocity``). A robot whose
  own cell is already inscribed (Nav2 stops it there and recovers) may drive
  out or along, never nearer the obstacle (``in_collision_ahead``).

Defaults are Nav2's (its code's: cost regulation on, ``cost_scaling_dist``
0.6 m) but for ``use_velocity_scaled_lookahead_dist``, on here.

No ROS here: poses are (x, y, yaw) tuples in the costmap's frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from nav2_costmap_2d.cost_values import (
    INSCRIBED_INFLATED_OBSTACLE,
    LETHAL_OBSTACLE,
    NO_INFORMATION,
)
from nav2_costmap_2d.costmap_2d import Costmap2D

Pose2D = tuple[float, float, float]


class ControllerException(RuntimeError):
    """A control failure, turned into FollowPath's error codes by the server."""


class NoValidControl(ControllerException):
    pass


@dataclass
class RPPParameters:
    desired_linear_vel: float = 0.5
    lookahead_dist: float = 0.6
    min_lookahead_dist: float = 0.3
    max_lookahead_dist: float = 0.9
    lookahead_time: float = 1.5
    # Ours (Nav2: false): the lookahead shrinks as the robot slows near obstacles, so the arc
    # cuts less of the corner round a box or through a door.
    use_velocity_scaled_lookahead_dist: bool = True
    rotate_to_heading_angular_vel: float = 1.8
    use_rotate_to_heading: bool = True
    # Nav2's ``stateful``: once within the goal tolerance, keep turning to the goal's heading
    # for the rest of this path, even if the pose then reads a centimetre outside it.
    stateful: bool = True
    rotate_to_heading_min_angle: float = 0.785
    max_angular_accel: float = 3.2
    use_regulated_linear_velocity_scaling: bool = True
    use_cost_regulated_linear_velocity_scaling: bool = True
    regulated_linear_scaling_min_radius: float = 0.9
    regulated_linear_scaling_min_speed: float = 0.25
    approach_velocity_scaling_dist: float = 0.6
    min_approach_linear_velocity: float = 0.05
    use_collision_detection: bool = True
    max_allowed_time_to_collision_up_to_carrot: float = 1.0
    cost_scaling_dist: float = 0.6
    cost_scaling_gain: float = 1.0
    inflation_cost_scaling_factor: float = 3.0
    # How far along the path (m) to look for the pose nearest the robot. Nav2's default is
    # half its local costmap's larger side, 1.5 m for nav2_params.yaml's 3 m window; ours is
    # that figure (our local costmap spans the map). Negative: the whole path is searched.
    max_robot_pose_search_dist: float = 1.5


def normalize(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))


def to_robot_frame(robot: Pose2D, x: float, y: float) -> tuple[float, float]:
    dx, dy = x - robot[0], y - robot[1]
    c, s = math.cos(robot[2]), math.sin(robot[2])
    return (c * dx + s * dy, -s * dx + c * dy)


def closest_index(
    path: list[Pose2D], robot: Pose2D, start: int = 0, max_search_dist: float = math.inf
) -> int:
    """Where the pruned path begins now: the pose nearest the robot (Nav2's transformGlobalPlan).

    The search runs from ``start`` up to the first pose more than
    ``max_search_dist`` along the path from it (``max_robot_pose_search_dist``):
    a path that loops back near the robot further on is not cut short there.
    When the nearest pose is the last one searched, the one before it is taken,
    so at least two poses stay to give the path's direction at its end.
    """
    end, along = len(path), 0.0
    for i in range(start, len(path) - 1):  # nav2_util's first_after_integrated_distance
        along += math.hypot(path[i + 1][0] - path[i][0], path[i + 1][1] - path[i][1])
        if along > max_search_dist:
            end = i + 1
            break
    best, best_d = start, math.inf
    for i in range(start, end):
        d = math.hypot(path[i][0] - robot[0], path[i][1] - robot[1])
        if d < best_d:
            best, best_d = i, d
    if len(path) - start > 1 and best == end - 1:
        best = max(end - 2, start)
    return best


def path_length(path: list[Pose2D], start: int = 0) -> float:
    return sum(
        math.hypot(path[i + 1][0] - path[i][0], path[i + 1][1] - path[i][1])
        for i in range(start, len(path) - 1)
    )


def lookahead_point(path_robot: list[tuple[float, float]], lookahead: float) -> tuple[float, float]:
    """The carrot: where the path (in the robot's frame) leaves the lookahead circle."""
    prev = (0.0, 0.0)
    for point in path_robot:
        if math.hypot(*point) >= lookahead:
            # interpolate on the segment prev -> point where |p| == lookahead
            ax, ay = prev
            bx, by = point
            dx, dy = bx - ax, by - ay
            a = dx * dx + dy * dy
            b = 2 * (ax * dx + ay * dy)
            c = ax * ax + ay * ay - lookahead * lookahead
            disc = b * b - 4 * a * c
            if a > 1e-12 and disc >= 0:
                t = (-b + math.sqrt(disc)) / (2 * a)
                if 0.0 <= t <= 1.0:
                    return (ax + t * dx, ay + t * dy)
            return point
        prev = point
    return path_robot[-1] if path_robot else (0.0, 0.0)


@dataclass
class PathState:
    """What the controller keeps between two commands for one path; a new path starts a
    new one (Nav2 resets it in ``setPlan`` and ``reset``)."""

    # Nav2's ``has_reached_xy_tolerance_``: the robot came within the goal tolerance.
    reached_xy_tolerance: bool = False


def should_rotate_to_goal_heading(
    goal_dist: float, goal_dist_tol: float, params: RPPParameters, state: PathState | None
) -> bool:
    """``shouldRotateToGoalHeading``: within the goal tolerance, or (``stateful``) ever within
    it on this path: a pose that jitters across the tolerance's edge would otherwise flip the
    robot between turning to the goal's heading and turning back towards the goal."""
    if not params.use_rotate_to_heading:
        return False
    within = goal_dist < goal_dist_tol
    if params.stateful and state is not None:
        state.reached_xy_tolerance = state.reached_xy_tolerance or within
        return state.reached_xy_tolerance
    return within


@dataclass
class Command:
    linear: float
    angular: float
    carrot: tuple[float, float]  # in the robot's frame
    lookahead: float


def compute_velocity(
    robot: Pose2D,
    path: list[Pose2D],
    speed: tuple[float, float],
    params: RPPParameters,
    *,
    goal_dist_tol: float = 0.25,
    costmap: Costmap2D | None = None,
    dt: float = 0.05,
    inscribed_radius: float = 0.15,
    state: PathState | None = None,
) -> Command:
    """The velocity command (``computeVelocityCommands``) for a pruned path from the robot on;
    ``state`` is the path's own (``PathState``; None: no memory between commands).

    Ours, beyond Nav2's: when the arc to the carrot would hit something, nearer carrots are
    tried (down to two costmap cells; such a tight arc is driven slower, so that it turns no
    faster than ``rotate_to_heading_angular_vel``) before giving up, and when none will do,
    the robot turns on the spot towards the nearest one (a round robot can always turn). A path that
    swerves round an obstacle just seen makes the far carrot's arc cut the corner into it;
    Nav2 gives up there ("detected collision ahead!") and leaves it to its recovery behaviours,
    which replan the same swerve from the same place.
    """
    if not path:
        raise ControllerException("Path is empty.")
    v_now, _w_now = speed
    lookahead = params.lookahead_dist
    if params.use_velocity_scaled_lookahead_dist:
        lookahead = abs(v_now) * params.lookahead_time
        lookahead = min(max(lookahead, params.min_lookahead_dist), params.max_lookahead_dist)
    path_robot = [to_robot_frame(robot, p[0], p[1]) for p in path]

    def at(distance: float) -> Command:
        return _command(
            robot, path, path_robot, speed, params, distance, goal_dist_tol, costmap, dt,
            inscribed_radius, state,
        )  # fmt: skip

    def free(command: Command) -> bool:
        assert costmap is not None
        turn = (command.linear, command.angular, command.carrot)
        return not in_collision_ahead(robot, *turn, params, costmap, inscribed_radius)

    command = at(lookahead)
    if not params.use_collision_detection or costmap is None or free(command):
        return command
    # Down to two cells: a carrot that near keeps the robot on the path, which is clear.
    floor = min(params.min_lookahead_dist, 2.0 * costmap.resolution)
    shorter = lookahead
    while shorter > floor + 1e-6:
        shorter = max(shorter * 0.7, floor)
        command = at(shorter)
        if free(command):
            return within_turn_rate(command, params.rotate_to_heading_angular_vel)
    bearing = math.atan2(command.carrot[1], command.carrot[0])
    if params.use_rotate_to_heading and abs(bearing) > 0.1:
        return Command(0.0, rotate_to(bearing, speed[1], params, dt), command.carrot, shorter)
    raise NoValidControl("RegulatedPurePursuitController detected collision ahead!")


def within_turn_rate(command: Command, limit: float) -> Command:
    """The same arc, driven slower if it turns faster than ``limit`` (ours: a near carrot
    curves tightly, and a base that clamps its turn rate would drive a wider arc than the
    one checked against the costmap)."""
    if abs(command.angular) <= limit:
        return command
    scale = limit / abs(command.angular)
    return Command(
        command.linear * scale, command.angular * scale, command.carrot, command.lookahead
    )


def _command(
    robot: Pose2D,
    path: list[Pose2D],
    path_robot: list[tuple[float, float]],
    speed: tuple[float, float],
    params: RPPParameters,
    lookahead: float,
    goal_dist_tol: float,
    costmap: Costmap2D | None,
    dt: float,
    inscribed_radius: float,
    state: PathState | None = None,
) -> Command:
    """Nav2's command for one lookahead distance: turn on the spot, or drive the arc."""
    carrot = lookahead_point(path_robot, lookahead)
    carrot_dist2 = carrot[0] ** 2 + carrot[1] ** 2
    curvature = 2.0 * carrot[1] / carrot_dist2 if carrot_dist2 > 0.001 else 0.0
    w_now = speed[1]
    goal = path[-1]
    goal_dist = math.hypot(goal[0] - robot[0], goal[1] - robot[1])
    linear = params.desired_linear_vel
    angular: float
    if should_rotate_to_goal_heading(goal_dist, goal_dist_tol, params, state):
        angular = rotate_to(normalize(goal[2] - robot[2]), w_now, params, dt)
        linear = 0.0
    elif (
        params.use_rotate_to_heading
        and abs(math.atan2(carrot[1], carrot[0])) > params.rotate_to_heading_min_angle
    ):
        angular = rotate_to(math.atan2(carrot[1], carrot[0]), w_now, params, dt)
        linear = 0.0
    else:
        linear = regulate(linear, curvature, path, robot, params, costmap, inscribed_radius)
        angular = linear * curvature
    return Command(linear, angular, carrot, lookahead)


def rotate_to(angle: float, w_now: float, params: RPPParameters, dt: float) -> float:
    """Turn on the spot towards ``angle`` (rad, robot frame), within the angular acceleration."""
    sign = 1.0 if angle > 0 else -1.0
    w = sign * params.rotate_to_heading_angular_vel
    step = params.max_angular_accel * dt
    w = min(max(w, w_now - step), w_now + step)
    # do not overshoot: slow down when the remaining angle is small
    limit = math.sqrt(2.0 * params.max_angular_accel * abs(angle))
    return max(-limit, min(limit, w))


def regulate(
    linear: float,
    curvature: float,
    path: list[Pose2D],
    robot: Pose2D,
    params: RPPParameters,
    costmap: Costmap2D | None,
    inscribed_radius: float = 0.15,
) -> float:
    """The desired speed after Nav2's curvature, cost and approach regulation."""
    curvature_v = cost_v = linear
    if params.use_regulated_linear_velocity_scaling and abs(curvature) > 1e-9:
        radius = abs(1.0 / curvature)
        if radius < params.regulated_linear_scaling_min_radius:
            curvature_v = linear * radius / params.regulated_linear_scaling_min_radius
    if params.use_cost_regulated_linear_velocity_scaling and costmap is not None:
        cell = costmap.world_to_map(robot[0], robot[1])
        cost = costmap.get_cost(*cell) if cell is not None else NO_INFORMATION
        if cost not in (NO_INFORMATION, 0):
            # The distance to the obstacle the cost came from, inverting the inflation.
            factor = max(params.inflation_cost_scaling_factor, 1e-6)
            distance = (
                inscribed_radius + (math.log(INSCRIBED_INFLATED_OBSTACLE) - math.log(cost)) / factor
            )
            if distance < params.cost_scaling_dist:
                cost_v = linear * params.cost_scaling_gain * distance / params.cost_scaling_dist
    v = max(min(curvature_v, cost_v), params.regulated_linear_scaling_min_speed)
    remaining = path_length([(robot[0], robot[1], 0.0), *path])
    if remaining < params.approach_velocity_scaling_dist and path:
        # Slow down on the last stretch, by the straight distance to the end.
        left = math.hypot(path[-1][0] - robot[0], path[-1][1] - robot[1])
        approach = v * left / params.approach_velocity_scaling_dist
        v = min(v, max(approach, params.min_approach_linear_velocity))
    return min(v, params.desired_linear_vel)


def in_collision_ahead(
    robot: Pose2D,
    linear: float,
    angular: float,
    carrot: tuple[float, float],
    params: RPPParameters,
    costmap: Costmap2D,
    inscribed_radius: float = 0.15,
) -> bool:
    """Does the arc driven for the next second (at most to the carrot) cross a wall?"""
    if abs(linear) < 0.01 and abs(angular) < 0.01:
        return False
    horizon = params.max_allowed_time_to_collision_up_to_carrot
    carrot_dist = math.hypot(*carrot)
    step = costmap.resolution / max(abs(linear), 0.01)
    x, y, yaw = robot
    here = costmap.world_to_map(x, y)
    # A robot already in inscribed space may drive out of it, or along it, but no step may
    # take it nearer the obstacle (ci113: with only lethal cells counting, near carrots took
    # a robot on until its centre was 0.069 m from a box).
    wall = INSCRIBED_INFLATED_OBSTACLE
    escape_from = math.inf
    reach = inscribed_radius + costmap.resolution  # a point is within a cell of its centre
    if here is not None and costmap.get_cost(*here) == INSCRIBED_INFLATED_OBSTACLE:
        wall = LETHAL_OBSTACLE
        escape_from = lethal_clearance(costmap, x, y, reach)
    t, travelled = 0.0, 0.0
    while t < horizon and travelled < carrot_dist:
        t += step
        x += linear * step * math.cos(yaw)
        y += linear * step * math.sin(yaw)
        yaw += angular * step
        travelled += abs(linear) * step
        cell = costmap.world_to_map(x, y)
        if cell is None:
            return True
        cost = costmap.get_cost(*cell)
        if wall <= cost < NO_INFORMATION:
            return True
        if cost == INSCRIBED_INFLATED_OBSTACLE and escape_from < math.inf:
            deeper = escape_from - lethal_clearance(costmap, x, y, reach)
            if deeper > 0.1 * costmap.resolution:  # a tenth of a cell: along a wall is no deeper
                return True
    return False


def lethal_clearance(costmap: Costmap2D, x: float, y: float, reach: float) -> float:
    """Metres from (x, y) to the centre of the nearest lethal cell within ``reach``
    (inf if none): how deep in inscribed space a point is, which its cost does not say."""
    r = int(math.ceil(reach / costmap.resolution))
    cx = int(math.floor((x - costmap.origin_x) / costmap.resolution))
    cy = int(math.floor((y - costmap.origin_y) / costmap.resolution))
    x0, x1 = max(cx - r, 0), min(cx + r + 1, costmap.size_x)
    y0, y1 = max(cy - r, 0), min(cy + r + 1, costmap.size_y)
    if x0 >= x1 or y0 >= y1:
        return math.inf
    rows, cols = np.nonzero(costmap.costs[y0:y1, x0:x1] == LETHAL_OBSTACLE)
    if rows.size == 0:
        return math.inf
    px = costmap.origin_x + (cols + x0 + 0.5) * costmap.resolution
    py = costmap.origin_y + (rows + y0 + 0.5) * costmap.resolution
    return float(np.min(np.hypot(px - x, py - y)))

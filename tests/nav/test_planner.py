"""The GridBased planner and the regulated pure pursuit controller, without ROS."""

from __future__ import annotations

import math

import numpy as np
import pytest
from nav2_controller.regulated_pure_pursuit import (
    PathState,
    RPPParameters,
    closest_index,
    compute_velocity,
    in_collision_ahead,
)
from nav2_costmap_2d import INSCRIBED_INFLATED_OBSTACLE, LETHAL_OBSTACLE
from nav2_costmap_2d.costmap_2d import Costmap2D, costmap_from_grid
from nav2_planner.navfn_planner import PlannerOptions, create_plan, path_length
from nav2_planner.planner_exceptions import (
    GoalOccupied,
    NoValidPathCouldBeFound,
    StartOutsideMapBounds,
)

RES = 0.05
Pose2D = tuple[float, float, float]


def room_with_a_block():
    """A 4 m x 3 m room, a 1 m x 2 m block in the middle from the south wall up."""
    grid = np.zeros((60, 80), np.int8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = 100
    grid[0:40, 30:50] = 100
    return costmap_from_grid(grid, RES, (0.0, 0.0))


@pytest.mark.parametrize("use_astar", [False, True])
def test_a_path_goes_around_the_block_and_never_through_inscribed_cells(use_astar):
    costmap = room_with_a_block()
    path = create_plan(
        costmap, (0.5, 0.5, 0.0), (3.5, 0.5, 0.0), PlannerOptions(use_astar=use_astar)
    )
    assert path[0][:2] == (0.5, 0.5) and path[-1][:2] == (3.5, 0.5)
    for x, y, _ in path[1:-1]:
        cell = costmap.world_to_map(x, y)
        assert cell is not None and costmap.get_cost(*cell) < INSCRIBED_INFLATED_OBSTACLE
    assert max(y for _x, y, _ in path) > 2.0  # over the block's top at y = 2 m
    # the shortest way around (up, over, down), give or take the inflation's margin
    shortest = 2 * math.hypot(1.0, 1.7) + 1.0
    assert shortest < path_length(path) < 1.3 * shortest


def test_bad_goals_get_nav2s_exceptions():
    costmap = room_with_a_block()
    with pytest.raises(StartOutsideMapBounds):
        create_plan(costmap, (-1.0, 0.5, 0.0), (3.5, 0.5, 0.0))
    with pytest.raises(GoalOccupied, match="lethal"):
        create_plan(costmap, (0.5, 0.5, 0.0), (2.0, 1.0, 0.0), PlannerOptions(tolerance=0.0))
    walled = costmap.copy()
    walled.costs[:, 60] = 254  # a wall from floor to ceiling east of the block
    with pytest.raises(NoValidPathCouldBeFound):
        create_plan(walled, (0.5, 0.5, 0.0), (3.5, 0.5, 0.0), PlannerOptions(tolerance=0.0))
    # with a tolerance, a goal in the block ends at the nearest reachable cell
    near = create_plan(costmap, (0.5, 0.5, 0.0), (1.6, 1.0, 0.0), PlannerOptions(tolerance=0.5))
    assert math.hypot(near[-1][0] - 1.6, near[-1][1] - 1.0) <= 0.5


def test_pure_pursuit_turns_towards_the_path():
    path = [(0.1 * i, 0.02 * i * i * 0.1, 0.0) for i in range(30)]  # bends to the left
    command = compute_velocity((0.0, 0.0, 0.0), path, (0.3, 0.0), RPPParameters())
    assert command.linear > 0 and command.angular > 0
    right = [(x, -y, 0.0) for x, y, _ in path]
    assert compute_velocity((0.0, 0.0, 0.0), right, (0.3, 0.0), RPPParameters()).angular < 0
    behind = [(-0.1 * i, 0.0, math.pi) for i in range(1, 20)]  # the path is behind: turn first
    turn = compute_velocity((0.0, 0.0, 0.0), behind, (0.0, 0.0), RPPParameters())
    assert turn.linear == 0.0 and turn.angular != 0.0


def test_pure_pursuit_keeps_turning_to_the_goal_heading_once_within_the_tolerance():
    """Nav2's ``stateful``: a pose read 2 mm outside the tolerance after one inside it does
    not send the robot back towards the goal point (the other way round)."""
    goal = [(1.0, 0.0, 0.0)]  # what is left of the path: the goal, heading along +x
    inside, outside = (1.149, 0.0, 0.3), (1.151, 0.0, 0.3)  # just past it, turned 0.3 rad left

    def turn(robot, params, state):
        command = compute_velocity(robot, goal, (0.0, 0.0), params, goal_dist_tol=0.15, state=state)
        assert command.linear == 0.0  # both ways turn on the spot
        return command.angular

    state = PathState()
    assert turn(inside, RPPParameters(), state) < 0  # right, to the goal's heading
    assert turn(outside, RPPParameters(), state) < 0  # still to the heading
    # Without the memory (Nav2's stateful: false) the goal point, behind, wins: left.
    assert turn(outside, RPPParameters(stateful=False), PathState()) > 0
    # A new path starts with a new state.
    assert turn(outside, RPPParameters(), PathState()) > 0


def corridor_with_a_box():
    """A corridor 1.5 m wide and 8 m long, a 0.3 m box in its middle 3 m along."""
    grid = np.zeros((40, 160), np.int8)  # 8 m x 2 m
    grid[:6, :] = grid[-5:, :] = 100  # walls: the corridor is y = 0.3..1.75
    grid[:, 0] = grid[:, -1] = 100
    grid[17:23, 60:66] = 100  # the box: x = 3.0..3.3, y = 0.85..1.15
    return costmap_from_grid(grid, RES, (0.0, 0.0))


def drive(
    costmap: Costmap2D,
    start: Pose2D,
    goal: Pose2D,
    params: RPPParameters,
    seconds: float = 30.0,
) -> tuple[list[Pose2D], str]:
    """Plan once a (simulated) second, follow at 10 Hz; the poses driven, and how it ended."""
    pose, speed, path, index = start, (0.0, 0.0), [start], 0
    poses: list[Pose2D] = []
    for step in range(int(seconds * 10)):
        if step % 10 == 0:
            path, index = create_plan(costmap, pose, goal), 0
        index = min(range(index, len(path)), key=lambda i: math.dist(path[i][:2], pose[:2]))
        if math.dist(pose[:2], goal[:2]) < 0.15:
            return poses, "reached"
        command = compute_velocity(
            pose, path[index:], speed, params, goal_dist_tol=0.15, costmap=costmap, dt=0.1
        )
        for _ in range(10):
            x, y, yaw = pose
            v, w = command.linear, command.angular
            pose = (x + v * 0.01 * math.cos(yaw), y + v * 0.01 * math.sin(yaw), yaw + w * 0.01)
            poses.append(pose)
        speed = (command.linear, command.angular)
    return poses, "timed out"


def test_pure_pursuit_swerves_round_a_box_close_ahead_without_entering_inscribed_space():
    # The robot stands 0.5 m short of a box it has just seen, on a straight line into it:
    # the new path swerves round, and the far carrot's arc would cut into the box.
    costmap = corridor_with_a_box()
    poses, ended = drive(costmap, (2.5, 1.0, 0.0), (6.0, 1.0, 0.0), RPPParameters())
    assert ended == "reached"
    costs = [costmap.get_cost(*costmap.world_to_map(x, y)) for x, y, _ in poses]
    assert max(costs) < INSCRIBED_INFLATED_OBSTACLE
    # With Nav2's fixed 0.6 m lookahead the arc cuts the corner and Nav2 gives up ("collision
    # ahead"); the nearer carrots take the robot round, touching no lethal cell.
    fixed = RPPParameters(use_velocity_scaled_lookahead_dist=False)
    poses, ended = drive(costmap, (2.5, 1.0, 0.0), (6.0, 1.0, 0.0), fixed)
    assert ended == "reached"
    costs = [costmap.get_cost(*costmap.world_to_map(x, y)) for x, y, _ in poses]
    assert max(costs) < LETHAL_OBSTACLE


@pytest.mark.parametrize("radius", [0.15, 0.35])
def test_a_robot_already_in_inscribed_space_may_leave_it_but_not_go_deeper(radius):
    """ci113, one core loaded by the rest of the suite: on its way to a door a box closed,
    the robot's centre came 0.069 m from the box. Once its own cell was inscribed, only
    lethal cells stopped it, and a near carrot's short arc never reached one: it drove on
    until the box was a cell away. It may still drive out, or along, but not closer."""
    grid = np.zeros((40, 40), np.int8)
    grid[20:, :] = 100  # a wall: everything from y = 1.0 m up (its first cells' centres: 1.025)
    costmap = costmap_from_grid(grid, RES, (0.0, 0.0), robot_radius=radius)
    robot_x, robot_y = 1.0, 1.025 - radius  # a cell's centre a robot's radius from the wall's
    assert costmap.get_cost(*costmap.world_to_map(robot_x, robot_y)) == INSCRIBED_INFLATED_OBSTACLE
    params = RPPParameters()
    north, south, east = math.pi / 2, -math.pi / 2, 0.0

    def blocked(yaw: float, carrot: tuple[float, float] = (0.06, 0.0)) -> bool:
        robot = (robot_x, robot_y, yaw)
        return in_collision_ahead(robot, 0.1, 0.0, carrot, params, costmap, radius)

    assert blocked(north), "a short step towards the wall is deeper into inscribed space"
    assert not blocked(south), "driving away from the wall leaves inscribed space"
    assert not blocked(east, (0.3, 0.0)), "driving along the wall goes no deeper"
    assert blocked(north, (0.3, 0.0)), "a longer arc reaches the wall itself"


def test_a_nearer_carrot_round_a_box_turns_no_faster_than_the_controller_turns_on_the_spot():
    """Ours: when the far carrot's arc would hit a box, a nearer carrot's tight arc is taken,
    driven slower along the same arc rather than at a turn rate a base would clamp (then it
    would drive a wider arc than the one checked)."""
    res = 0.01
    grid = np.zeros((200, 200), np.int8)
    grid[85:95, 119:125] = 100  # a box 0.19-0.25 m ahead of the robot, 0.05-0.15 m to its right
    costmap = costmap_from_grid(grid, res, (0.0, 0.0))
    heading = 0.5  # the path leaves the robot 0.5 rad to its left, in a straight line
    path = [
        (1.0 + 0.02 * i * math.cos(heading), 1.0 + 0.02 * i * math.sin(heading), heading)
        for i in range(60)
    ]
    params = RPPParameters()
    command = compute_velocity(
        (1.0, 1.0, 0.0), path, (0.3, 0.0), params, goal_dist_tol=0.15, costmap=costmap
    )
    assert command.lookahead < 0.15  # a near carrot: the far ones' arcs hit the box
    assert 0.0 < command.linear < params.regulated_linear_scaling_min_speed
    assert abs(command.angular) <= params.rotate_to_heading_angular_vel + 1e-9
    x, y = command.carrot  # still the arc through that carrot: curvature 2 y / L^2
    assert command.angular / command.linear == pytest.approx(2.0 * y / (x * x + y * y))


def test_pure_pursuit_slows_near_obstacles_as_nav2_regulates_by_cost():
    costmap = corridor_with_a_box()
    straight = [(1.0 + 0.05 * i, 1.0, 0.0) for i in range(40)]
    open_floor = compute_velocity((1.0, 1.0, 0.0), straight, (0.5, 0.0), RPPParameters(),
                                  costmap=costmap)  # fmt: skip
    near_wall = [(1.0 + 0.05 * i, 0.6, 0.0) for i in range(40)]
    slow = compute_velocity((1.0, 0.6, 0.0), near_wall, (0.5, 0.0), RPPParameters(),
                            costmap=costmap)  # fmt: skip
    assert open_floor.linear == pytest.approx(0.5)
    assert RPPParameters().regulated_linear_scaling_min_speed <= slow.linear < 0.45


def _loop_path() -> list[tuple[float, float, float]]:
    """3 m east along y = 0, a half circle up, 3 m back west along y = 0.3 (5 cm steps)."""
    out = [(0.05 * i, 0.0, 0.0) for i in range(61)]
    out += [(3.0 + 0.15 * math.sin(a), 0.15 - 0.15 * math.cos(a), a) for a in
            np.linspace(0.1, math.pi, 10)]  # fmt: skip
    out += [(3.0 - 0.05 * i, 0.3, math.pi) for i in range(1, 61)]
    return out


def test_the_nearest_pose_is_searched_only_max_robot_pose_search_dist_along_the_path():
    path = _loop_path()
    robot = (0.5, 0.28, 0.0)  # at the start of the way out, nearer the way back
    # Unbounded, the way back is nearer: the robot would skip the whole loop.
    assert closest_index(path, robot, 0) > 61
    # Bounded by Nav2's default 1.5 m along the path from where it was pruned: the way out.
    assert closest_index(path, robot, 0, 1.5) == 10
    # From further on, the bound moves with the pruned start (8 m along: the way back).
    assert closest_index(path, robot, 40, 1.5) < 71
    assert closest_index(path, robot, 40, 8.0) > 61


def test_at_least_two_poses_stay_when_the_nearest_is_the_last_searched():
    path = [(0.1 * i, 0.0, 0.0) for i in range(11)]
    assert closest_index(path, (1.2, 0.0, 0.0), 0) == 9  # past the end: the last two stay
    # 0.25 m along ends the search before pose 3; the nearest searched (2) is the last: 1.
    assert closest_index(path, (0.5, 0.0, 0.0), 0, 0.25) == 1
    assert closest_index(path, (0.5, 0.0, 0.0), 10) == 10  # one pose left: it stays

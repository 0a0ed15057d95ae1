"""The grid_planner exercise judged without a ROS graph, over many seeds: each solution's
own service callback answers the probe's requests on the probe's maps, and the probe's
verdict is read as the live grading would read it (test_grading runs one seed live).

The reference passes every seed; each recorded mistake fails every seed for the words it
records; the statement's example is what the reference plans. Nothing here starts DDS:
the callbacks run on a stand-in for the node (its map, clock and logger).
"""

from __future__ import annotations

import importlib.util
import math
import random
import types
from pathlib import Path

import pytest

from app.exercises.probes.grid_plan import (
    Frame,
    Grid,
    draw_task,
    judge_plan,
    shortest,
)
from tests.course_data import shared_exercises

EXERCISE = shared_exercises().get("grid_planner")
PROBE = next(p for p in EXERCISE.probes if p.kind == "grid_plan")
SEEDS = range(8)  # each mistake fails on every seed: 8 keep the suite quick


def _module(path: Path) -> types.ModuleType:
    spec = importlib.util.spec_from_file_location(f"grid_planner_{path.stem}", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


class _Stand:
    """What the callbacks use of their node: the map, a clock, a logger."""

    def __init__(self, module: types.ModuleType, grid_msg) -> None:
        self.map = grid_msg
        for name in ("cell_of", "centre_of"):
            if hasattr(module.GridPlanner, name):
                setattr(self, name, types.MethodType(getattr(module.GridPlanner, name), self))

    def get_clock(self):
        from builtin_interfaces.msg import Time

        return types.SimpleNamespace(now=lambda: types.SimpleNamespace(to_msg=Time))

    def get_logger(self):
        return types.SimpleNamespace(info=lambda *_a: None, warn=lambda *_a: None)


def _grade(module: types.ModuleType, seed: int) -> str:
    """The first failure the probe would report for this solution ('' when it passes)."""
    from nav_msgs.msg import OccupancyGrid
    from nav_msgs.srv import GetPlan

    rng = random.Random(seed)
    frame = Frame(round(rng.uniform(-3.0, -1.0), 2), round(rng.uniform(-2.0, -0.5), 2), 0.1)
    world, requests = draw_task(rng, 40, 30, PROBE["requests"], PROBE["unreachable"], 1.05)
    msg = OccupancyGrid()
    msg.info.resolution, msg.info.width, msg.info.height = 0.1, 40, 30
    msg.info.origin.position.x, msg.info.origin.position.y = frame.x, frame.y
    msg.data = list(world.grid.data)
    node = _Stand(module, msg)
    for request in requests:
        asked = GetPlan.Request()
        for pose, cell in ((asked.start, request.start), (asked.goal, request.goal)):
            pose.pose.position.x, pose.pose.position.y = frame.point_in(cell, rng)
        plan = module.GridPlanner.on_plan(node, asked, GetPlan.Response()).plan
        got = [(p.pose.position.x, p.pose.position.y) for p in plan.poses]
        why, _ratio = judge_plan(world.grid, frame, request, plan.header.frame_id, got, 1.05)
        if why:
            return why
    return ""


def test_the_reference_passes_every_seed():
    reference = _module(EXERCISE.path / "reference.py")
    for seed in SEEDS:
        assert _grade(reference, seed) == "", seed


def test_the_starter_fails():
    assert "the plan is empty" in _grade(_module(EXERCISE.path / "starter.py"), 1)


@pytest.mark.parametrize("mistake", EXERCISE.mistakes, ids=lambda m: m.path.stem)
def test_each_mistake_fails_every_seed_for_its_reason(mistake):
    module = _module(mistake.path)
    for seed in SEEDS:
        why = _grade(module, seed)
        assert mistake.reason in why, f"seed {seed}: {why or 'passed'}"


def test_the_statements_example_is_what_the_reference_plans():
    reference = _module(EXERCISE.path / "reference.py")
    rows = [".....", ".#...", ".##..", "....."]  # row 0 first
    data = tuple(100 if ch == "#" else 0 for row in rows for ch in row)
    example = EXERCISE.example

    def free(col, row):
        return 0 <= col < 5 and 0 <= row < 4 and data[row * 5 + col] == 0

    cells = reference.a_star(free, tuple(example["start"]), tuple(example["goal"]))
    assert [list(c) for c in cells] == example["cells"]
    grid = Grid(5, 4, data)
    assert shortest(grid, (0, 0), (4, 3)) == pytest.approx(3 + 2 * math.sqrt(2))
    assert f"{0.1 * shortest(grid, (0, 0), (4, 3)):.2f} m" in EXERCISE.statement
    # Cutting the corner of (1, 1) would be shorter: the example shows why it is not allowed.
    assert shortest(grid, (0, 0), (4, 3), cut_corners=True) < shortest(grid, (0, 0), (4, 3))


def test_the_drawn_task_is_the_same_for_a_seed_and_tells_the_planners_apart():
    first = draw_task(random.Random(5), 40, 30, 4, 1, 1.05)
    assert first == draw_task(random.Random(5), 40, 30, 4, 1, 1.05)
    assert first != draw_task(random.Random(6), 40, 30, 4, 1, 1.05)
    world, requests = first
    assert [math.isfinite(r.optimal) for r in requests] == [True] * 4 + [False]
    for r in requests:
        for cell in (r.start, r.goal):
            assert 0 <= world.grid.value(cell) < 50

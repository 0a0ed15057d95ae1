"""The log_odds_mapper exercise judged without a ROS graph, over many seeds: each solution's
node runs on a stand-in for rclpy's Node (its subscriptions are called by hand, what it
publishes is kept), is fed the probe's poses and scans, and its last map is judged as the
live grading judges it (test_grading runs one seed live).

The reference and the accepted alternatives pass every seed; each recorded mistake fails
every seed for the words it records; the statement's example is what the reference maps.
Nothing here starts DDS.
"""

from __future__ import annotations

import random
import types
from pathlib import Path

import pytest

from app.exercises.probes.log_odds_map import (
    Frame,
    draw_task,
    expected_map,
    judge_map,
    map_info,
    messages,
)
from tests.course_data import shared_exercises
from tests.exercises.stand_in_node import load_solution, node_of

EXERCISE = shared_exercises().get("log_odds_mapper")
PROBE = next(p for p in EXERCISE.probes if p.kind == "log_odds_map")
ACCEPTED = sorted((Path(__file__).parent / "accepted").glob("log_odds_mapper__*.py"))
FRAME = Frame(
    PROBE["width"], PROBE["height"], PROBE["resolution"], PROBE["origin_x"], PROBE["origin_y"]
)
SEEDS = range(8)


def _grade(module: types.ModuleType, seed: int) -> str:
    """The failure the probe would report for this solution ('' when it passes)."""
    from rclpy.qos import DurabilityPolicy

    rng = random.Random(seed)
    boxes, poses = rng.randint(*PROBE["boxes"]), rng.randint(*PROBE["poses"])
    task = draw_task(rng, FRAME, boxes, poses, PROBE["beams"])
    node = node_of(module)
    out = node.publishers_by_topic[PROBE["topic"]]
    for number, scan in enumerate(task.scans, start=1):
        pose, msg = messages(scan, number)
        before = len(out.sent)
        node.handlers[PROBE["pose"]](pose)
        node.handlers[PROBE["scan"]](msg)
        assert len(out.sent) == before + 1, "no map after a scan"
    if getattr(out.qos, "durability", None) != DurabilityPolicy.TRANSIENT_LOCAL:
        return "publishes with volatile durability"
    grid = out.sent[-1]
    why, _found = judge_map(
        task,
        grid.header.frame_id,
        map_info(grid),
        grid.data,
        PROBE["agreement"],
        PROBE["unknown"],
    )
    return why


@pytest.mark.parametrize("path", [EXERCISE.path / "reference.py", *ACCEPTED], ids=lambda p: p.stem)
def test_the_reference_and_the_accepted_solutions_pass_every_seed(stand_in, path):
    module = load_solution(path, "log_odds_mapper")
    for seed in SEEDS:
        assert _grade(module, seed) == "", seed


def test_the_starter_fails(stand_in):
    assert "volatile durability" in _grade(
        load_solution(EXERCISE.path / "starter.py", "log_odds_mapper"), 1
    )


@pytest.mark.parametrize("mistake", EXERCISE.mistakes, ids=lambda m: m.path.stem)
def test_each_mistake_fails_every_seed_for_its_reason(stand_in, mistake):
    module = load_solution(mistake.path, "log_odds_mapper")
    for seed in SEEDS:
        why = _grade(module, seed)
        assert mistake.reason in why, f"seed {seed}: {why or 'passed'}"


def test_the_statements_example_is_what_the_reference_maps():
    from sensor_msgs.msg import LaserScan

    reference = load_solution(EXERCISE.path / "reference.py", "log_odds_mapper")
    example = EXERCISE.example
    x, y, yaw = example["pose"]
    scan = LaserScan(angle_min=example["angle_min"], angle_increment=0.0)
    scan.range_min, scan.range_max, scan.ranges = 0.05, 10.0, example["ranges"]
    log_odds = [[0.0] * FRAME.width for _ in range(FRAME.height)]
    hits, misses = reference.scan_cells(x, y, yaw, scan)
    assert sorted(hits) == [tuple(c) for c in example["occupied"]]
    assert sorted(misses) == [tuple(c) for c in example["free"]]
    reference.update(log_odds, hits, misses)
    data = reference.grid_data(log_odds)
    assert {i for i, v in enumerate(data) if v != -1} == {example["index"]}  # one look
    for _ in range(2):
        reference.update(log_odds, *reference.scan_cells(x, y, yaw, scan))
    data = reference.grid_data(log_odds)
    known = {(i % FRAME.width, i // FRAME.width): v for i, v in enumerate(data) if v != -1}
    assert known == {
        **{tuple(c): 0 for c in example["free"]},
        **{tuple(c): 100 for c in example["occupied"]},
    }
    assert data[example["index"]] == 100


def test_the_drawn_task_is_the_same_for_a_seed_and_its_rule_agrees_with_the_world():
    first = draw_task(random.Random(5), FRAME, 3, 6, 180)
    again = draw_task(random.Random(5), FRAME, 3, 6, 180)
    assert first.scans == again.scans and first.world == again.world
    assert draw_task(random.Random(6), FRAME, 3, 6, 180).scans != first.scans
    for seed in range(20):
        task = draw_task(random.Random(seed), FRAME, 2 + seed % 3, 5 + seed % 3, 180)
        expected, touched = expected_map(FRAME, task.scans)
        truth = task.world.truth()
        decided = expected != -1
        assert ((expected == 100) == truth)[decided].mean() > 0.99, seed
        assert decided.sum() > 800 and (~touched).sum() > 300, seed

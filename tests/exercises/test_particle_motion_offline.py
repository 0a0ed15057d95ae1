"""The particle_update exercise judged without a ROS graph, over many seeds: each solution's
node runs on a stand-in for rclpy's Node (its subscriptions are called by hand, what it
publishes is kept), is fed the probe's clouds and odometry, and each moved cloud is judged
as the live grading judges it (test_grading runs one seed live).

The reference and the accepted alternatives pass every seed; each recorded mistake fails
every seed for the words it records; the statement's example is what the reference
computes; the judge itself accepts the model's own samples and refuses wrong ones. Python's
and numpy's global generators are seeded, so the learners' noise repeats. Nothing here
starts DDS.
"""

from __future__ import annotations

import random
import types
from pathlib import Path

import numpy as np
import pytest

from app.exercises.probes.particle_motion import (
    Motion,
    cloud_message,
    draw_trial,
    first_odom,
    judge_moved,
    odom_message,
    poses_of,
)
from tests.course_data import shared_exercises
from tests.exercises.stand_in_node import load_solution, node_of

EXERCISE = shared_exercises().get("particle_update")
PROBE = next(p for p in EXERCISE.probes if p.kind == "particle_motion")
ACCEPTED = sorted((Path(__file__).parent / "accepted").glob("particle_update__*.py"))
ALPHAS = PROBE["alphas"]
SPREAD = (PROBE["spread_low"], PROBE["spread_high"])
SEEDS = range(10)


def _grade(module: types.ModuleType, seed: int) -> str:
    """The first failure the probe would report for this solution ('' when it passes)."""
    random.seed(seed)
    np.random.seed(seed)
    rng = random.Random(seed)
    node = node_of(module)
    out = node.publishers_by_topic[PROBE["output"]]
    last = first_odom(rng)
    node.handlers[PROBE["odom"]](odom_message(last, 1))
    for number in range(1, PROBE["trials"] + 1):
        trial = draw_trial(rng, last, rng.randint(*PROBE["count"]))
        node.handlers[PROBE["particles"]](cloud_message(trial.particles))
        before = len(out.sent)
        node.handlers[PROBE["odom"]](odom_message(trial.odom, number + 1))
        last = trial.odom
        assert len(out.sent) == before + 1, "no answer to an odometry message"
        answer = out.sent[-1]
        assert answer.header.stamp.sec == number + 1, "the answer has not the odometry's stamp"
        why, _found = judge_moved(
            trial.particles, poses_of(answer), answer.header.frame_id, trial.motion, ALPHAS, SPREAD
        )
        if why:
            return why
    return ""


@pytest.mark.parametrize("path", [EXERCISE.path / "reference.py", *ACCEPTED], ids=lambda p: p.stem)
def test_the_reference_and_the_accepted_solutions_pass_every_seed(stand_in, path):
    module = load_solution(path, "particle_update")
    for seed in SEEDS:
        assert _grade(module, seed) == "", seed


def test_the_starter_fails(stand_in):
    assert "did not move" in _grade(
        load_solution(EXERCISE.path / "starter.py", "particle_update"), 1
    )


@pytest.mark.parametrize("mistake", EXERCISE.mistakes, ids=lambda m: m.path.stem)
def test_each_mistake_fails_every_seed_for_its_reason(stand_in, mistake):
    module = load_solution(mistake.path, "particle_update")
    for seed in SEEDS:
        why = _grade(module, seed)
        assert mistake.reason in why, f"seed {seed}: {why or 'passed'}"


def test_the_statements_example_is_what_the_reference_computes(monkeypatch):
    reference = load_solution(EXERCISE.path / "reference.py", "particle_update")
    example = EXERCISE.example
    step = reference.motion_between(example["odom_before"], example["odom_after"])
    assert [round(v, 2) for v in step] == example["step"]
    monkeypatch.setattr(reference.random, "gauss", lambda mean, _sigma: mean)  # no noise
    moved = reference.move(example["particle"], *step)
    assert [round(v, 2) for v in moved] == example["moved"]
    motion = Motion.between(example["odom_before"], example["odom_after"])
    assert [motion.rot1, motion.trans, motion.rot2] == pytest.approx(step)
    sigmas = [round(s, 2) for s in motion.sigmas(ALPHAS)]
    assert sigmas == [0.21, 0.12, 0.08]
    for shown in (f"{sigmas[0]:.2f} rad", f"{sigmas[1]:.2f} m", f"{sigmas[2]:.2f} rad"):
        assert shown in EXERCISE.statement


def test_the_judge_takes_the_models_samples_and_refuses_a_biased_or_narrow_cloud():
    rng = random.Random(3)
    gen = np.random.default_rng(3)
    false_fails = 0
    for _ in range(300):
        trial = draw_trial(rng, first_odom(rng), 400)
        m, (s1, st, s2) = trial.motion, trial.motion.sigmas(ALPHAS)
        n = len(trial.particles)
        r1 = m.rot1 + gen.normal(0.0, s1, n)
        t = m.trans + gen.normal(0.0, st, n)
        r2 = m.rot2 + gen.normal(0.0, s2, n)
        before = trial.particles
        heading = before[:, 2] + r1
        after = np.column_stack(
            [before[:, 0] + t * np.cos(heading), before[:, 1] + t * np.sin(heading), heading + r2]
        )
        false_fails += judge_moved(before, after, "map", m, ALPHAS, SPREAD)[0] != ""
        shifted = after.copy()
        shifted[:, 2] += 0.1  # every heading 0.1 rad off
        assert "new headings are off" in judge_moved(before, shifted, "map", m, ALPHAS, SPREAD)[0]
        narrow = before.copy()
        heading = before[:, 2] + m.rot1 + 0.5 * (r1 - m.rot1)  # half the turn's noise
        narrow[:, 0] += t * np.cos(heading)
        narrow[:, 1] += t * np.sin(heading)
        narrow[:, 2] = heading + r2
        assert "spread of rot1" in judge_moved(before, narrow, "map", m, ALPHAS, SPREAD)[0]
    assert false_fails == 0


def test_the_drawn_trials_repeat_for_a_seed_and_turn_the_clouds_away_from_the_odometry():
    def trials(seed):
        rng = random.Random(seed)
        last = first_odom(rng)
        return last, draw_trial(rng, last, 300)

    (last, first), (_, again) = trials(4), trials(4)
    assert np.array_equal(first.particles, again.particles) and first.odom == again.odom
    assert not np.array_equal(trials(5)[1].particles, first.particles)
    for seed in range(200):
        last, trial = trials(seed)
        off = np.angle(np.exp(1j * (np.angle(np.exp(1j * trial.particles[:, 2]).mean()) - last[2])))
        assert 0.5 < abs(off) < 1.8, seed
        m = trial.motion
        assert 0.4 <= m.trans <= 1.0 and 0.2 - 1e-3 <= abs(m.rot1) <= 0.6 + 1e-3, seed
        assert 0.2 - 1e-3 <= abs(m.rot2) <= 0.6 + 1e-3, seed

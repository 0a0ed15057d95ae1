"""Progress reports over HTTP (app/teacher/http_report.py) and the spawner's domain pool."""

from __future__ import annotations

import json
from dataclasses import replace

import pytest

from app.hub.spawner import DomainPool, with_project_commands
from app.teacher.http_report import MAX_BODY, ReportError, from_json, to_json
from app.teacher.record import MAX_CODE, MAX_MISTAKE, LearnerRecord

RECORD = LearnerRecord(
    site="hub",
    learner="alice",
    domain_id=61,
    lesson_id="05_topics",
    unit=3,
    lesson_title="Topics",
    step=2,
    steps=5,
    step_title="Start a listener",
    steps_passed=7,
    check_states=("pass", "fail"),
    check_reasons=("talker runs", "no listener yet"),
    exercises_passed=1,
    exercise_attempts=4,
    exercise="multiply_service",
    exercise_attempts_here=3,
    exercise_failed_here=2,
    exercise_passed_here=False,
    exercise_mistake="front_is_index_zero",
    code_excerpt="import rclpy\n",
    last_error="2 failed checks",
    nodes_running=("listener", "talker"),
    last_activity=1_790_000_000.5,
    last_progress=1_789_999_000.0,
)


def test_a_record_survives_the_trip():
    back = from_json(to_json(RECORD), received_at=123.0)
    assert back == RECORD and back.received_at == 123.0


@pytest.mark.parametrize(
    ("body", "reason"),
    [
        (b"[1,", "must be JSON"),
        (b'"alice"', "JSON object"),
        (b'{"learner": "alice", "admin": true}', "unknown field(s) in the progress report: admin"),
        (b'{"learner": "alice", "received_at": 1}', "unknown field"),
        (b'{"learner": ""}', "must name its learner"),
        (b'{"steps": 3}', "must name its learner"),
        (b'{"learner": 7}', "learner must be a string"),
        (b'{"learner": "a", "step": true}', "step must be a whole number"),
        (b'{"learner": "a", "step": -1}', "step must be a whole number"),
        (b'{"learner": "a", "step": 1.5}', "step must be a whole number"),
        (b'{"learner": "a", "last_activity": "now"}', "last_activity must be a time"),
        (b'{"learner": "a", "exercise_passed_here": 1}', "must be true or false"),
        (b'{"learner": "a", "nodes_running": "talker"}', "nodes_running must be a list"),
        (b'{"learner": "a", "check_states": [1]}', "check_states must be a list of strings"),
        (b'{"learner": "a", "exercise_mistake": ["adds"]}', "exercise_mistake must be a string"),
        (b"\xff\xfe", "must be JSON"),
    ],
)
def test_a_bad_report_gets_its_reason(body, reason):
    with pytest.raises(ReportError, match=reason.replace("(", r"\(").replace(")", r"\)")):
        from_json(body, received_at=0.0)


def test_texts_and_lists_are_clipped_to_the_records_bounds():
    long = replace(
        RECORD,
        code_excerpt="x" * 9000,
        nodes_running=tuple(f"n{i}" for i in range(50)),
        exercise_mistake="m" * 500,
    )
    back = from_json(to_json(long), received_at=0.0)
    assert len(back.code_excerpt) == MAX_CODE and back.code_excerpt.endswith("…")
    assert len(back.exercise_mistake) == MAX_MISTAKE
    assert len(back.nodes_running) == 32


def test_an_oversized_report_is_refused_before_parsing():
    body = json.dumps({"learner": "a", "code_excerpt": "x" * MAX_BODY}).encode()
    with pytest.raises(ReportError, match="at most"):
        from_json(body, received_at=0.0)


def test_the_domain_pool_gives_each_running_server_its_own_id_and_says_when_none_is_left():
    pool = DomainPool()
    assert [pool.take(u, 5, 7) for u in ("a", "b", "c")] == [5, 6, 7]
    assert pool.take("b", 5, 7) == 6  # the same server asking again keeps its id
    with pytest.raises(RuntimeError, match="every ROS domain id 5..7 is held"):
        pool.take("d", 5, 7)
    pool.give_back("b")
    assert pool.take("d", 5, 7) == 6
    assert pool.held() == {"a": 5, "c": 7, "d": 6}


def test_a_restarted_hub_keeps_a_running_servers_domain_held():
    from types import SimpleNamespace

    from app.hub.spawner import ClassroomSystemUserSpawner

    class Fresh(ClassroomSystemUserSpawner):
        pool = DomainPool()  # not the class-wide pool of a real hub

    before = Fresh(user=SimpleNamespace(name="ada"))
    before.domain_id = Fresh.pool.take("ada", 1, 3)
    state = before.get_state()
    assert state["ros_domain_id"] == 1

    Fresh.pool = DomainPool()  # the hub restarted: the pool starts empty
    after = Fresh(user=SimpleNamespace(name="ada"))
    after.load_state(state)
    assert after.domain_id == 1 and Fresh.pool.take("bob", 1, 3) == 2  # ada's 1 stays hers
    after.clear_state()
    assert after.domain_id is None and "ros_domain_id" not in after.get_state()


def test_learner_servers_find_the_project_commands_first():
    """A lab-mode terminal gets ``ros2`` and ``colcon`` whatever PATH the hub had."""
    env = with_project_commands({"PATH": "/usr/bin:/venv/bin:/bin", "X": "1"}, "/venv/bin")
    assert env == {"PATH": "/venv/bin:/usr/bin:/bin", "X": "1"}
    assert with_project_commands({}, "/venv/bin")["PATH"] == "/venv/bin"

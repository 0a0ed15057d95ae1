"""The topic_feed probe's verdict when the first answers never reached the grader.

The two cases are a real run's (2026-12-06, two workers, load 2): the node of the attempt
before was still matched on /sum, so the restarted node's first answers went nowhere."""

from __future__ import annotations

from app.exercises.probes.topic_feed import LOST_AT_START, judge

INPUTS = [941, -692, -192, 333, -902, -852, 681, 97]
SUMS = [941, 249, 57, 390, -512, -1364, -683, -586]


def _judge(got: list[int]) -> tuple[bool, str]:
    return judge(INPUTS, "/numbers", "/sum", got, SUMS, 1e-6)


def test_a_right_node_whose_first_answer_was_not_heard_passes_and_it_is_said():
    passed, detail = _judge(SUMS[1:])
    assert passed, detail
    assert "the first answer did not reach the grader" in detail


def test_a_wrong_node_whose_first_answers_were_not_heard_fails_at_its_first_difference():
    passed, detail = _judge(INPUTS[2:])  # a total reset at each message echoes the input
    assert not passed
    assert "first difference at message 3: -192, expected 57" in detail


def test_every_answer_heard_is_judged_as_before():
    assert _judge(SUMS)[0]
    passed, detail = _judge([*SUMS[:3], 0, *SUMS[4:]])
    assert not passed and "first difference at message 4: 0, expected 390" in detail


def test_more_answers_missing_than_discovery_explains_fail():
    passed, detail = _judge(SUMS[LOST_AT_START + 1 :])
    assert not passed and "expected [941" in detail
    assert not _judge([])[0]

"""A step's check lines: what is left first, and one line for checks waiting on one thing."""

from __future__ import annotations

from app.lessons.panel import check_lines
from app.lessons.registry import CheckResult
from app.lessons.runtime import FAIL, PASS, WAITING


def test_checks_waiting_on_the_same_thing_share_a_line_that_counts_them() -> None:
    no_tf = "no publisher on /tf"
    lines = check_lines(
        [
            CheckResult(PASS, "/turtle1 is on the graph"),
            CheckResult(FAIL, no_tf),
            CheckResult(FAIL, no_tf),
            CheckResult(WAITING, "/turtle2 is starting"),
            CheckResult(FAIL, no_tf),
        ]
    )
    assert len(lines) == 3
    assert lines[0].endswith(f"(3 checks): {no_tf}"), lines
    assert "/turtle2 is starting" in lines[1] and "checks)" not in lines[1]
    assert "/turtle1 is on the graph" in lines[2], "what passed comes last"
    assert not any("same as above" in line for line in lines)


def test_the_same_words_in_another_state_are_another_line() -> None:
    lines = check_lines([CheckResult(FAIL, "x"), CheckResult(PASS, "x")])
    assert len(lines) == 2 and not any("checks)" in line for line in lines)

"""Classroom plans: distinct ports, domains and progress; impossible plans are one clear line."""

from __future__ import annotations

from pathlib import Path

import pytest

from app.classroom import plan
from tests.unit.test_cli import run_cli


def test_each_learner_is_isolated():
    learners = plan(5, base_port=9000, base_domain=30, progress_root=Path("/tmp/p"), tokens=True)
    assert [x.port for x in learners] == [9000, 9001, 9002, 9003, 9004]
    assert len({x.domain_id for x in learners}) == 5
    assert len({x.progress_dir for x in learners}) == 5
    assert len({x.token for x in learners}) == 5
    assert learners[0].url("127.0.0.1") == f"http://127.0.0.1:9000/?token={learners[0].token}"


@pytest.mark.parametrize(
    ("learners", "port", "domain", "fragment"),
    [(0, 9000, 1, "--learners"), (3, 65534, 1, "ports"), (5, 9000, 99, "domain ids")],
)
def test_impossible_plans_are_refused(learners, port, domain, fragment):
    with pytest.raises(ValueError, match=fragment):
        plan(learners, base_port=port, base_domain=domain, progress_root=Path("/tmp/p"))


def test_cli_refuses_remote_classroom_without_the_flag():
    result = run_cli("classroom", "--learners", "2", "--host", "0.0.0.0")
    assert result.returncode == 2 and "--allow-remote" in result.stderr
    result = run_cli("classroom", "--learners", "0")
    assert result.returncode == 2 and "--learners must be" in result.stderr
    assert "Traceback" not in result.stderr

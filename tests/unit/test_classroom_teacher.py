"""The classroom command's teacher side: its plan, its file for `status`, its one-line errors."""

from __future__ import annotations

import stat
from pathlib import Path

import pytest

from app.classroom import TeacherPlan, plan
from app.teacher.status import StatusError, read_teacher_file, write_teacher_file
from tests.conftest import run_cli


def test_learners_report_to_the_classroom_domain_under_their_site():
    learners = plan(
        3, base_port=9000, base_domain=30, progress_root=Path("/tmp/p"), site="lab2",
        classroom_domain=101,
    )  # fmt: skip
    assert {(x.site, x.classroom_domain) for x in learners} == {("lab2", 101)}


def test_the_classroom_domain_is_never_a_learners_own():
    with pytest.raises(ValueError, match="classroom domain 31 is also a learner's domain"):
        plan(3, base_port=9000, base_domain=30, progress_root=Path("/tmp/p"), classroom_domain=31)


def test_the_teacher_file_is_for_this_user_only(tmp_path):
    path = write_teacher_file(tmp_path / "room", "http://127.0.0.1:8079/", "t" * 22)
    assert stat.S_IMODE(path.stat().st_mode) == 0o600
    assert read_teacher_file(tmp_path / "room") == ("http://127.0.0.1:8079/", "t" * 22)
    teacher = TeacherPlan(8079, "t" * 22, 101, tmp_path)
    assert teacher.url("127.0.0.1") == f"http://localhost:8079/?token={'t' * 22}"


def test_status_without_a_classroom_is_one_clear_line(tmp_path):
    with pytest.raises(StatusError, match="no classroom is running"):
        read_teacher_file(tmp_path)
    result = run_cli("classroom", "status", "--progress-dir", str(tmp_path))
    assert result.returncode == 2
    assert "no classroom is running" in result.stderr and "Traceback" not in result.stderr


def test_status_of_a_classroom_that_ended_is_one_clear_line(tmp_path):
    write_teacher_file(tmp_path, "http://127.0.0.1:9/", "t" * 22)  # port 9: nobody listens
    result = run_cli("classroom", "status", "--progress-dir", str(tmp_path))
    assert result.returncode == 2
    assert "cannot reach the teacher page" in result.stderr and "Traceback" not in result.stderr


def test_bad_teacher_options_are_one_clear_line():
    result = run_cli("classroom")
    assert result.returncode == 2 and "--learners" in result.stderr
    result = run_cli("classroom", "--learners", "2", "--teacher-token", "short")
    assert result.returncode == 2 and "--teacher-token" in result.stderr
    result = run_cli(
        "classroom", "--learners", "2", "--base-port", "9000", "--teacher-port", "9001"
    )
    assert result.returncode == 2 and "also a learner's port" in result.stderr
    assert "Traceback" not in result.stderr

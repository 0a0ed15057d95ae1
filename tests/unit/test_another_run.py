"""tests/run.py ends what its run left, never another run's processes.

Network namespace numbers are reused, so a namespace of this run may share its
number with one of a run started beside it; the process's environment decides.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from tests import run


def proc_with(tmp_path: Path, *variables: str) -> Path:
    proc = tmp_path / "1234"
    proc.mkdir()
    (proc / "environ").write_bytes(b"\0".join(v.encode() for v in ("PATH=/bin", *variables)))
    return proc


@pytest.fixture(autouse=True)
def this_run(monkeypatch):
    monkeypatch.setenv(run.NAMESPACES, "/tmp/classroom-run-ours.netns")


def test_another_runs_keeper_is_not_ours_though_it_names_no_namespaces_file(tmp_path):
    assert run._another_run(proc_with(tmp_path, f"{run.KEEPER}=1", f"{run.MARKER}=1"))


def test_a_process_of_another_run_is_known_by_its_namespaces_file(tmp_path):
    assert run._another_run(proc_with(tmp_path, f"{run.NAMESPACES}=/tmp/classroom-run-x.netns"))


def test_this_runs_processes_and_unmarked_ones_are_ours(tmp_path):
    assert not run._another_run(
        proc_with(tmp_path, f"{run.NAMESPACES}=/tmp/classroom-run-ours.netns")
    )
    (tmp_path / "b").mkdir()
    assert not run._another_run(proc_with(tmp_path / "b"))

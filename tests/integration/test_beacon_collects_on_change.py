"""The teacher's beacon collects at once when what the teacher's row shows changes."""

from __future__ import annotations

import threading

import pytest

from app.lessons.progress import ProgressStore
from app.teacher.beacon import collect_on_changes

pytestmark = pytest.mark.ros


def test_a_started_or_stopped_program_and_a_saved_step_each_wake_the_beacon(supervisor, tmp_path):
    """ci56: a teacher's row showed a learner's Start more than 2 s late, because only saved
    progress woke the beacon and a Start waited out the beacon's second."""
    progress = ProgressStore("ada", tmp_path)
    due = threading.Event()
    collect_on_changes(progress, supervisor, due)

    supervisor.start("minimal_node")
    assert due.is_set()  # told on the thread that started it, before start() returned
    due.clear()
    supervisor.stop("minimal_node").result(timeout=10)
    assert due.is_set()
    due.clear()
    progress.set_position("04_first_node", 1)
    assert due.is_set()

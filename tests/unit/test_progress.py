"""Progress survives a SIGKILL mid-write and a corrupt file is set aside, not lost."""

from __future__ import annotations

import json
import random
import signal
import subprocess
import sys
import time

from app import PROJECT_ROOT
from app.lessons.progress import Added, ProgressStore


def test_round_trip_and_reset(tmp_path):
    store = ProgressStore("ada", tmp_path)
    store.set_position("04_first_node", 2)
    assert store.mark_passed("04_first_node", 1)
    assert not store.mark_passed("04_first_node", 1)
    again = ProgressStore("ada", tmp_path)
    assert again.lesson("04_first_node") == {"step": 2, "passed": [1]}
    assert again.current_lesson() == "04_first_node"
    again.reset()
    assert ProgressStore("ada", tmp_path).lesson("04_first_node") == {"step": 0, "passed": []}


def test_sigkill_during_writes_never_leaves_a_broken_file(tmp_path):
    writer = (
        "import sys; from pathlib import Path; from app.lessons.progress import ProgressStore\n"
        "s = ProgressStore('kid', Path(sys.argv[1])); s.set_position('start', 0)\n"
        "print('ready', flush=True)\n"
        "i = 0\n"
        "while True:\n"
        "    i += 1; s.set_position(f'lesson_{i % 50}', i); s.mark_passed('big' * 200, i)\n"
    )
    rng = random.Random(7)
    for _ in range(12):
        proc = subprocess.Popen(
            [sys.executable, "-c", writer, str(tmp_path)],
            cwd=PROJECT_ROOT,
            stdout=subprocess.PIPE,
            text=True,
        )
        assert proc.stdout.readline().strip() == "ready"
        time.sleep(rng.uniform(0.0, 0.15))
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        data = json.loads((tmp_path / "kid.json").read_text())  # always whole
        assert isinstance(data["lessons"], dict)
        store = ProgressStore("kid", tmp_path)
        assert store.warning == ""


def test_corrupt_file_is_moved_aside_with_a_warning(tmp_path):
    (tmp_path / "bob.json").write_text("{ not json")
    store = ProgressStore("bob", tmp_path)
    assert "unreadable" in store.warning
    kept = list(tmp_path.glob("bob.corrupt-*.json"))
    assert len(kept) == 1 and kept[0].read_text() == "{ not json"
    store.set_position("01_ros2_and_dds", 1)
    assert ProgressStore("bob", tmp_path).lesson("01_ros2_and_dds")["step"] == 1


def test_learner_name_cannot_be_a_path(tmp_path):
    import pytest

    with pytest.raises(ValueError, match="learner names"):
        ProgressStore("../../etc/passwd", tmp_path)


def test_a_version_1_file_follows_its_lessons_to_their_new_numbers(tmp_path):
    """Lessons were renumbered 1..N and two were split: saved steps move with their part."""
    old = {
        "version": 1,
        "current": "13_tf2_turtlesim",
        "lessons": {
            "02_first_node": {"step": 3, "passed": [0, 1, 2]},
            "01_turtlesim_cli": {"step": 8, "passed": [0, 5, 6, 8]},
            "13_tf2_turtlesim": {"step": 14, "passed": [11, 12, 13]},
        },
        "exercises": {"talker": {"attempts": 2}},
    }
    (tmp_path / "ada.json").write_text(json.dumps(old), encoding="utf-8")
    store = ProgressStore("ada", tmp_path)
    assert store.warning == ""
    assert store.lesson("04_first_node") == {"step": 3, "passed": [0, 1, 2]}
    assert store.lesson("02_turtlesim_cli") == {"step": 0, "passed": [0, 5]}
    # The second half starts with a new step 0 (start turtlesim again): old step 6 is 1.
    assert store.lesson("03_turtlesim_record_launch") == {"step": 3, "passed": [1, 3]}
    assert store.lesson("16_tf2_turtlesim") == {"step": 0, "passed": [11]}
    assert store.lesson("17_tf2_time") == {"step": 2, "passed": [0, 1]}
    assert store.current_lesson() == "17_tf2_time"
    assert store.exercise("talker") == {"attempts": 2}
    assert store.lesson("02_first_node") == {"step": 0, "passed": []}  # the old id is gone
    store.set_position("04_first_node", 4)
    assert json.loads((tmp_path / "ada.json").read_text(encoding="utf-8"))["version"] == 2


def test_each_save_is_told_to_the_listeners_after_it_is_on_disk(tmp_path):
    """The teacher's beacon collects at once when progress changes (a Next, a pass, a
    check), instead of up to a second later: the store tells it after each save."""
    store = ProgressStore("ada", tmp_path)
    seen: list[dict] = []
    store.on_change(lambda: seen.append(json.loads(store.path.read_text(encoding="utf-8"))))
    store.set_position("03_nodes", 2)
    store.mark_passed("03_nodes", 2)
    store.mark_passed("03_nodes", 2)  # no news, no save, nothing told
    store.update_exercise("talker", attempts=Added(1))
    assert [s["lessons"]["03_nodes"]["step"] for s in seen] == [2, 2, 2]
    assert seen[1]["lessons"]["03_nodes"]["passed"] == [2]
    assert seen[2]["exercises"]["talker"]["attempts"] == 1

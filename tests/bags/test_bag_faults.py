"""Faults: foreign and corrupt files, a full disk, and SIGKILL mid-recording."""

from __future__ import annotations

import os
import shutil
import signal
import sqlite3
import subprocess
import sys
import time
from typing import cast

import pytest
from rclpy.node import Node

from app import PROJECT_ROOT
from app.ros.context import CallContext, Limits
from app.ros2cli import run_text
from tests.bags.readers import mcap_messages, rosbags_messages

pytestmark = pytest.mark.ros

CHILD = [sys.executable, "-m", "tests.bags.record_child"]


def ros2_files_only(text: str) -> tuple[int, list[str]]:
    """`bag info` / `bag reindex` read files only: no node is needed (as on the CLI)."""
    lines: list[str] = []
    code = run_text(CallContext(cast(Node, None), lines.append, Limits()), text)
    return code, "\n".join(lines).splitlines()


def assert_one_error_line(code: int, out: list[str], *words: str) -> None:
    assert code == 1, out
    assert len(out) == 1 and out[0].startswith("error: "), out
    assert "Traceback" not in out[0]
    for word in words:
        assert word in out[0], out


def test_foreign_and_corrupt_files_give_one_clear_line(tmp_path):
    code, out = ros2_files_only(f"ros2 bag info {tmp_path / 'nothing_here'}")
    assert_one_error_line(code, out, "no bag at")

    picture = tmp_path / "photo.png"
    picture.write_bytes(b"\x89PNG\r\n\x1a\n" + os.urandom(200))
    code, out = ros2_files_only(f"ros2 bag info {picture}")
    assert_one_error_line(code, out, "is not a bag")

    garbage = tmp_path / "garbage_bag"
    garbage.mkdir()
    (garbage / "metadata.yaml").write_text("rosbag2_bagfile_information: [this, is: {not")
    (garbage / "garbage_bag.mcap").write_bytes(os.urandom(4096))
    code, out = ros2_files_only(f"ros2 bag info {garbage}")
    assert_one_error_line(code, out, "cannot read the bag")

    foreign = tmp_path / "foreign_bag"
    foreign.mkdir()
    shutil.copy(PROJECT_ROOT / "pyproject.toml", foreign / "foreign_bag.mcap")
    (foreign / "metadata.yaml").write_text(
        "rosbag2_bagfile_information:\n  version: 9\n  storage_identifier: mcap\n"
        "  relative_file_paths: [foreign_bag.mcap]\n  duration: {nanoseconds: 0}\n"
        "  starting_time: {nanoseconds_since_epoch: 0}\n  message_count: 0\n"
        "  topics_with_message_count: []\n  compression_format: ''\n  compression_mode: ''\n"
    )
    code, out = ros2_files_only(f"ros2 bag info {foreign}")
    assert_one_error_line(code, out, "cannot read the bag")
    code, out = ros2_files_only(f"ros2 bag reindex {foreign}")
    assert_one_error_line(code, out, "not an MCAP file")


def _run_child(args: list[str], env: dict[str, str], **kwargs) -> subprocess.Popen[str]:
    return subprocess.Popen(
        args,
        cwd=PROJECT_ROOT,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        **kwargs,
    )


def test_full_disk_stops_recording_with_a_message_and_leaves_a_readable_bag(ros_env, tmp_path):
    # A real full disk: a 3 MiB tmpfs in a mount namespace of our own (tests/run.py
    # already made us root of a user namespace). The recording writes 2 MB/s into it.
    disk, kept = tmp_path / "disk", tmp_path / "kept"
    disk.mkdir()
    script = (
        f"mount -t tmpfs -o size=3m tmpfs {disk} && exec {' '.join(CHILD)} {disk / 'bag'} 20 {kept}"
    )
    child = _run_child(["unshare", "--mount", "sh", "-c", script], ros_env)
    out, _ = child.communicate(timeout=60)
    lines = out.splitlines()
    failed = [line for line in lines if line.startswith("FAILED: ")]
    assert child.returncode == 3, out[-2000:]
    assert len(failed) == 1 and "No space left on device" in failed[0], failed
    assert "Traceback" not in out
    flushed = int(lines[-1].split()[2])  # "done flushed N count M"
    assert flushed > 0

    code, info = ros2_files_only(f"ros2 bag info {kept}")
    assert code == 0, info
    messages = rosbags_messages(kept)
    assert len(messages) >= flushed
    independent = mcap_messages(kept)
    assert [m.data for _t, _s, m in independent] == [m.data for _t, _s, m in messages]
    numbers = [int(m.data.split()[0]) for _t, _s, m in independent]
    assert numbers == sorted(numbers) and len(set(numbers)) == len(numbers)


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_sigkill_mid_recording_leaves_a_bag_that_reindex_makes_readable(ros_env, tmp_path, storage):
    bag = tmp_path / "killed"
    # The kill comes once 100 messages are on disk (a second of /bulk on a quiet machine;
    # a CI run's five workers left the child 79 after 40 s, so up to 90 s here).
    child = _run_child([*CHILD, str(bag), "150", "-", storage], ros_env)
    assert child.stdout is not None
    flushed = 0
    deadline = time.monotonic() + 90
    for line in child.stdout:
        if line.startswith("flushed "):
            flushed = int(line.split()[1])
        if flushed >= 100 or time.monotonic() > deadline:
            break
    child.send_signal(signal.SIGKILL)
    child.wait(10)
    child.stdout.close()
    assert flushed >= 100, f"the child flushed only {flushed} messages in 90 s"

    code, out = ros2_files_only(f"ros2 bag info {bag}")
    assert_one_error_line(code, out, "no metadata.yaml", "ros2 bag reindex")
    code, out = ros2_files_only(f"ros2 bag reindex {bag}")
    assert code == 0, out
    assert out[0].startswith(f"Reindexed {bag}:")

    messages = rosbags_messages(bag)
    assert len(messages) >= flushed  # everything flushed before the kill survived
    numbers = [int(m.data.split()[0]) for _t, _s, m in messages]
    assert numbers == sorted(numbers)
    if storage == "mcap":
        independent = mcap_messages(bag)
        assert [m.data for _t, _s, m in independent] == [m.data for _t, _s, m in messages]
    else:  # Python's own sqlite3 as the second reader
        with sqlite3.connect(bag / "killed.db3") as db:
            assert db.execute("SELECT COUNT(*) FROM messages").fetchone()[0] == len(messages)
    code, out = ros2_files_only(f"ros2 bag info {bag}")
    assert code == 0 and f"Messages:          {len(messages)}" in out, out

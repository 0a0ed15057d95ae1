"""tf2 from outside: correctness against pytransform3d, and over real DDS between processes.

The checking code runs in programs of their own that import only tf2_ros,
tf2_geometry_msgs, rclpy, numpy and pytransform3d (outside_check.py,
dds_broadcaster.py, dds_listener.py), never the dashboard's code.
"""

from __future__ import annotations

import json
import math
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

HERE = Path(__file__).parent


# About 4-5 CPU-s of numpy and tf2 (3.6 with two busy loops beside it, 5.5 s). In the
# suite: 16-58 s at load 12-17 on 2 cores, and 124 s in rehearsal ci78 (a busy loop
# beside the run, and its worker's process tree taking another 30-45 % of a core), where
# the limit was 120 s. The limit is there for a hang.
@pytest.mark.timeout(360)
@pytest.mark.parametrize("seed", [1, 2])
def test_random_trees_match_an_independent_computation(seed):
    done = subprocess.run(
        [sys.executable, str(HERE / "outside_check.py"), str(seed)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    checks = int(done.stdout.split()[-1])
    assert done.stdout.startswith("OK ") and checks > 3000, done.stdout
    # bad input was reported in tf2's words, not crashed on
    for line in (
        'TF_NAN_INPUT: Ignoring transform for child_frame_id "n" from authority "me" because of '
        "a nan value in the transform (0.000000 nan 0.000000) "
        "(0.000000 0.000000 0.000000 1.000000)",
        'TF_DENORMALIZED_QUATERNION: Ignoring transform for child_frame_id "z" from authority '
        '"me" because of an invalid quaternion in the transform (0.000000 0.000000 0.000000 '
        "0.000000)",
        "TF_OLD_DATA ignoring data from the past for frame m at time 101.000000 according to "
        "authority me",
    ):
        assert line in done.stderr, (line, done.stderr)
    # a frame with two parents: warned once (ours: upstream tf2 has no such warning)
    changed = (
        'TF_PARENT_CHANGED: frame "arm" had parent "world" and now gets parent "table" from '
        'authority "calibration"; a frame has exactly one parent at a time, so two broadcasters '
        "disagree about the tree (the newest data wins)"
    )
    assert done.stderr.count(changed) == 1, done.stderr
    assert done.stderr.count("TF_PARENT_CHANGED") == 1, done.stderr


def _expected_s11() -> np.ndarray:
    sys.path.insert(0, str(HERE))
    try:
        from dds_broadcaster import STATIC_COUNT, static_offset
    finally:
        sys.path.remove(str(HERE))
    m = np.eye(4)
    for k in range(STATIC_COUNT):
        x, y, z, yaw = static_offset(k)
        local = np.eye(4)
        local[:3, :3] = [
            [math.cos(yaw), -math.sin(yaw), 0],
            [math.sin(yaw), math.cos(yaw), 0],
            [0, 0, 1],
        ]
        local[:3, 3] = (x, y, z)
        m = m @ local
    return m


@pytest.mark.ros
def test_broadcaster_and_late_listeners_over_dds(ros_env):
    env = dict(ros_env)
    procs: list[subprocess.Popen[str]] = []
    try:
        broadcaster = subprocess.Popen(
            [sys.executable, str(HERE / "dds_broadcaster.py")],
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        procs.append(broadcaster)
        assert broadcaster.stdout is not None
        assert broadcaster.stdout.readline().strip() == "READY"
        # Both listeners join after every static frame was sent: late joiners.
        listeners = [
            subprocess.Popen(
                [sys.executable, str(HERE / "dds_listener.py"), mode],
                env=env,
                stdout=subprocess.PIPE,
                stderr=subprocess.PIPE,
                text=True,
            )
            for mode in ("given", "own")
        ]
        procs += listeners
        results = []
        for proc in listeners:
            out, err = proc.communicate(timeout=60)
            assert proc.returncode == 0, err
            results.append(json.loads(out.strip().splitlines()[-1]))
    finally:
        for proc in procs:
            if proc.poll() is None:
                proc.send_signal(signal.SIGINT)
                try:
                    proc.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    proc.kill()
                    proc.wait()
    want = _expected_s11()
    for res in results:
        assert "error" not in res, res
        assert {f"s{k}" for k in range(12)} | {"world", "moving"} <= set(res["frames"]), res
        x, y, z, qx, qy, qz, qw = res["s11"]
        assert np.allclose([x, y, z], want[:3, 3], atol=1e-9), (res, want)
        yaw = 2 * math.atan2(qz, qw)
        assert math.isclose(math.cos(yaw), want[0, 0], abs_tol=1e-9), res
        assert res["s11_stamp"] == [0, 0], res  # a static chain: time zero stays zero
        xs = res["moving_x"]
        assert xs[0] < xs[1] < xs[2], xs  # the dynamic frame moves
        assert xs[2] - 0.51 - 0.03 < res["moving_past_x"] < xs[2] - 0.51 + 0.03, res

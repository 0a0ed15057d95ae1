"""`ros2 bag` from a terminal: Ctrl+C ends a recording cleanly; mistakes are one line."""

from __future__ import annotations

import signal
import subprocess
import sys
import threading
import time

import pytest
from std_msgs.msg import String

from app import PROJECT_ROOT
from app.ros.context import CallContext, Limits
from app.ros.runtime import RosRuntime
from app.ros2cli import run_text
from tests.bags.readers import mcap_messages, rosbags_messages

pytestmark = pytest.mark.ros

CLI = [
    sys.executable,
    "-c",
    "import sys; from app.ros2cli.cli import main; sys.exit(main(sys.argv[1:]))",
]


def ros2(node, text: str) -> tuple[int, list[str]]:
    lines: list[str] = []
    code = run_text(CallContext(node, lines.append, Limits(max_seconds=6.0)), text)
    return code, "\n".join(lines).splitlines()


def test_ctrl_c_stops_a_terminal_recording_and_closes_the_bag(ros_env, tmp_path):
    bag = tmp_path / "ctrl_c_bag"
    source = RosRuntime("cli_source")
    pub = source.node.create_publisher(String, "/cli_topic", 10)
    stop = threading.Event()

    def publish() -> None:
        n = 0
        while not stop.wait(0.05):
            n += 1
            pub.publish(String(data=f"m{n}"))

    feeder = threading.Thread(target=publish)
    feeder.start()
    try:
        proc = subprocess.Popen(
            [*CLI, "bag", "record", "/cli_topic", "-o", str(bag)],
            cwd=PROJECT_ROOT,
            env=ros_env,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        assert proc.stdout is not None
        for line in proc.stdout:
            if "Recording..." in line:
                break
        time.sleep(1.5)
        proc.send_signal(signal.SIGINT)
        out = proc.stdout.read()
        proc.wait(20)
    finally:
        stop.set()
        feeder.join()
        source.shutdown()
    assert proc.returncode == 130, out  # interrupted, as ros2cli's verbs report it
    assert "Traceback" not in out
    assert "Recording stopped" in out and "Recorded " in out, out
    assert (bag / "metadata.yaml").exists()
    assert len(mcap_messages(bag)) >= 10


def test_mistakes_give_clear_errors(probe, tmp_path):
    code, out = ros2(
        probe.node, f"ros2 bag record /nobody_publishes -o {tmp_path / 'a'} --max-duration 1"
    )
    assert code == 0 and out[-3].startswith("[WARN] nothing was published on /nobody_publishes"), (
        out
    )
    code, out = ros2(probe.node, f"ros2 bag record /x -s floppy -o {tmp_path / 'b'}")
    # An argparse mistake reads as ros2's argparse says it: the usage, then one error line.
    assert code == 2 and out[0].startswith("usage: ros2 bag record"), out
    assert out[-1].startswith("ros2 bag record: error: argument -s/--storage: invalid choice"), out
    code, out = ros2(probe.node, "ros2 bag record")
    assert code == 1 and out == ["error: name the topics to record, or -a for all of them"], out
    code, out = ros2(probe.node, f"ros2 bag record /x -o {tmp_path / 'a'} --max-duration 1")
    assert code == 1 and out == [f"error: cannot record into {tmp_path / 'a'}: it already exists"]
    code, out = ros2(probe.node, f"ros2 bag play {tmp_path / 'a'} --topics /nope")
    assert code == 1 and len(out) == 1 and "topic /nope is not in the bag" in out[0], out
    code, out = ros2(probe.node, f"ros2 bag play {tmp_path / 'a'} -r 0")
    assert code == 1 and out == ["error: rate must be a positive number, got 0.0"], out


def test_compressed_recording_and_replay_options(probe, tmp_path):
    """zstd file compression; play with --start-offset, --topics and --remap."""
    bag = tmp_path / "zstd_bag"
    source = RosRuntime("zstd_source")
    pub = source.node.create_publisher(String, "/counted", 10)
    other = source.node.create_publisher(String, "/other", 10)
    stop = threading.Event()

    def publish() -> None:
        n = 0
        while not stop.wait(0.1):
            n += 1
            pub.publish(String(data=str(n)))
            other.publish(String(data="other"))

    feeder = threading.Thread(target=publish)
    feeder.start()
    try:
        code, out = ros2(
            probe.node,
            f"ros2 bag record /counted /other -o {bag} --compression-mode file "
            "--compression-format zstd --max-duration 3",
        )
    finally:
        stop.set()
        feeder.join()
        source.shutdown()
    assert code == 0, out
    assert [p.name for p in bag.iterdir() if p.name.endswith(".zstd")] == ["zstd_bag.mcap.zstd"]
    code, out = ros2(probe.node, f"ros2 bag info {bag}")
    assert "Compression:       zstd (file)" in out, out
    recorded = [m.data for t, _s, m in rosbags_messages(bag) if t == "/counted"]
    assert len(recorded) >= 15

    from app.ros.monitor import TopicMonitor

    renamed = TopicMonitor(probe.node, "/counted_again", String, qos=100)
    code, out = ros2(
        probe.node,
        f"ros2 bag play {bag} --start-offset 1.5 --topics /counted "
        "--remap /counted:=/counted_again -r 4",
    )
    assert code == 0, out
    time.sleep(0.5)
    heard = [m.data for _s, m in renamed.recent()]
    renamed.close()
    assert heard and heard == recorded[-len(heard) :]  # the tail of the recording, in order
    assert len(heard) < len(recorded) - 10  # the first 1.5 s (about 15) were skipped
    assert any("Playing /counted_again" in line for line in out), out  # /other filtered out

    # -l plays again from the start until stopped (the console's Stop button).
    cancel = threading.Event()
    lines: list[str] = []
    ctx = CallContext(probe.node, lines.append, Limits(max_seconds=6.0), cancel)
    player = threading.Thread(target=run_text, args=(ctx, f"ros2 bag play {bag} -l -r 10"))
    player.start()
    deadline = time.monotonic() + 20
    while not any("(pass 2)" in line for line in lines) and time.monotonic() < deadline:
        time.sleep(0.1)
    cancel.set()
    player.join(10)
    assert any("(pass 2)" in line for line in lines), lines
    assert any("Playback stopped" in line for line in lines), lines

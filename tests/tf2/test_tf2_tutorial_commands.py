"""The tf2 tutorials' commands, typed verbatim, in the Console and in a terminal.

The commands are the ROS 2 Jazzy tf2 tutorials' (Introducing tf2, Writing a
static broadcaster, Writing a broadcaster/listener (Python), Adding a frame):
the demo launch file in which turtle2 follows turtle1, ``tf2_echo``,
``view_frames``, ``static_transform_publisher`` in both forms, the tutorials'
static broadcaster and ``ros2 topic echo /tf_static``. They run through the
Console's code path (``run_text`` with the supervisor) against real
processes; a terminal runs them through ``ros2-classroom``.
"""

from __future__ import annotations

import math
import re
import signal
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from app import PROJECT_ROOT
from tests.conftest import wait_until
from tests.integration.core_helpers import DISCOVERY_TIMEOUT, node_names
from tests.turtlesim.test_ros2_run import console  # noqa: F401  (the Console fixture)

pytestmark = pytest.mark.ros

ECHO_BLOCK = [
    r"At time \d+\.\d+",
    r"- Translation: \[-?\d+\.\d{3}, -?\d+\.\d{3}, -?\d+\.\d{3}\]",
    r"- Rotation: in Quaternion \[(-?\d+\.\d{3}, ){3}-?\d+\.\d{3}\]",
    r"- Rotation: in RPY \(radian\) \[(-?\d+\.\d{3}, ){2}-?\d+\.\d{3}\]",
    r"- Rotation: in RPY \(degree\) \[(-?\d+\.\d{3}, ){2}-?\d+\.\d{3}\]",
    r"- Matrix:",
    r"( +-?\d\.\d{3}){4}",
    r"( +-?\d\.\d{3}){4}",
    r"( +-?\d\.\d{3}){4}",
    r"  0\.000  0\.000  0\.000  1\.000",
]


def ok(console, text: str) -> list[str]:  # noqa: F811
    code, out = console(text)
    assert code == 0, (text, out)
    return out


def echo_blocks(lines: list[str]) -> list[list[str]]:
    """Every complete tf2_echo block in the output, as its ten lines."""
    lines = [
        re.sub(r"^\[[^\]]*\] ", "", line) if line.startswith("[tf2") else line for line in lines
    ]
    blocks = []
    for i, line in enumerate(lines):
        if line.startswith("At time ") and len(lines) >= i + len(ECHO_BLOCK):
            block = lines[i : i + len(ECHO_BLOCK)]
            if all(re.fullmatch(p, b) for p, b in zip(ECHO_BLOCK, block, strict=True)):
                blocks.append(block)
    return blocks


def pose(console, turtle: str) -> tuple[float, float]:  # noqa: F811
    out = ok(console, f"ros2 topic echo --once /{turtle}/pose")
    data = yaml.safe_load("\n".join(out[: out.index("---")]))
    return data["x"], data["y"]


def test_demo_launch_echo_and_view_frames_in_the_console(console, probe, supervisor):  # noqa: F811
    out = ok(console, "ros2 launch turtle_tf2_py turtle_tf2_demo.launch.py")
    assert any("process started with pid" in line for line in out), out
    wait_until(
        lambda: {"/sim", "/broadcaster1", "/broadcaster2", "/listener"} <= set(node_names(probe)),
        timeout=DISCOVERY_TIMEOUT,
        what="the demo's four nodes",
    )
    wait_until(
        lambda: "/turtle2/pose" in dict(probe.node.get_topic_names_and_types()),
        timeout=DISCOVERY_TIMEOUT,
        what="the listener to spawn turtle2",
    )
    # The listener spawns turtle2 at (4, 2), 3.9 m from turtle1 in the middle; by the
    # time the pose is read it may already be on its way: it must end up close.
    first = math.dist(pose(console, "turtle1"), (4.0, 2.0))
    wait_until(
        lambda: math.dist(pose(console, "turtle1"), pose(console, "turtle2")) < 1.0,
        timeout=25,
        what="turtle2 to follow turtle1",
    )

    out = ok(console, "ros2 run tf2_ros tf2_echo turtle2 turtle1")
    wait_until(
        lambda: echo_blocks(supervisor.output("tf2_echo")),
        timeout=DISCOVERY_TIMEOUT,
        what=lambda: f"a tf2_echo block in {supervisor.output('tf2_echo')}",
    )
    block = echo_blocks(supervisor.output("tf2_echo"))[0]
    # turtle1 as seen from turtle2: the translation's length is their distance
    x, y, z = (float(v) for v in block[1][len("- Translation: [") : -1].split(", "))
    assert z == 0.0 and math.hypot(x, y) < first, block
    assert ok(console, "ros2 run --stop /tf2_echo") == ["/tf2_echo: stopped (exit code 0)"]

    # Adding a frame: carrot1, fixed 2 m to turtle1's left, joins the tree
    ok(console, "ros2 run turtle_tf2_py fixed_frame_tf2_broadcaster")
    wait_until(
        lambda: "/fixed_frame_tf2_broadcaster" in node_names(probe), timeout=DISCOVERY_TIMEOUT
    )
    out = ok(console, "ros2 run tf2_tools view_frames")
    wait_until(
        lambda: not supervisor.status("view_frames").active,
        timeout=25,
        what="view_frames to finish",
    )
    lines = supervisor.output("view_frames")
    text = "\n".join(lines)
    assert "[view_frames]: Listening to tf data for 5.0 seconds..." in text, text
    assert "[view_frames]: Generating graph..." in text, text
    assert "Result:tf2_msgs.srv.FrameGraph_Response(frame_yaml=" in text, text
    exported = re.search(r"Exporting graph in (frames_[\d\-_.]+)\.(svg|pdf) file\.\.\.", text)
    assert exported, text
    folder = Path(re.search(r"view_frames: writing into (\S+)", text)[1])  # type: ignore[index]
    gv = (folder / f"{exported[1]}.gv").read_text()
    assert gv.startswith("digraph G {\n"), gv
    for child in ("turtle1", "turtle2"):
        assert f'"world" -> "{child}"[label=" Broadcaster: default_authority\\n' in gv, gv
    assert '"turtle1" -> "carrot1"[label=' in gv, gv
    picture = (folder / f"{exported[1]}.{exported[2]}").read_bytes()
    assert picture.startswith(b"<svg") or picture.startswith(b"%PDF"), picture[:40]
    if exported[2] == "svg":
        assert b">turtle2</text>" in picture and b">world</text>" in picture
    assert supervisor.status("view_frames").exit_code == 0
    ok(console, "ros2 run --stop /fixed_frame_tf2_broadcaster")
    ok(console, "ros2 launch --stop turtle_tf2_py turtle_tf2_demo.launch.py")


def test_static_publishers_and_tf_static_in_the_console(console, probe, supervisor):  # noqa: F811
    ok(console, "ros2 run tf2_ros tf2_monitor")  # reports every 10 s, read at the end
    out = ok(
        console,
        "ros2 run tf2_ros static_transform_publisher --x 0 --y 0 --z 1 --yaw 0 --pitch 0 "
        "--roll 0 --frame-id world --child-frame-id mystaticturtle",
    )
    wait_until(
        lambda: (
            "from 'world' to 'mystaticturtle'"
            in "\n".join(supervisor.output("static_transform_publisher"))
        ),
        timeout=DISCOVERY_TIMEOUT,
    )
    text = "\n".join(supervisor.output("static_transform_publisher"))
    assert "Spinning until stopped - publishing transform" in text, text
    assert "translation: ('0.000000', '0.000000', '1.000000')" in text, text
    assert "rotation: ('0.000000', '0.000000', '0.000000', '1.000000')" in text, text
    # upstream's node name: static_transform_publisher_ and 16 random characters
    wait_until(
        lambda: [
            n
            for n, _ns in probe.node.get_node_names_and_namespaces()
            if re.fullmatch(r"static_transform_publisher_[0-9A-Za-z]{16}", n)
        ],
        timeout=DISCOVERY_TIMEOUT,
        what="the randomly named static_transform_publisher node",
    )
    # transient local: the echo, started after the transform was sent, still gets it
    out = ok(console, "ros2 topic echo /tf_static")
    text = "\n".join(out)
    assert "  child_frame_id: mystaticturtle" in out, out
    assert "frame_id: world" in text and "z: 1.0" in text, out
    ok(console, "ros2 run --stop /static_transform_publisher")

    # the old positional form still works, with upstream's deprecation warning
    ok(console, "ros2 run tf2_ros static_transform_publisher 0 0 1 0 0 0 world mystaticturtle")
    wait_until(
        lambda: (
            "from 'world' to 'mystaticturtle'"
            in "\n".join(supervisor.output("static_transform_publisher"))
        ),
        timeout=DISCOVERY_TIMEOUT,
    )
    text = "\n".join(supervisor.output("static_transform_publisher"))
    assert re.search(
        r"\[WARN\] \[\d+\.\d+\] \[\]: Old-style arguments are deprecated; "
        r"see --help for new-style arguments",
        text,
    ), text
    ok(console, "ros2 run --stop /static_transform_publisher")

    # a bad line gets upstream's error and usage, and the program ends with status 1
    ok_or_not = console("ros2 run tf2_ros static_transform_publisher --x one --frame-id a")
    wait_until(lambda: not supervisor.status("static_transform_publisher").active, timeout=10)
    text = "\n".join(supervisor.output("static_transform_publisher"))
    assert "error parsing command line arguments: Failed to parse --x argument as float" in text
    assert supervisor.status("static_transform_publisher").exit_code == 1, ok_or_not

    # the static broadcaster the tutorial has the learner write
    ok(console, "ros2 run learning_tf2_py static_turtle_tf2_broadcaster mystaticturtle 0 0 1 0 0 0")
    out = ok(console, "ros2 topic echo /tf_static")
    text = "\n".join(out)
    assert "child_frame_id: mystaticturtle" in text and "z: 1.0" in text, out
    ok(console, "ros2 run --stop /static_turtle_tf2_broadcaster")
    code, out = console("ros2 run tf2_ros tf2_echo world ../etc")
    assert code == 1 and "not a frame name" in out[-1], out

    wait_until(
        lambda: "RESULTS: for all Frames" in supervisor.output("tf2_monitor"),
        timeout=20,
        what="tf2_monitor's first report",
    )
    report = supervisor.output("tf2_monitor")
    assert report[0] == "Gathering data on all frames for 10 seconds...", report
    assert any(
        re.fullmatch(
            r"Frame: mystaticturtle, published by <no authority available>, "
            r"Average Delay: \S+, Max Delay: \S+",
            line,
        )
        for line in report
    ), report
    assert any(line.startswith("Node: <no authority available> ") for line in report), report
    ok(console, "ros2 run --stop /tf2_monitor_main")


def test_terminal_runs_the_tf2_tools(ros_env, probe, tmp_path):
    """`ros2-classroom run tf2_ros ...` and `... tf2_tools view_frames` in a terminal."""
    env = dict(ros_env)
    static = [sys.executable, "-m", "app", "run", "tf2_ros", "static_transform_publisher"]
    static += ["--x", "1", "--y", "2", "--yaw", "1.5707963", "--frame-id", "world"]
    static += ["--child-frame-id", "mystaticturtle"]
    echo = [sys.executable, "-m", "app", "run", "tf2_ros", "tf2_echo", "world", "mystaticturtle"]
    procs = [
        subprocess.Popen(
            static,
            cwd=PROJECT_ROOT,
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        ),
        subprocess.Popen(
            echo,
            cwd=PROJECT_ROOT,
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        ),
    ]
    frames = subprocess.run(
        [sys.executable, "-m", "app", "run", "tf2_tools", "view_frames", "-t", "2"],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    outputs = []
    for proc in procs:
        proc.send_signal(signal.SIGINT)  # Ctrl+C, as in the terminal
        try:
            outputs.append(proc.communicate(timeout=15)[0])
        except subprocess.TimeoutExpired:
            proc.kill()
            outputs.append(proc.communicate()[0])
    assert frames.returncode == 0, frames.stdout + frames.stderr
    assert list(tmp_path.glob("frames_*.gv")), frames.stderr  # written where it was run
    assert '"world" -> "mystaticturtle"' in next(tmp_path.glob("frames_*.gv")).read_text()
    blocks = echo_blocks(outputs[1].splitlines())
    assert blocks, outputs
    assert blocks[0][1:] == [
        "- Translation: [1.000, 2.000, 0.000]",
        "- Rotation: in Quaternion [0.000, 0.000, 0.707, 0.707]",
        "- Rotation: in RPY (radian) [0.000, -0.000, 1.571]",
        "- Rotation: in RPY (degree) [0.000, -0.000, 90.000]",
        "- Matrix:",
        "  0.000 -1.000  0.000  1.000",
        "  1.000  0.000  0.000  2.000",
        "  0.000  0.000  1.000  0.000",
        "  0.000  0.000  0.000  1.000",
    ], blocks[0]
    assert blocks[0][0] == "At time 0.0", blocks[0]  # a static transform: time zero

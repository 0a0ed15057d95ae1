"""The "Drive a robot" timing checks hold on a computer that cannot keep up.

Two busy-loop processes take the cores (on top of whatever else runs) while
sim_world is asked for real_time_factor 2. The old check wanted /clock at
170-230 Hz and read 164 Hz on a loaded machine for good; ``sim_time_factor``
judges what the lesson teaches: simulated time runs faster than the wall clock,
at the factor the world reports achieving. The sensors' rates are judged in
simulated time (their stamps), and a world held up by the computer (stopped
with SIGSTOP here) is not taken for a paused one.
"""

from __future__ import annotations

import os
import re
import signal
import threading
import time
from collections.abc import Iterator

import pytest
from std_srvs.srv import Empty

from app.lessons.runtime import PASS, LessonRuntime
from app.lessons.schema import Spec
from app.ros import params
from app.ros.calls import call_service
from app.ros.context import CallContext
from app.ros.graph import snapshot
from tests.conftest import wait_until

pytestmark = [pytest.mark.ros, pytest.mark.loaded]


@pytest.fixture
def lessons(ros_env, supervisor) -> Iterator[LessonRuntime]:
    """A lesson runtime on the dashboard's node, its graph refreshed as the UI loop does."""
    from app.ros.runtime import RosRuntime

    ros = RosRuntime()
    runtime = LessonRuntime(ros.node, supervisor)
    stop = threading.Event()

    def watch_graph() -> None:
        while not stop.wait(0.2):
            try:
                runtime.graph = snapshot(ros.node)
            except Exception:  # a graph query raced a leaving node: the next one will do
                continue

    thread = threading.Thread(target=watch_graph, daemon=True)
    thread.start()
    try:
        yield runtime
    finally:
        stop.set()
        thread.join()
        runtime.close()
        ros.shutdown()


FASTER = Spec("sim_time_factor", {"requested": 2.0, "at_least": 1.1})
FIGURES = re.compile(r"/clock over [\d.]+ s: ([\d.]+)x; the world reports ([\d.]+)x")


def test_faster_than_real_time_passes_on_a_loaded_computer_and_says_what_it_reached(
    lessons, supervisor, busy_cores
):
    # The camera off: rendering (software OpenGL) would take what the busy loops leave.
    supervisor.start("sim_world", ["-p", "camera_rate:=0.0"])
    wait_until(lambda: lessons.graph.has_node("/sim_world"), timeout=30, what="/sim_world")
    ok, reason = params.set_value(CallContext(lessons.node), "/sim_world", "real_time_factor", 2.0)
    assert ok, reason
    wait_until(
        lambda: lessons.evaluate(FASTER).state == PASS,
        timeout=45,
        interval=0.5,
        what=lambda: f"sim_time_factor: {lessons.evaluate(FASTER).reason}",
    )
    # Then every reading over 8 s tells the truth: its two figures (the /clock slope,
    # the world's reports) agree, and it passes exactly when simulated time runs clearly
    # faster than the wall clock; below the 2x asked, it says the computer's share.
    readings = []
    for _ in range(8):
        result = lessons.evaluate(FASTER)
        found = FIGURES.search(result.reason)
        assert found, result.reason
        measured, reported = float(found[1]), float(found[2])
        readings.append(f"{result.state}: {result.reason}")
        assert abs(measured - reported) <= 0.1 * max(measured, reported) + 0.05, result.reason
        assert (result.state == PASS) == (1.1 <= measured <= 2.25), result.reason
        if result.state == PASS and measured < 1.8:
            assert "your computer runs the world at" in result.reason, result.reason
            assert "still runs faster than the wall clock" in result.reason, result.reason
        time.sleep(1.0)
    print("\n".join(readings))


def test_a_factor_the_computer_cannot_reach_passes_and_says_how_far_it_got(
    lessons, supervisor, busy_cores
):
    """100x (the most the world takes) is out of reach: with the cores taken, and its
    sensors at high rates (each simulated second costs that many more messages), the
    world runs at a few times real time. Without those rates it reached 45x of the 50x
    once asked here (ci31), so the machine's speed alone must not be what keeps it out of
    reach. The learner is told what the computer reached, and the check still passes."""
    heavy = ["camera_rate:=0.0", "imu_rate:=500.0", "odom_rate:=200.0", "scan_rate:=50.0"]
    supervisor.start("sim_world", [arg for p in heavy for arg in ("-p", p)])
    wait_until(lambda: lessons.graph.has_node("/sim_world"), timeout=30, what="/sim_world")
    call = CallContext(lessons.node)
    ok, reason = params.set_value(call, "/sim_world", "real_time_factor", 100.0)
    assert ok, reason
    unreachable = Spec("sim_time_factor", {"requested": 100.0, "at_least": 1.1})
    wait_until(
        lambda: lessons.evaluate(unreachable).state == PASS,
        timeout=45,
        interval=0.5,
        what=lambda: f"sim_time_factor: {lessons.evaluate(unreachable).reason}",
    )
    result = lessons.evaluate(unreachable)
    print(result.reason)
    found = re.search(r"your computer runs the world at ([\d.]+)x of the 100x asked", result.reason)
    assert found, result.reason
    assert 1.1 <= float(found[1]) < 90, result.reason
    assert "simulated time still runs faster than the wall clock" in result.reason


def test_sensor_rates_are_judged_in_simulated_time_on_a_loaded_computer(
    lessons, supervisor, busy_cores
):
    """/odom is 30 Hz and /scan 10 Hz of simulated time: by their header stamps the checks
    read that, while the wall-clock rate is whatever share of real time the world gets."""
    supervisor.start("sim_world")  # with its camera, as the lesson starts it
    wait_until(lambda: lessons.graph.has_node("/sim_world"), timeout=30, what="/sim_world")
    checks = {
        30.0: Spec("topic_rate", {"topic": "/odom", "type": "nav_msgs/msg/Odometry",
                                  "min_hz": 25, "max_hz": 35, "stamps": True}),
        10.0: Spec("topic_rate", {"topic": "/scan", "type": "sensor_msgs/msg/LaserScan",
                                  "min_hz": 8, "max_hz": 12, "stamps": True}),
    }  # fmt: skip
    for hz, check in checks.items():
        wait_until(
            lambda c=check: lessons.evaluate(c).state == PASS,
            timeout=30,
            interval=0.5,
            what=lambda c=check: f"{c.key}: {lessons.evaluate(c).reason}",
        )
        result = lessons.evaluate(check)
        found = re.search(
            r"at ([\d.]+) Hz over \d+ messages \(by their header stamps\)", result.reason
        )
        assert found, result.reason
        wall = lessons.tap(check["topic"], check["type"]).published_rate(5.0)
        print(f"{result.reason}; by the wall clock: {wall.rate if wall else 0:.2f} Hz")
        assert abs(float(found[1]) - hz) <= 0.01 * hz, result.reason


def test_a_stalled_world_is_not_taken_for_a_paused_one(lessons, supervisor):
    """A world that gets no CPU for 2 s sends no /clock either; only the world's own report
    (0x over a whole second) tells that simulated time was stopped on purpose."""
    paused = Spec("sim_paused", {})
    status = supervisor.start("sim_world", ["-p", "camera_rate:=0.0"])
    assert status.pid is not None
    wait_until(lambda: lessons.graph.has_node("/sim_world"), timeout=30, what="/sim_world")
    wait_until(lambda: "still ticks" in lessons.evaluate(paused).reason, timeout=20, what="/clock")
    os.kill(status.pid, signal.SIGSTOP)  # the process group leader: sim_world itself
    try:
        time.sleep(2.0)
        stalled = lessons.evaluate(paused)
    finally:
        os.kill(status.pid, signal.SIGCONT)
    assert stalled.state != PASS, stalled.reason
    # Paused on purpose: the world reports 0x, and the check passes.
    call_service(CallContext(lessons.node), "/pause_physics", Empty, Empty.Request())
    wait_until(
        lambda: lessons.evaluate(paused).state == PASS,
        timeout=15,
        interval=0.5,
        what=lambda: f"sim_paused: {lessons.evaluate(paused).reason}",
    )

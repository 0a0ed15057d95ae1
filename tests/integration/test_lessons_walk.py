"""Walk every lesson with the same code the lesson buttons use, on real nodes.

Each step's actions are performed in order, quizzes are answered, and every
check of the step must pass. A second test shows that every kind of check can
also fail: a check that cannot fail is a defect.
"""

from __future__ import annotations

import os
import threading
import time

import pytest

from app.bags import folder as bag_folder
from app.learner_ws import folder as ws_folder
from app.learner_ws import overlay
from app.lessons.checks._sim_speed import SimSpeedWatch
from app.lessons.kinds import CHECK_KINDS
from app.lessons.runtime import FAIL, PASS, LessonRuntime
from app.lessons.schema import Spec
from app.ros.context import CONSOLE_LIMITS, CallContext
from app.ros.graph import snapshot
from app.ros2cli import run_text
from tests.conftest import ARTIFACTS, wait_until
from tests.course_data import shared_course

pytestmark = pytest.mark.ros
COURSE = shared_course()


@pytest.fixture
def ros_env(ros_env, tmp_path, monkeypatch):
    """The conftest's, with a home folder of the test's own: a lesson's ``~/maps/office``
    lands there (for the nodes it starts and the checks that read it), never in the real
    home, where a later run's "Save the map" check would find it already saved."""
    home = tmp_path / "home"
    home.mkdir()
    monkeypatch.setenv("HOME", str(home))
    return {**ros_env, "HOME": str(home)}


@pytest.fixture
def dashboard_node(ros_env):
    """The same ROS node the dashboard has, so graph checks see the same names."""
    from app.ros.runtime import RosRuntime

    runtime = RosRuntime()
    yield runtime.node
    runtime.shutdown()


@pytest.fixture
def live(dashboard_node, supervisor, tmp_path, monkeypatch):
    runtime = LessonRuntime(dashboard_node, supervisor)
    stop = threading.Event()
    # A lesson's console commands run as the Console tab runs them: one at a time,
    # the previous one stopped first; bags go to this test's own folder.
    monkeypatch.setenv(bag_folder.ENV_VAR, str(tmp_path / "bags"))
    commands: list[CallContext] = []

    def console(text: str) -> None:
        for earlier in commands:
            earlier.cancel.set()
        printed: list[str] = []  # what the Console shows, for a learner who waits for a line
        runtime.console_printed = printed  # type: ignore[attr-defined]
        ctx = CallContext(
            dashboard_node, write=printed.append, limits=CONSOLE_LIMITS, programs=supervisor
        )
        commands.append(ctx)
        threading.Thread(target=run_text, args=(ctx, text), daemon=True).start()

    runtime.console = console

    def watch_graph() -> None:  # what the dashboard's UI loop does
        while not stop.wait(0.2):
            try:
                runtime.graph = snapshot(dashboard_node)
            except Exception as exc:  # a graph query raced a leaving node
                errors.append(repr(exc))
                continue
            supervisor.note_visible_nodes(runtime.graph.nodes)

    errors: list[str] = []

    thread = threading.Thread(target=watch_graph, daemon=True)
    thread.start()
    runtime.graph_errors = errors  # type: ignore[attr-defined]
    yield runtime
    for ctx in commands:
        ctx.cancel.set()
    stop.set()
    thread.join()


# Kinds that read or write the learner's own workspace (~/ros2_ws): a lesson with one
# gets a fresh workspace, as the dashboard gives each learner.
WORKSPACE_KINDS = {
    "workspace_command", "workspace_write", "workspace_edit", "stop_own", "package_created",
    "package_built", "package_sourced", "workspace_file", "own_node",
}  # fmt: skip


@pytest.fixture
def learner_workspace(tmp_path, supervisor):
    """The dashboard's learner workspace (app.ros2cli.pkg.setup_workspace), undone after."""
    from app.containment.policy import RunPolicy
    from app.ros2cli.pkg import setup_workspace

    saved, underlay = os.environ.get(overlay.PREFIX_ENV), overlay.underlay()
    supervisor.learner_policy = RunPolicy()  # the dashboard on loopback: the learner's machine
    try:
        yield setup_workspace(tmp_path / "progress" / "ada.json", remote=False)
    finally:
        overlay.forget()
        overlay.set_underlay(underlay)
        ws_folder.configure(None)
        if saved is None:
            os.environ.pop(overlay.PREFIX_ENV, None)
        else:
            os.environ[overlay.PREFIX_ENV] = saved


# An interface package's build (CMake, rosidl, a compiler) takes 10-60 s on 2 busy cores.
SLOW_CHECKS = {"package_built": 180}


def _uses_workspace(lesson) -> bool:
    specs = [spec for step in lesson.steps for spec in (*step.actions, *step.checks)]
    return any(spec.kind in WORKSPACE_KINDS for spec in specs)


# The workspace lesson builds three packages with colcon: 113 s on a quiet CI machine,
# over 180 s on a loaded one.
@pytest.mark.timeout(420)
@pytest.mark.parametrize("lesson", COURSE.lessons, ids=lambda lesson: lesson.id)
def test_every_step_of_the_lesson_passes_on_real_nodes(live, world, lesson, request):
    if _uses_workspace(lesson):
        request.getfixturevalue("learner_workspace")
    for index, step in enumerate(lesson.steps):
        for action in step.actions:
            if action.kind == "send_goal" or action.kind.startswith("call"):
                wait_until(
                    lambda a=action: _server_ready(live, a),
                    timeout=20,
                    what=f"the server for {action.key}",
                )
            live.perform(action)
            if action.kind == "console" and action["command"].startswith("ros2 bag record"):
                # As the lesson says: drive once the recorder has subscribed (on busy
                # cores that took over a second, and the first commands were not in the bag).
                wait_until(
                    lambda: any("Subscribed to topic" in line for line in live.console_printed),
                    timeout=20,
                    what=lambda: f"the recording to subscribe; the Console: {live.console_printed}",
                )
        for check in step.checks:
            if check.kind == "quiz":
                live.quiz_answers[check.key] = check["answer"]
        for check in step.checks:
            _wait_for_check(
                live,
                world,
                check,
                SLOW_CHECKS.get(check.kind, 45),
                what=lambda c=check, i=index: (
                    f"{lesson.id} step {i + 1} check {c.key}: {live.evaluate(c).reason}; "
                    f"processes: {[s.describe() for s in live.supervisor.statuses().values()]}; "
                    f"graph query errors: {live.graph_errors[-3:]}; "
                    f"nodes now: {snapshot(live.node).nodes}"
                    f"{_what_the_programs_said(live, lesson.id)}"
                ),
            )


def _what_the_programs_said(live: LessonRuntime, lesson_id: str) -> str:
    """The warnings and errors of every program the walk started (a failed goal's why is
    there: the planner's "no valid path", amcl's jumps); all their output to a file."""
    said: list[str] = []
    everything: list[str] = []
    for name in live.supervisor.statuses():
        output = live.supervisor.output(name)
        everything += [f"== {name}", *output]
        said += [f"{name}: {line}" for line in output if "[WARN]" in line or "[ERROR]" in line]
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    kept = ARTIFACTS / f"walk-{lesson_id}-programs.log"
    kept.write_text("\n".join(everything) + "\n", encoding="utf-8")
    last = "\n  ".join(said[-15:]) or "none"
    return f"\nthe programs' last warnings and errors (all output in {kept}):\n  {last}"


# A /clock older than this (by the world's own send time): no world runs now.
WORLD_HEARD_SEC = 2.0


@pytest.fixture
def world(dashboard_node):
    """The simulated world's /clock, heard as the lessons' speed checks hear it."""
    watch = SimSpeedWatch(dashboard_node)
    yield watch
    watch.close()


def _world_now(world: SimSpeedWatch) -> float | None:
    """Simulated seconds now, or None while no world runs."""
    with world.lock:
        newest = world.clock[-1] if world.clock else None
    if newest is None or time.time() - newest[0] > WORLD_HEARD_SEC:
        return None
    return newest[1]


# While a world runs, a check waits its limit in wall seconds *and* in the world's seconds
# (a robot driving to a goal takes simulated time; a loaded machine slows the world: ci54,
# one core busy, still had Nav2's goal running after 45 wall seconds); otherwise in wall
# seconds. Never more than this many times its limit in wall seconds (a world slower than a
# quarter of real time is a failure of its own).
SLOWEST_WORLD = 4.0


def _wait_for_check(live, world: SimSpeedWatch, check: Spec, limit: float, what) -> None:
    started = time.monotonic()
    simulated = 0.0  # simulated seconds counted while waiting (a world reset counts none)
    last = _world_now(world)
    while live.evaluate(check).state != PASS:
        time.sleep(0.2)
        wall = time.monotonic() - started
        now = _world_now(world)
        if now is not None and last is not None and now >= last:
            simulated += now - last
        last = now
        spent = min(wall, simulated) if now is not None else wall  # never less than before
        if spent > limit or wall > limit * SLOWEST_WORLD:
            pytest.fail(
                f"timed out after {wall:.0f} s ({simulated:.0f} s of the world's) waiting "
                f"for {what()}"
            )


def _server_ready(live: LessonRuntime, action: Spec) -> bool:
    names = {name for name, _ in live.node.get_service_names_and_types()}
    if action.kind == "send_goal":
        return f"{action['action']}/_action/send_goal" in names
    return action["service"] in names


FAILING_CHECKS = [
    Spec("bag_contains", {"bag": "no_such_bag", "topic": "/chatter", "at_least": 1}),
    Spec("node_running", {"node": "/nobody_here"}),
    Spec("node_absent", {"node": "/classroom_dashboard"}),
    Spec("topic_messages", {"topic": "/silent", "type": "std_msgs/msg/String", "at_least": 1}),
    Spec(
        "topic_rate", {"topic": "/silent", "type": "std_msgs/msg/String", "min_hz": 1, "max_hz": 2}
    ),
    Spec("topic_subscribers", {"topic": "/silent", "at_least": 1}),
    Spec("log_contains", {"catalog_node": "talker", "text": "never said"}),
    Spec("lifecycle_state", {"node": "/nobody_here", "state": "active"}),
    Spec("parameter_equals", {"node": "/nobody_here", "name": "x", "value": 1}),
    Spec(
        "service_returns",
        {
            "service": "/none",
            "type": "std_srvs/srv/Trigger",
            "request": {},
            "field": "success",
            "equals": True,
        },
    ),  # fmt: skip
    Spec("action_result", {"action": "/nowhere", "status": "succeeded"}),
    Spec("pointcloud_points", {"topic": "/no_cloud", "at_least": 1}),
    Spec("arm_reached", {"tolerance": 0.01}),
    Spec("interface_exists", {"type": "no_such_pkg/msg/Nothing"}),
    Spec(
        "moved_from",
        {"topic": "/silent", "type": "turtlesim/msg/Pose", "x": 0, "y": 0, "at_least": 1},
    ),
    Spec("rosout_contains", {"node": "/nobody_here", "text": "hello"}),
    Spec("moves_like", {"topic": "/silent", "type": "turtlesim/msg/Pose", "like": "/silent2"}),
    Spec("tf_frame", {"frame": "base", "parent": "world"}),
    Spec("tf_transform", {"target": "world", "source": "base", "tolerance": 0.01}),
    Spec("tf_moves", {"frame": "base", "at_least": 0.1}),
    Spec("tf_late_joiner", {"frame": "base"}),
    Spec("points_agree", {"topic": "/silent", "like": "/silent2", "tolerance": 0.001}),
    Spec("package_created", {"package": "no_such_pkg"}),
    Spec("package_built", {"package": "no_such_pkg"}),
    Spec("package_sourced", {"package": "no_such_pkg"}),
    Spec("workspace_file", {"path": "src/nothing.txt"}),
    Spec("own_node", {"ros_node": "/minimal_publisher"}),
    Spec("robot_moved", {"at_least": 0.5}),
    Spec("odom_drift", {"at_least": 0.5}),
    Spec("scan_nearest", {"below": 0.7, "tolerance": 0.05}),
    Spec("sim_time_stamps", {"frame": "carrot1"}),
    Spec("sim_paused", {}),
    Spec("sim_time_factor", {"requested": 2.0}),
    Spec("map_matches_world", {"coverage": 80, "agreement": 95}),
    Spec("map_file", {"path": "~/no/such/map.yaml"}),
    Spec("localized", {"within": 0.2}),
    Spec("robot_near", {"x": 1.0, "y": 2.0, "within": 0.3}),
    Spec("quiz", {"question": "2+2?", "options": ["3", "4"], "answer": "4"}),
]


def test_every_check_kind_can_fail(live, learner_workspace):
    assert {spec.kind for spec in FAILING_CHECKS} == set(CHECK_KINDS)
    live.quiz_answers[FAILING_CHECKS[-1].key] = "3"
    wait_until(lambda: live.graph.has_node("/classroom_dashboard"), what="our node in the graph")
    for spec in FAILING_CHECKS:
        result = live.evaluate(spec)
        assert result.state == FAIL, (spec.kind, result)
        assert result.reason, spec.kind

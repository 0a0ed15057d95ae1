"""How the tests are shared among tests/run.py's workers (pytest-xdist).

Two rules, both for a worker pool on two cores:

- A module whose tests share what a module-scoped fixture made (a MuJoCo
  run, a JupyterHub with its learners spawned, a built workspace) and that
  run in their written order is one unit of work: one worker runs all of it,
  in order, and makes the fixture once. Every other test is a unit of its
  own and goes to whichever worker is free. (xdist's ``loadgroup`` would say
  this with a mark, but xdist 3.8 cannot rename pytest 9's node ids, so its
  groups silently fall apart.)
- Each test folder's units are spread evenly over the run instead of coming
  one folder after another: three workers in the browser tests at once (three
  software-rendering Chromiums) take the cores that the grading tests, which
  mostly wait, hardly use. Measured on 2 cores, whole suite: 16.2 min spread
  (a third of the time a core idle); 20.9 min in folder order, though five of
  that run's tests also waited out their time limits.

And a third: the cores go to the tests that use them. Most of a grading, a
lesson walk or a ros2 verb's test is spent waiting on the clock (a check's
time limit, a rate measured over seconds, discovery): three workers of
``test_grading`` alone kept two cores 15-40 % busy. So the first
GENERAL_WORKERS workers take every unit, in the spread order, and the
WAITING_WORKERS more take only such waiting units (the next one in that
order), never a browser or a simulated world, and a build only where the
whole module was measured to wait: the rest runs at most GENERAL_WORKERS at
a time, as before.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any, TypeVar

GENERAL_WORKERS = 3  # take any unit: the whole suite's share of the cores, measured
# Take only waiting units (below). Measured on 2 cores, whole suite, first phase: 2 of them
# 22.7 min (the general workers took a third of the waiting units); 4 of them 20.0 min,
# green, the general workers' own units then the bound (57.8 min of tests / 3). A fourth
# general worker (with 3 waiting) took 20.8 min and timed out a teacher view under load 25.
WAITING_WORKERS = 4

ONE_WORKER = frozenset(
    {
        "tests/browser/test_accessibility.py",
        "tests/faults/test_sigterm_stops.py",
        "tests/hub/test_jupyterhub.py",
        "tests/hub/test_lean_hub.py",
        "tests/integration/test_learner_workspace.py",
        "tests/integration/test_workspace_lesson_kinds.py",
        "tests/sim/test_sim_physics.py",
        "tests/sim/test_sim_world_ros.py",
        "tests/turtlesim/test_turtlesim_node.py",
        "tests/urdf/test_rsp_outside.py",
    }
)

# Modules whose module-scoped fixture is cheap enough to make again on each
# worker, and whose tests gain from being shared out (the reason says why).
SHARED_MODULE_FIXTURES = {
    "tests/exercises/test_grading.py": "one probe node and a supervisor; ~60 cases to share",
    "tests/exercises/test_attempts.py": "one probe node and a supervisor, for two gradings",
    "tests/unit/test_slam_geometry.py": "synthetic frames rendered in memory in a second",
}

Item = TypeVar("Item")


# One-worker modules that must not run at the same time either: they share a
# unit. Two JupyterHubs at once (each with its learners' servers, dashboards and
# a browser) took both cores for minutes and timed each other out.
SAME_UNIT = {
    "tests/hub/test_jupyterhub.py": "tests/hub/<both hubs>",
    "tests/hub/test_lean_hub.py": "tests/hub/<both hubs>",
}


# Modules whose cases are grouped by the first word of their parameter: one worker runs
# a group in order, so what the cases of a group share is made once.
GROUPED_BY_PARAMETER = {
    # A unit per exercise: its cases are attempts, one after the other, on the setup
    # (world, turtlesim, Nav2) the first one started, as a learner's are.
    "tests/exercises/test_grading.py": "an exercise's cases share its running setup",
}


def unit_of(nodeid: str) -> str:
    """The unit of work a test belongs to: its module (or its modules'), its group, or
    the test alone."""
    module = nodeid.split("::", 1)[0]
    if module in SAME_UNIT:
        return SAME_UNIT[module]
    if module in GROUPED_BY_PARAMETER and "[" in nodeid:
        test, _, case = nodeid.partition("[")
        return f"{test}[{re.split(r'-|__', case, maxsplit=1)[0]}]"
    return module if module in ONE_WORKER else nodeid


def _folder(unit: str) -> str:
    return unit.split("::", 1)[0].rsplit("/", 1)[0]


def spread(items: Sequence[Item], nodeid_of: Any = lambda item: item.nodeid) -> list[Item]:
    """``items`` with each folder's units spread evenly over the run (a unit stays whole).

    A unit's place is its rank among its folder's units, as a fraction of
    that folder's count, halved for a long unit (``LONG_UNITS``); ties keep the
    collection order.
    """
    units: dict[str, list[Item]] = {}
    for item in items:
        units.setdefault(unit_of(nodeid_of(item)), []).append(item)
    folders: dict[str, list[str]] = {}
    for unit in units:
        folders.setdefault(_folder(unit), []).append(unit)
    place = {
        unit: (rank + 0.5) / len(members) * (0.5 if is_long(unit) else 1.0)
        for members in folders.values()
        for rank, unit in enumerate(members)
    }
    return [item for unit in sorted(units, key=place.__getitem__) for item in units[unit]]


# Units that take 45 s or more (ci16, quiet, 2 cores), by the start of their unit name.
# They get half their place, so all of them start in the first half of the run: one
# that started near the end held the run up alone while the other workers had finished
# (ci16: 23.4 min for 20.7 min of general work per worker; a simulation trial of 80 s,
# the viser stress test and a replay started in the last tenth).
LONG_UNITS = (
    "tests/browser/test_accessibility.py",
    "tests/hub/<both hubs>",
    "tests/faults/test_kill_restart.py::",
    "tests/browser/test_lessons.py::test_complete_the_workspace_lesson",
    "tests/faults/test_outside_clients.py::test_every_interface_of_every_node",
    "tests/integration/test_lessons_walk.py::test_every_step_of_the_lesson_passes_on_real_nodes[20_",
    "tests/faults/test_start_stop_cycles.py::",
    "tests/browser/test_stage.py::test_every_",
    "tests/faults/test_viser_threads.py::",
    "tests/browser/test_turtle_attempt_replay.py::",
    "tests/browser/test_attempt_replay.py::",
    "tests/exercises/test_sim_probe_learner_executor.py::",
    "tests/integration/test_learner_workspace.py",
    "tests/faults/test_run_keeper.py::test_the_workers_after_the_general_ones",
    "tests/integration/test_terminal_commands.py::test_interface_package_builds",
    "tests/faults/test_sigterm_stops.py",
    "tests/integration/test_lessons_walk.py::test_every_step_of_the_lesson_passes_on_real_nodes[24_",
    "tests/exercises/test_grading.py::test_grading[wall_follower]",
    "tests/exercises/test_grading.py::test_grading[patrol]",
)


def is_long(unit: str) -> bool:
    return unit.startswith(LONG_UNITS)


# Modules whose tests mostly wait on the clock, and start no browser or world.
WAITING_MODULES = frozenset(
    {
        "tests/exercises/test_grading.py",
        "tests/integration/test_lessons_walk.py",
        "tests/integration/test_core_nodes.py",
        "tests/integration/test_ros2cli_types_and_errors.py",
        "tests/integration/test_ros2cli_fidelity.py",
        "tests/integration/test_ros2cli_params_lifecycle.py",
        "tests/integration/test_supervisor.py",
        "tests/tf2/test_tf2_tutorial_commands.py",
        "tests/tf2/test_tf_checks.py",
        "tests/turtlesim/test_cli_tutorial_commands.py",
        "tests/turtlesim/test_ros2_run.py",
        # Measured (a full run on 2 cores, one core kept busy beside it: each worker's
        # process tree's CPU over the test's wall time, by sampling): these use at most
        # 40 % of a core on average, builds and launches included, so they wait beside
        # the general workers instead of holding one of them (ci14: the waiting workers
        # were idle for the second half of the run).
        "tests/integration/test_learner_workspace.py",  # 28 %, colcon builds
        "tests/faults/test_run_keeper.py",  # 39 %, small pytest runs of its own
        "tests/sandbox/test_contained_build.py",  # 30 %, contained builds
        "tests/tf2/test_tf2_time_tutorials.py",  # 38 %
        "tests/classroom/test_warm_start.py",  # 17 %
        "tests/integration/test_terminal_commands.py",  # 30 %, an interface build
        "tests/classroom/test_teacher_two_hosts.py",  # 28 %, wire clients, no browser
        "tests/exercises/test_seed_replay.py",  # 11 %
        "tests/turtlesim/test_turtlesim_node.py",  # 14 %
        "tests/urdf/test_tutorial_launch.py",  # 28 %
        "tests/nav/test_nav2_bringup_dds.py",  # 19 %, Nav2 without a world
        "tests/unit/test_exercise_workspace.py",  # 17 %
        "tests/bags/test_bag_roundtrip.py",  # 3 %
        "tests/faults/test_ros_liveness.py",  # one dashboard, mostly waiting for its guard
    }
)
_LESSONS = Path(__file__).resolve().parent.parent / "lessons"
# What takes a core: a simulated world (MuJoCo, the office with Nav2), the SLAM capstone,
# or a colcon build (a lesson's command, an exercise that is a package).
_BUSY = re.compile(r'"(sim_\w+|office_\w+|slam_node)"|colcon build|^package = "\w', re.M)


def busy_cases() -> set[str]:
    """Exercise slugs and lesson ids whose grading or walk takes a core (``_BUSY``)."""
    data = [*_LESSONS.glob("*/exercises/*/exercise.toml"), *_LESSONS.glob("*/lesson.toml")]
    return {p.parent.name for p in data if _BUSY.search(p.read_text(encoding="utf-8"))}


def waits(unit: str, busy: frozenset[str] | set[str]) -> bool:
    """Whether ``unit`` mostly waits: a test of WAITING_MODULES whose parameter (an
    exercise slug or a lesson id) is not ``busy``."""
    module, _, name = unit.partition("::")
    case = name.partition("[")[2].rstrip("]")
    return module in WAITING_MODULES and not any(
        case == item or case.startswith(f"{item}-") for item in busy
    )


def _worker_number(node: Any) -> int:
    return int(str(node.workerinput["workerid"]).removeprefix("gw"))


def make_scheduler(config: Any, log: Any) -> Any:
    """xdist's scope scheduler with our units, handed out in the spread order, the
    workers after GENERAL_WORKERS given only units that wait."""
    from xdist.scheduler import LoadScopeScheduling

    busy = frozenset(busy_cases())

    class Units(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return unit_of(nodeid)

        def _assign_work_unit(self, node: Any) -> None:
            if _worker_number(node) < GENERAL_WORKERS:
                super()._assign_work_unit(node)
                return
            unit = next((u for u in self.workqueue if waits(u, busy)), None)
            if unit is None:  # nothing left that waits: the rest is the general workers'
                if not node.shutting_down:
                    node.shutdown()
                return
            self.workqueue.move_to_end(unit, last=False)
            super()._assign_work_unit(node)

    # Its reorder puts the largest units first: all the one-worker modules at
    # once at the start, which undoes the spreading.
    config.option.loadscopereorder = False
    return Units(config, log)

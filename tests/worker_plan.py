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
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, TypeVar

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


def unit_of(nodeid: str) -> str:
    """The unit of work a test belongs to: its module (or its modules'), or the test alone."""
    module = nodeid.split("::", 1)[0]
    if module in SAME_UNIT:
        return SAME_UNIT[module]
    return module if module in ONE_WORKER else nodeid


def _folder(unit: str) -> str:
    return unit.split("::", 1)[0].rsplit("/", 1)[0]


def spread(items: Sequence[Item], nodeid_of: Any = lambda item: item.nodeid) -> list[Item]:
    """``items`` with each folder's units spread evenly over the run (a unit stays whole).

    A unit's place is its rank among its folder's units, as a fraction of
    that folder's count; ties keep the collection order.
    """
    units: dict[str, list[Item]] = {}
    for item in items:
        units.setdefault(unit_of(nodeid_of(item)), []).append(item)
    folders: dict[str, list[str]] = {}
    for unit in units:
        folders.setdefault(_folder(unit), []).append(unit)
    place = {
        unit: (rank + 0.5) / len(members)
        for members in folders.values()
        for rank, unit in enumerate(members)
    }
    return [item for unit in sorted(units, key=place.__getitem__) for item in units[unit]]


def make_scheduler(config: Any, log: Any) -> Any:
    """xdist's scope scheduler with our units, handed out in the spread order."""
    from xdist.scheduler import LoadScopeScheduling

    class Units(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return unit_of(nodeid)

    # Its reorder puts the largest units first: all the one-worker modules at
    # once at the start, which undoes the spreading.
    config.option.loadscopereorder = False
    return Units(config, log)

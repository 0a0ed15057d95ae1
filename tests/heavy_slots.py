"""No more tests that each take a whole core at once than the machine has cores.

tests/run.py's workers share the tests (tests/worker_plan.py), and three of
them may take any test. On a machine half as fast as the one the plan was
measured on, three such tests at once (two patrol gradings, each with a
MuJoCo world and Nav2, beside a browser test with a world of its own) held
the load at 26 on two cores, and the page answered no click for 30 s
(rehearsal ci70; the CI run of 9043cb1 failed nine browser tests so).

So a test that keeps about a core busy for most of its time (``is_heavy``:
a Chromium, a simulated world, a busy grading, or a module measured so)
first takes one of as many slots as the run has free cores (the machine's, less
those something else kept busy as the run began: tests/run.py measures them): a
lock on a file named after the run's namespaces file (tests/run.py), which every
worker of the run shares.
A worker whose next test is heavy waits for a slot; the cores are full then
anyway. A few tests keep about two cores busy on their own (``takes_all``: a
world drawn by software WebGL in a Chromium, a grading with a world and
Nav2's seven nodes); they take every slot, in order, so no other heavy test
runs beside them (rehearsal ci74: one of each at once held the load at 19,
and the page answered no click on its dropdown for 30 s). The kernel drops
the lock when a worker dies, so a crash frees its slot. A run with one
worker, or pytest by hand, has nothing to share.
"""

from __future__ import annotations

import fcntl
import os
import time
from collections.abc import Callable
from typing import IO, Any

from tests.run import FREE_CORES, NAMESPACES, SLOT_SUFFIX  # one file per run, by its keeper
from tests.worker_plan import busy_cases, unit_of

# Measured (rehearsal ci70, 2 cores, a worker's process tree): these keep 0.6-1.3 of a
# core busy over their wall time.
HEAVY_MODULES = (
    "tests/exercises/test_sim_probe_learner_executor.py",
    "tests/faults/test_outside_clients.py",
    "tests/faults/test_sigterm_stops.py",
    "tests/faults/test_start_stop_cycles.py",
    "tests/faults/test_viser_threads.py",
    "tests/faults/test_load.py",
    "tests/hub/",
    "tests/nav/test_amcl_dds.py",
    "tests/nav/test_mapping_dds.py",
    "tests/nav/test_nav_stack_dds.py",
    "tests/nav/test_navigation_dds.py",
    "tests/nav/test_obstacles_dds.py",
    "tests/nav/test_waypoint_follower_dds.py",
    "tests/sim/test_sim_physics.py",
    "tests/sim/test_sim_world_ros.py",
)
# Measured (rehearsal ci74 and ci70, 2 cores): each of these keeps about two cores busy.
WHOLE_MACHINE = (
    "tests/browser/test_sim_world_view.py",
    "tests/exercises/test_grading.py::test_grading[patrol-",
)
# Modules whose tests each grade an exercise or walk a lesson; a busy one takes a core.
CASE_MODULES = ("tests/exercises/test_grading.py", "tests/integration/test_lessons_walk.py")
POLL_S = 0.5


def is_heavy(nodeid: str, fixturenames: Any, busy: frozenset[str] | set[str]) -> bool:
    """Whether the test keeps about a core busy: it drives a Chromium, is in
    HEAVY_MODULES, or grades or walks a ``busy`` case (tests/worker_plan.py)."""
    if "browser" in fixturenames:
        return True
    module, _, name = nodeid.partition("::")
    if module.startswith(HEAVY_MODULES):
        return True
    case = name.partition("[")[2].rstrip("]")
    return module in CASE_MODULES and any(
        case == item or case.startswith(f"{item}-") for item in busy
    )


def takes_all(nodeid: str) -> bool:
    """Whether the test keeps about two cores busy on its own: it takes every slot."""
    return nodeid.startswith(WHOLE_MACHINE)


def slot_files(run_file: str, cores: int) -> list[str]:
    return [f"{run_file}{SLOT_SUFFIX}{number}" for number in range(max(1, cores))]


def take_slot(paths: list[str], sleep: Callable[[float], None] = time.sleep) -> IO[str]:
    """The first of ``paths`` this process can lock, waiting until one is free."""
    while True:
        for path in paths:
            handle = open(path, "a", encoding="ascii")  # held until released
            try:
                fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
                return handle
            except BlockingIOError:
                handle.close()
        sleep(POLL_S)


def take_all(paths: list[str]) -> list[IO[str]]:
    """Every one of ``paths``, each waited for in their order: two workers that both want
    them all never hold one each (and a one-slot taker never waits while holding one)."""
    held = []
    for path in paths:
        handle = open(path, "a", encoding="ascii")  # held until released
        fcntl.flock(handle, fcntl.LOCK_EX)  # blocks until this slot is free
        held.append(handle)
    return held


class HeavySlots:
    """One worker's side of the run's slots: taken before a heavy test, kept while
    the next test is heavy and of the same unit (a module-scoped world lives on
    between them), given back otherwise."""

    def __init__(self, run_file: str | None, cores: int | None = None):
        self.paths = slot_files(run_file, cores or os.cpu_count() or 1) if run_file else []
        self.busy = frozenset(busy_cases())
        self.held: list[IO[str]] = []

    def heavy(self, item: Any) -> bool:
        return bool(self.paths) and is_heavy(item.nodeid, item.fixturenames, self.busy)

    def before(self, item: Any) -> float:
        """Take a slot for ``item`` if it is heavy (every slot if it ``takes_all``); the
        seconds waited for it."""
        if not self.heavy(item):
            return 0.0
        wanted = len(self.paths) if takes_all(item.nodeid) else 1
        if len(self.held) >= wanted:
            return 0.0
        self.release()  # a kept slot first: slots are only ever waited for holding none
        began = time.monotonic()
        self.held = take_all(self.paths) if wanted > 1 else [take_slot(self.paths)]
        return time.monotonic() - began

    def after(self, item: Any, nextitem: Any) -> None:
        keep = (
            nextitem is not None
            and self.heavy(nextitem)
            and unit_of(nextitem.nodeid) == unit_of(item.nodeid)
        )
        if not keep:
            self.release()
        elif not takes_all(nextitem.nodeid):
            for handle in self.held[1:]:  # the next one needs a single slot: others may go on
                handle.close()
            self.held = self.held[:1]

    def release(self) -> None:
        for handle in self.held:
            handle.close()  # closing the file drops the lock
        self.held = []


def for_this_worker() -> HeavySlots:
    """The slots of the run this xdist worker belongs to; none outside a run's workers."""
    shared = os.environ.get("PYTEST_XDIST_WORKER") and os.environ.get(NAMESPACES)
    free = os.environ.get(FREE_CORES, "")  # the keeper's: cores nothing else kept busy
    return HeavySlots(shared or None, int(free) if free.isdigit() else None)

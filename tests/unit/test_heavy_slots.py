"""The run's slots for tests that each keep a core busy (tests/heavy_slots.py)."""

from __future__ import annotations

import subprocess
import sys
from types import SimpleNamespace

import pytest

from app import PROJECT_ROOT
from tests.conftest import wait_until
from tests.heavy_slots import (
    HEAVY_MODULES,
    WHOLE_MACHINE,
    HeavySlots,
    is_heavy,
    slot_files,
    take_all,
    take_slot,
    takes_all,
)

BUSY = frozenset({"patrol", "24_navigation"})


class Waited(Exception):
    """take_slot would have slept: every slot was taken."""


def _refuse_to_wait(_seconds: float) -> None:
    raise Waited


def _item(nodeid: str, fixtures: tuple[str, ...] = ()) -> SimpleNamespace:
    return SimpleNamespace(nodeid=nodeid, fixturenames=fixtures)


@pytest.mark.parametrize(
    ("nodeid", "fixtures", "heavy"),
    [
        ("tests/lti/test_gradebook.py::test_a", ("page", "browser", "dashboard"), True),
        ("tests/lti/test_gradebook.py::test_b", ("dashboard",), False),
        ("tests/exercises/test_grading.py::test_grading[patrol-reference]", (), True),
        ("tests/exercises/test_grading.py::test_grading[patrol_x-reference]", (), False),
        ("tests/exercises/test_grading.py::test_grading[talker-reference]", (), False),
        ("tests/integration/test_lessons_walk.py::test_walk[24_navigation]", (), True),
        ("tests/hub/test_lean_hub.py::test_x", (), True),
        ("tests/nav/test_nav2_bringup_dds.py::test_x", (), False),
        ("tests/unit/test_cli.py::test_x", (), False),
    ],
)
def test_what_keeps_a_core_busy_is_heavy(nodeid, fixtures, heavy):
    assert is_heavy(nodeid, fixtures, BUSY) is heavy


def test_every_heavy_module_or_folder_exists():
    # A renamed module would silently run beside the others again.
    modules = [*HEAVY_MODULES, *(prefix.split("::")[0] for prefix in WHOLE_MACHINE)]
    missing = [path for path in modules if not (PROJECT_ROOT / path).exists()]
    assert not missing, missing


def test_a_test_that_takes_all_waits_for_every_slot_and_holds_them_all(tmp_path):
    run = str(tmp_path / "run.netns")
    world = "tests/browser/test_sim_world_view.py::test_the_world"
    assert takes_all(world) and is_heavy(world, ("browser",), BUSY)
    assert takes_all("tests/exercises/test_grading.py::test_grading[patrol-starter]")
    assert not takes_all("tests/exercises/test_grading.py::test_grading[patrol_x-starter]")
    paths = slot_files(run, cores=2)
    other = take_slot(paths[1:])  # another worker's heavy test, on the second slot
    taker = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import time; from tests.heavy_slots import take_all, slot_files;"
            f" held = take_all(slot_files({run!r}, 2)); print(len(held), flush=True);"
            " time.sleep(60)",
        ],
        cwd=PROJECT_ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    try:
        wait_until(lambda: _locked(paths[0]), timeout=30, what="the taker to hold slot 0")
        with pytest.raises(Waited):  # it holds the first slot while it waits for the second
            take_slot(paths, sleep=_refuse_to_wait)
        other.close()
        assert taker.stdout.readline().strip() == "2", taker.communicate(timeout=10)
        with pytest.raises(Waited):  # no heavy test runs beside it
            take_slot(paths, sleep=_refuse_to_wait)
    finally:
        taker.kill()
        taker.wait(timeout=10)
    take_all(paths)  # its death freed both


def _locked(path: str) -> bool:
    """Whether another process holds ``path``'s slot (taken and given back at once if not)."""
    try:
        take_slot([path], sleep=_refuse_to_wait).close()
    except Waited:
        return True
    return False


def test_all_slots_are_given_back_down_to_one_for_a_next_test_that_needs_one(tmp_path):
    slots = HeavySlots(str(tmp_path / "run.netns"), cores=2)
    grading = "tests/exercises/test_grading.py::test_grading"
    patrol = _item(f"{grading}[patrol-reference]")
    nav = _item(f"{grading}[nav_x-reference]")
    slots.busy = frozenset({"patrol", "nav_x"})
    slots.before(patrol)
    assert len(slots.held) == 2
    slots.after(patrol, nav)
    kept = len(slots.held)
    if kept:  # one unit (tests/worker_plan.py): one slot kept, the other free again
        assert kept == 1
        take_slot(slots.paths, sleep=_refuse_to_wait).close()
        assert slots.before(nav) == 0.0
    slots.before(patrol)  # from one slot to all: the kept one given back first
    assert len(slots.held) == 2
    slots.release()


def test_a_slot_is_taken_once_and_free_again_when_given_back(tmp_path):
    paths = slot_files(str(tmp_path / "run.netns"), cores=2)
    first, second = take_slot(paths), take_slot(paths)
    with pytest.raises(Waited):
        take_slot(paths, sleep=_refuse_to_wait)
    second.close()
    third = take_slot(paths, sleep=_refuse_to_wait)
    assert third.name == second.name
    first.close()
    third.close()


def test_a_worker_that_dies_frees_its_slot(tmp_path):
    paths = slot_files(str(tmp_path / "run.netns"), cores=1)
    holder = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import sys, time; from tests.heavy_slots import take_slot;"
            f" slot = take_slot({paths!r}); print('held', flush=True); time.sleep(60)",
        ],
        cwd=PROJECT_ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    try:
        assert holder.stdout.readline().strip() == "held", holder.communicate(timeout=10)
        with pytest.raises(Waited):
            take_slot(paths, sleep=_refuse_to_wait)
        holder.kill()
        holder.wait(timeout=10)
        take_slot(paths, sleep=_refuse_to_wait).close()
    finally:
        holder.kill()
        holder.wait(timeout=10)


def test_a_slot_is_kept_through_a_one_worker_module_and_given_back_after_it(tmp_path):
    slots = HeavySlots(str(tmp_path / "run.netns"), cores=1)
    world = "tests/sim/test_sim_physics.py"  # one worker runs it whole (tests/worker_plan.py)
    first, second = _item(f"{world}::test_a"), _item(f"{world}::test_b")
    light = _item("tests/unit/test_cli.py::test_x")
    slots.before(first)
    slots.after(first, second)
    with pytest.raises(Waited):  # the world lives on between its tests: the slot stays taken
        take_slot(slots.paths, sleep=_refuse_to_wait)
    assert slots.before(second) == 0.0
    slots.after(second, light)
    take_slot(slots.paths, sleep=_refuse_to_wait).close()
    assert slots.before(light) == 0.0 and slots.held == []


def test_two_tests_shared_out_one_by_one_each_take_the_slot_again(tmp_path):
    slots = HeavySlots(str(tmp_path / "run.netns"), cores=1)
    first = _item("tests/browser/test_x.py::test_a", ("browser",))
    second = _item("tests/browser/test_x.py::test_b", ("browser",))
    slots.before(first)
    slots.after(first, second)  # another worker may take it meanwhile
    take_slot(slots.paths, sleep=_refuse_to_wait).close()


def test_outside_a_run_nothing_is_shared():
    slots = HeavySlots(None)
    assert slots.before(_item("tests/browser/test_x.py::test_a", ("browser",))) == 0.0
    assert slots.held == []


def test_the_run_removes_its_slot_files_with_its_own(tmp_path):
    from tests.run import _remove_slot_files

    run_file = str(tmp_path / "classroom-run-x.netns")
    for path in [*slot_files(run_file, 2), f"{run_file}-other.heavy0"]:
        open(path, "w").close()
    _remove_slot_files(run_file)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["classroom-run-x.netns-other.heavy0"]


@pytest.mark.parametrize(
    ("busy_share", "free"),
    [(0.0, 2), (0.3, 2), (0.4, 1), (0.5, 1), (1.0, 1)],  # a busy loop on one core: 0.5
)
def test_the_keeper_counts_as_free_the_cores_nothing_else_kept_busy(monkeypatch, busy_share, free):
    """Two cores: the slots the run's heavy tests share are those nothing else kept busy as
    the run began, one at least (a machine busy throughout still runs the suite)."""
    from tests import run

    ticks = iter([(0, 1000), (int(busy_share * 1000), 2000)])  # busy, total: 1000 ticks apart
    monkeypatch.setattr(run, "_cpu_ticks", lambda: next(ticks))
    monkeypatch.setattr(run.os, "cpu_count", lambda: 2)
    got, busy = run.cores_free_of_others(sample_sec=0.0)
    assert (got, round(busy, 2)) == (free, round(2 * busy_share, 2))


def test_a_worker_takes_as_many_slots_as_the_keeper_found_free(monkeypatch, tmp_path):
    from tests import heavy_slots
    from tests.run import FREE_CORES, NAMESPACES

    monkeypatch.setenv("PYTEST_XDIST_WORKER", "gw0")
    monkeypatch.setenv(NAMESPACES, str(tmp_path / "run.netns"))
    monkeypatch.setenv(FREE_CORES, "1")
    assert len(heavy_slots.for_this_worker().paths) == 1
    monkeypatch.delenv(FREE_CORES)
    assert len(heavy_slots.for_this_worker().paths) == (heavy_slots.os.cpu_count() or 1)


def test_the_cpu_ticks_are_read_from_the_kernel():
    from tests.run import _cpu_ticks

    busy0, total0 = _cpu_ticks()
    sum(range(2_000_000))  # some work of our own, so the counters move
    busy1, total1 = _cpu_ticks()
    assert 0 <= busy0 <= total0 and busy1 > busy0 and total1 > total0

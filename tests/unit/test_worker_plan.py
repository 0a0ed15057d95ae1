"""The plan that shares the tests among tests/run.py's workers."""

from __future__ import annotations

import re

from app import PROJECT_ROOT
from tests.worker_plan import (
    LONG_UNITS,
    ONE_WORKER,
    SAME_UNIT,
    SHARED_MODULE_FIXTURES,
    WAITING_MODULES,
    busy_cases,
    is_long,
    spread,
    unit_of,
    waits,
)

HUB = "tests/hub/test_jupyterhub.py"
MODULE_FIXTURE = re.compile(r"^@pytest\.fixture\(.*scope=.module", re.M)


def _ids(folder: str, count: int, module: str = "test_x.py") -> list[str]:
    return [f"tests/{folder}/{module}::test_{i}" for i in range(count)]


def test_every_one_worker_module_exists():
    # A renamed module would silently be shared out test by test again.
    missing = [path for path in ONE_WORKER if not (PROJECT_ROOT / path).is_file()]
    assert not missing, missing


def test_the_two_hub_modules_never_run_at_once():
    assert unit_of(f"{HUB}::test_a") == unit_of("tests/hub/test_lean_hub.py::test_b")
    assert set(SAME_UNIT) <= ONE_WORKER


def test_every_module_fixture_is_made_once_or_said_to_be_cheap():
    # A module fixture in a shared-out module is made again each time a worker
    # comes back to the module: the SIGTERM module's (the whole catalog started
    # and stopped) ran a dozen times and took half an hour of a CI run.
    with_one = {
        str(path.relative_to(PROJECT_ROOT))
        for path in (PROJECT_ROOT / "tests").rglob("test_*.py")
        if MODULE_FIXTURE.search(path.read_text(encoding="utf-8"))
    }
    unplanned = with_one - ONE_WORKER - set(SHARED_MODULE_FIXTURES)
    assert not unplanned, f"module fixtures with no plan (tests/worker_plan.py): {unplanned}"


def test_a_one_worker_module_is_one_unit_and_other_tests_are_their_own():
    assert unit_of(f"{HUB}::test_a") == unit_of(f"{HUB}::test_b[x::y]")
    assert unit_of("tests/sim/test_sim_physics.py::test_a") == "tests/sim/test_sim_physics.py"
    assert unit_of("tests/unit/test_cli.py::test_a") == "tests/unit/test_cli.py::test_a"


def test_an_exercises_grading_cases_are_one_unit_whoever_wrote_them():
    grading = "tests/exercises/test_grading.py::test_grading"
    cases = ("patrol-reference", "patrol-swaps_x_and_y", "patrol__goto_each", "patrol-cheat")
    assert {unit_of(f"{grading}[{case}]") for case in cases} == {f"{grading}[patrol]"}
    assert unit_of(f"{grading}[wall_stop-reference]") == f"{grading}[wall_stop]"
    # A unit that waits stays one unless its exercise takes a core.
    assert waits(f"{grading}[heartbeat_logger]", busy=set())
    assert not waits(f"{grading}[patrol]", busy={"patrol"})


def test_a_one_worker_module_stays_whole_and_in_its_written_order():
    hub = [f"{HUB}::test_{name}" for name in ("spawn", "refuse", "teacher")]
    order = spread([*_ids("browser", 4), *hub, *_ids("unit", 6)], nodeid_of=str)
    at = order.index(hub[0])
    assert order[at : at + 3] == hub


def test_each_folders_tests_are_spread_over_the_whole_run():
    browser, exercises, unit = _ids("browser", 10), _ids("exercises", 30), _ids("unit", 60)
    order = spread([*browser, *exercises, *unit], nodeid_of=str)
    assert sorted(order) == sorted([*browser, *exercises, *unit])
    for folder in (browser, exercises, unit):
        positions = [order.index(nodeid) for nodeid in folder]
        assert positions == sorted(positions)  # the collection order within a folder
        first_half = sum(p < len(order) / 2 for p in positions)
        assert abs(first_half - len(folder) / 2) <= 1, (folder[0], positions)


def test_every_waiting_module_exists_and_starts_no_browser():
    # A waiting worker beside three general ones must never start a Chromium.
    # (The browser tests' mark, Playwright, or conftest's page/browser fixtures; a
    # docstring may still say "browser" about a wire client.)
    uses_a_browser = re.compile(
        r"mark\.browser|playwright|chromium|def \w+\([^)]*\b(page|browser)\b"
    )
    for path in WAITING_MODULES:
        source = (PROJECT_ROOT / path).read_text(encoding="utf-8")
        assert not uses_a_browser.search(source), f"{path} uses a browser: it does not only wait"
    # The check finds one where there is one.
    browser_test = (PROJECT_ROOT / "tests/browser/test_tour.py").read_text(encoding="utf-8")
    assert uses_a_browser.search(browser_test)


def test_only_gradings_and_walks_that_start_nothing_busy_wait():
    busy = busy_cases()
    assert {"patrol", "wall_follower", "24_navigation", "package_adder"} <= busy
    grading = "tests/exercises/test_grading.py::test_grading"
    walk = (
        "tests/integration/test_lessons_walk.py::test_every_step_of_the_lesson_passes_on_real_nodes"
    )
    assert waits(f"{grading}[counter_publisher-starter]", busy)
    assert waits(f"{walk}[05_topics]", busy)
    assert not waits(f"{grading}[patrol-reference]", busy)  # the office world with Nav2
    assert not waits(f"{walk}[20_workspaces_packages]", busy)  # colcon builds
    assert not waits("tests/browser/test_stage.py::test_every_step", busy)


def test_long_units_start_in_the_first_half_and_each_names_real_tests():
    faults = _ids("faults", 20)
    long_one = "tests/faults/test_kill_restart.py::test_twenty_sigkills_lose_nothing"
    assert is_long(long_one) and not is_long(faults[0])
    order = spread([*_ids("unit", 40), *faults, long_one], nodeid_of=str)
    assert order.index(long_one) < len(order) / 2  # collected last of its folder
    # Each entry still names tests: a renamed one would silently start late again.
    hub_units = set(SAME_UNIT.values())
    for prefix in LONG_UNITS:
        if prefix in hub_units:
            continue
        module, _, name = prefix.partition("::")
        source = (PROJECT_ROOT / module).read_text(encoding="utf-8")
        if name:
            assert f"def {name.split('[')[0]}" in source, prefix

"""The teacher's view of a learner's attempts (classroom mode): the teacher page lists a
seat's kept attempts of the exercise it is on, shows one's result lines and plots, and
plays it with the learner's own player; a damaged attempt is said to be damaged.

The page runs here in the test's process (``TeacherPage`` as ``classroom`` builds it, the
roster replaced by a fixed record: no DDS), over a bags folder laid out as a classroom's
dashboards keep it (``<bags>/<learner>/attempts/<exercise>/``). The attempt's bag is
written with rosbags' writer (a robot driving at a wall, as the simulated world's ground
truth), its metadata carries the verdict as a grading writes it, and its plot is drawn by
the grader's own plotting code.
"""

from __future__ import annotations

import math
import os
import re
import time
from pathlib import Path

import pytest
from nav_msgs.msg import Odometry
from playwright.sync_api import Page, expect
from rclpy.serialization import serialize_message
from rosbags.rosbag2 import StoragePlugin, Writer

from app.bags.definitions import definition
from app.exercises import plots
from app.exercises.attempt_folders import CUSTOM_PREFIX, ResultLine, attempt_label, custom_data
from app.exercises.trace import Trace
from app.teacher.attempt_files import attempt_markdown, kept_attempts, plot_files
from app.teacher.page import LocalAttempts, TeacherPage
from app.teacher.record import LearnerRecord
from tests.conftest import ARTIFACTS, free_port

SITE, LEARNER, SLUG = "local", "ana", "wall_stop"
FAILED = "20261129-101500-seed4242-fail"
DAMAGED = "20261129-101900.recording"  # a dashboard killed mid-grading leaves this
START_NS = 1_795_947_300_000_000_000
WHY = "trial 1: it came to 0.21 m of the wall ahead at 5.8 s: closer than the bound 0.35 m"


def _odom(x: float) -> Odometry:
    msg = Odometry()
    msg.pose.pose.position.x, msg.pose.pose.position.y = x, -0.5
    msg.pose.pose.orientation.w = 1.0
    return msg


def _failed_attempt(folder: Path) -> list[tuple[float, float]]:
    """A wall_stop attempt that drove into the wall: its bag, verdict and plot; returns
    (seconds since the bag's start, x) of each ground-truth pose."""
    folder.parent.mkdir(parents=True, exist_ok=True)
    poses = [(i / 20, -1.0 + 0.5 * i / 20) for i in range(80)]  # 4 s at 0.5 m/s
    writer = Writer(folder, version=8, storage_plugin=StoragePlugin.MCAP)
    results = [
        ResultLine("node running /wall_stopper", True, "/wall_stopper is on the graph"),
        ResultLine("stop before the wall", False, WHY),
    ]
    for key, value in custom_data(
        SLUG, 4242, "fail", "1 of 2 checks passed: not yet.", results
    ).items():
        writer.set_custom_data(CUSTOM_PREFIX + key, value)
    with writer:
        msgdef, rihs01 = definition("nav_msgs/msg/Odometry")
        odom = writer.add_connection(
            "/ground_truth/odom", "nav_msgs/msg/Odometry", msgdef=msgdef, rihs01=rihs01
        )
        for t, x in poses:
            writer.write(odom, START_NS + int(t * 1e9), serialize_message(_odom(x)))
    trace = Trace.of(
        "distance to the wall ahead, trial 1",
        "m",
        [(t * 2, 1.8 - (x + 1.0)) for t, x in poses],
        low=0.35,
        broken_at=5.8,
        broken_why="closer than 0.35 m",
    )
    plots.save([trace], folder)
    (folder / "graded.py").write_text("print('graded')\n", encoding="utf-8")
    return poses


def _damaged_attempt(folder: Path) -> None:
    """Half of a real MCAP file, as a killed recording leaves it (no metadata.yaml), last
    written two minutes ago."""
    source = next((folder.parent / FAILED).glob("*.mcap"))
    folder.mkdir()
    data = source.read_bytes()
    half = folder / f"{DAMAGED}.mcap"
    half.write_bytes(data[: len(data) // 2])
    old = time.time() - 120
    os.utime(half, (old, old))


class _Roster:
    """The learners' reports as the page reads them (no DDS: one fixed seat)."""

    def __init__(self, records: list[LearnerRecord]) -> None:
        self._records = records

    def records(self) -> list[LearnerRecord]:
        return list(self._records)

    def send_notice(self, target: str, text: str) -> None:
        pass

    def set_reveal_after(self, value: int) -> None:
        pass


def _seat() -> LearnerRecord:
    return LearnerRecord(
        site=SITE,
        learner=LEARNER,
        domain_id=11,
        lesson_id="13_sim_sensors",
        unit=13,
        lesson_title="Sensors",
        step=4,
        steps=6,
        step_title="Stop before the wall",
        exercise=SLUG,
        exercise_failed_here=2,
        exercise_attempts_here=2,
        code_excerpt="print('hello')",
    )


@pytest.fixture
def bags(tmp_path: Path) -> tuple[Path, list[tuple[float, float]]]:
    folder = tmp_path / "bags" / LEARNER / "attempts" / SLUG
    poses = _failed_attempt(folder / FAILED)
    _damaged_attempt(folder / DAMAGED)
    return tmp_path / "bags", poses


def test_an_attempts_folder_reads_for_the_teacher_and_a_damaged_one_says_so(bags) -> None:
    root, _poses = bags
    folder = root / LEARNER / "attempts" / SLUG
    kept = kept_attempts(folder)
    assert [p.name for p in kept] == [DAMAGED, FAILED]  # newest first
    assert kept_attempts(folder / "nothing") == []
    told = attempt_markdown(folder / FAILED)
    assert "**1 of 2 checks passed: not yet.**" in told
    assert "- ✗ **stop before the wall**: trial 1: it came to 0.21 m" in told
    assert f"exercise check {SLUG} {folder / FAILED / 'graded.py'} --seed 4242" in told
    damaged = attempt_markdown(folder / DAMAGED)
    assert "damaged" in damaged and "Damaged" in damaged
    # Written to a moment ago: a grading under way, not a damaged one.
    (folder / DAMAGED / "more.mcap").write_bytes(b"")
    assert "Being graded now" in attempt_markdown(folder / DAMAGED)
    (folder / DAMAGED / "more.mcap").unlink()
    assert [p.name for p in plot_files(folder / FAILED)] == [
        "plot-1-distance-to-the-wall-ahead-trial-1.png"
    ]
    assert plot_files(folder / DAMAGED) == []
    # A folder that vanished, or a file where a folder should be: words, no exception.
    assert "Damaged" in attempt_markdown(folder / "20261129-102000-seed1-fail")
    assert plot_files(folder / FAILED / "graded.py") == []
    # Only this site's seats, and only names that are names, reach a folder.
    attempts = LocalAttempts(root, SITE)
    assert attempts.kept(_seat()) == kept
    assert attempts.newest(_seat()) == kept[0]
    other = LearnerRecord(**{**_seat().__dict__, "site": "B"})
    assert attempts.kept(other) == []
    sneaky = LearnerRecord(**{**_seat().__dict__, "exercise": "../../x"})
    assert attempts.kept(sneaky) == []


def _choose(page: Page, label: str, option: str) -> None:
    field = page.get_by_label(label, exact=True).locator("visible=true").first
    field.click()
    page.get_by_role("option", name=option, exact=True).click()


@pytest.mark.timeout(120)
def test_the_teacher_sees_a_learners_failed_attempt_its_plot_and_its_replay(browser, bags) -> None:
    root, poses = bags
    token = "t" * 24
    teacher = TeacherPage(
        "127.0.0.1",
        free_port(),
        token,
        _Roster([_seat()]),  # type: ignore[arg-type]
        attempts=LocalAttempts(root, SITE),
    )
    teacher.start()
    page = browser.new_page(viewport={"width": 1600, "height": 1000})
    try:
        page.goto(f"http://127.0.0.1:{teacher.port}/?token={token}")
        _choose(page, "Learner", f"{SITE}/{LEARNER}")
        page.get_by_role("tab", name="Learner's attempts").click()
        expect(page.get_by_text(re.compile(r"ana's attempts at wall_stop.*2 kept"))).to_be_visible(
            timeout=20_000
        )
        # The newest is the damaged one: it says so, and the page keeps going.
        expect(page.get_by_text(re.compile("Damaged")).first).to_be_visible(timeout=10_000)
        expect(page.get_by_text(re.compile("recording never ended")).first).to_be_visible()

        _choose(page, "Attempt", "2026-11-29 10:15:00 UTC · fail · seed 4242")
        expect(
            page.get_by_text(re.compile("it came to 0.21 m of the wall ahead")).first
        ).to_be_visible(timeout=10_000)
        # The plot (520 px wide as drawn), not a blank placeholder nor viser's logo.
        page.wait_for_function(
            "() => [...document.querySelectorAll('img')].some("
            "i => i.naturalWidth >= 500 && i.getBoundingClientRect().width > 200)",
            timeout=10_000,
        )

        page.get_by_role("button", name="Watch this attempt").click()
        expect(page.get_by_text(re.compile(r"ana's attempt at wall_stop"))).to_be_visible(
            timeout=20_000
        )
        robot = page.locator("#replay-robot")
        expect(robot).to_be_visible(timeout=20_000)
        # Played to its end (4 s; see tests/browser/replay_helpers.go_to_moments), then a
        # time typed in the slider's box.
        play = page.get_by_role("button", name=re.compile(r"^(Play|Pause)$"))
        expect(play).to_have_text(re.compile("Play"), timeout=60_000)
        time_box = (
            page.get_by_text("Time (s)", exact=True)
            .locator("visible=true")
            .first.locator("xpath=ancestor::div[contains(@class,'mantine-Flex-root')][1]//input")
            .last
        )
        time_box.fill("2.5")
        time_box.press("Enter")
        page.wait_for_function(
            "() => { const s = document.querySelector('svg.stage-replay');"
            " return s && s.dataset.cursor === '2.500'; }",
            timeout=20_000,
        )
        newest = max((p for p in poses if p[0] <= 2.5 + 1e-9), key=lambda p: p[0])
        x = float(robot.get_attribute("data-x") or "nan")
        assert math.isclose(x, newest[1], abs_tol=0.002), (x, newest)
        page.screenshot(path=str(ARTIFACTS / "teacher-attempt-replay.png"), full_page=True)

        # The damaged one plays what can be read, or says it cannot: never a dead page.
        _choose(page, "Attempt", attempt_label(Path(DAMAGED)))
        page.get_by_role("button", name="Watch this attempt").click()
        expect(
            page.get_by_text(re.compile(r"cannot be played|messages in \d")).first
        ).to_be_visible(timeout=20_000)
        expect(page.get_by_text(re.compile("Damaged")).first).to_be_visible()
    finally:
        ARTIFACTS.mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(ARTIFACTS / "teacher-attempts.png"), full_page=True)
        page.close()
        teacher.close()

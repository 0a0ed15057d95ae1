"""LTI in the one-server classroom mode: the hub's handlers on the classroom's own LTI port.

The server is app/hub/lti_classroom.py as ``classroom`` starts it, over real
HTTP, against the test LMS; the roster (what the dashboards publish on the
classroom domain, which needs ROS) is a list the test fills with records.
tests/classroom/test_classroom_lti.py runs the whole command.
"""

from __future__ import annotations

import html
import json
import re
import time
from collections.abc import Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path

import pytest

from app.classroom import Classroom, TeacherPlan, plan, start_lti
from app.hub.lti_classroom import ClassroomLtiServer, classroom_lti
from app.lti import claims
from app.lti.routes import ToolUrls
from app.teacher.record import LearnerRecord
from tests.conftest import free_port
from tests.lti.platform import TestPlatform
from tests.lti.service import Answer, request, wait_delivered, wait_for
from tests.lti.test_service import (
    EXERCISE,
    INSTRUCTOR,
    exercise_record,
    graded_link,
    launch,
    refusal,
    write_platforms,
)

SITE = "room-a"
TEACHER_TOKEN = "teacher-token-0123456789"
SEATS = {
    "learner1": "http://127.0.0.1:8100/?token=seat1-token",
    "learner2": "http://127.0.0.1:8101/?token=seat2-token",
}
TEACHER_URL = f"http://localhost:8099/?token={TEACHER_TOKEN}"


@dataclass
class Room:
    """The classroom's LTI server on a free loopback port, and the roster it grades from."""

    folder: Path
    platform: TestPlatform
    records: list[LearnerRecord] = field(default_factory=list)
    progress_root: Path | None = None  # the classroom's --progress-dir (the seats' folders)

    def __post_init__(self) -> None:
        write_platforms(self.folder, self.platform)
        port = free_port()
        self.server: ClassroomLtiServer = classroom_lti(
            f"http://127.0.0.1:{port}/classroom",
            learner_urls=SEATS,
            teacher_url=TEACHER_URL,
            teacher_token=TEACHER_TOKEN,
            site=SITE,
            host="127.0.0.1",
            port=port,
            records=lambda: list(self.records),
            folder=self.folder,
            progress_root=self.progress_root,
        )
        self.server.start()
        self.platform.tool_jwks = json.loads(request("GET", self.urls.jwks).body)

    @property
    def urls(self) -> ToolUrls:
        return self.server.lti.tool.urls

    def close(self) -> None:
        self.server.close()


@pytest.fixture
def room(platform: TestPlatform, tmp_path: Path) -> Iterator[Room]:
    running = Room(tmp_path / "lti", platform, progress_root=tmp_path / "progress")
    yield running
    running.close()


def seat_record(seat: str, passed: bool, site: str = SITE) -> LearnerRecord:
    """What a learner dashboard of the classroom publishes: its seat's name, not the LMS's."""
    record = exercise_record(seat, passed=passed)
    return replace(record, site=site)


def at_exercise(seat: str) -> str:
    """A seat's dashboard address, opened at the launched exercise (its ?exercise=)."""
    return f"{SEATS[seat]}&exercise={EXERCISE}"


def test_lms_learners_each_get_a_dashboard_of_their_own_and_keep_it(
    room: Room, platform: TestPlatform, tmp_path: Path
) -> None:
    link = graded_link(platform.lineitem_url("11"), {"exercise": EXERCISE})
    ada = launch(room, platform, **link)
    assert (ada.status, ada.location) == (303, at_exercise("learner1"))
    assert launch(room, platform, **link).location == at_exercise("learner1")  # Ada again
    assert launch(room, platform, sub="learner-43", **link).location == at_exercise("learner2")
    full = launch(room, platform, sub="learner-44", **link)
    assert "all 2 learner dashboards of this classroom already have a learner" in refusal(full)
    teacher = launch(room, platform, sub="teacher-1", **{claims.ROLES: [INSTRUCTOR]})
    assert (teacher.status, teacher.location) == (303, TEACHER_URL)

    # Another run of the classroom on the same folder: Ada still sits at learner1.
    room.close()
    again = Room(tmp_path / "lti", platform)
    try:
        assert launch(again, platform, sub="learner-44", **link).status == 400
        assert launch(again, platform, **link).location == at_exercise("learner1")
    finally:
        again.close()


def test_a_seat_that_passes_sends_its_lms_learners_grade_once(
    room: Room, platform: TestPlatform
) -> None:
    link = graded_link(platform.lineitem_url("11"), {"exercise": EXERCISE, "score_maximum": "5"})
    assert launch(room, platform, **link).location == at_exercise("learner1")  # Ada
    assert launch(room, platform, sub="learner-43", **link).location == at_exercise("learner2")
    room.records += [
        seat_record("learner1", passed=False),
        seat_record("learner2", passed=True, site="another-host"),  # not this classroom's seat
        seat_record("learner3", passed=True),  # no LMS learner sits there
    ]
    time.sleep(1.5)  # past a round of the roster
    assert platform.score_requests == []
    room.records[0] = seat_record("learner1", passed=True)
    wait_for(lambda: bool(platform.scores["11"]), why="Ada's score")
    time.sleep(2.5)  # the roster is read every second: the same pass is not sent again
    [score] = platform.scores["11"]
    assert (score["userId"], score["scoreGiven"], score["scoreMaximum"]) == ("learner-42", 5, 5)
    assert len(platform.score_requests) == 1


def test_the_gradebook_is_the_teachers_by_token(room: Room, platform: TestPlatform) -> None:
    link = graded_link(platform.lineitem_url("11"), {"exercise": EXERCISE})
    assert launch(room, platform, **link).status == 303
    platform.fail_next("11", 503, "maintenance", times=100)
    room.records.append(seat_record("learner1", passed=True))
    wait_for(lambda: bool(platform.score_requests), why="a first try")

    page_url = room.urls.base + "/gradebook"
    assert room.server.gradebook_url == f"{page_url}?token={TEACHER_TOKEN}"
    for url in (page_url, f"{page_url}?token=seat1-token", page_url + ".json"):
        refused = request("GET", url)
        assert refused.status == 403 and "Ada Lovelace" not in refused.body, url
    page = request("GET", room.server.gradebook_url)
    assert page.status == 200, page.body
    grid, lines = re.findall(r"<tbody>(.*?)</tbody>", page.body, re.S)  # the class, every line
    assert "Ada Lovelace" in grid and "… " in html.unescape(grid)
    text = html.unescape(re.sub(r"<[^>]+>", " ", lines))
    assert "Ada Lovelace" in text and "learner1" in text and "… waiting" in text
    assert "HTTP 503" in text and "maintenance" in text
    [cookie] = [name for name in page.cookies if name.startswith("classroom_lti_teacher_")]
    # The token came once in the address; the cookie carries it from then on (Retry too).
    jar = f"{cookie}={page.cookies[cookie]}; _xsrf={page.cookies['_xsrf']}"
    assert request("GET", page_url, headers={"Cookie": jar}).status == 200
    with platform.lock:
        platform.scripted["11"].clear()
    xsrf = html.unescape(re.findall(r'name="_xsrf" value="([^"]+)"', page.body)[0])
    retried = request("POST", page_url + "/retry", form={"_xsrf": xsrf}, headers={"Cookie": jar})
    assert retried.status == 303 and retried.location == "/classroom/gradebook?retried=1"
    wait_for(lambda: bool(platform.scores["11"]), timeout=4, why="the retried score")


def keep_attempt(folder: Path, name: str, results: list[tuple[str, bool, str]]) -> None:
    """A graded attempt as a seat's dashboard keeps it (app/exercises/attempts.py)."""
    (folder / name).mkdir(parents=True)
    custom = {
        "classroom.summary": f"{sum(r[1] for r in results)} of {len(results)} checks passed",
        "classroom.results": json.dumps(
            [{"name": n, "passed": p, "detail": d} for n, p, d in results]
        ),
    }
    meta = {"rosbag2_bagfile_information": {"custom_data": custom}}
    (folder / name / "metadata.yaml").write_text(json.dumps(meta))  # JSON is YAML too


def test_a_cell_of_the_gradebook_opens_the_seats_attempts_read_from_its_folder(
    room: Room, platform: TestPlatform
) -> None:
    link = graded_link(platform.lineitem_url("11"), {"exercise": EXERCISE, "score_maximum": "5"})
    assert launch(room, platform, **link).location == at_exercise("learner1")  # Ada
    assert room.progress_root is not None
    attempts = room.progress_root / "bags" / "learner1" / "attempts" / EXERCISE
    keep_attempt(attempts, "20261129-101500-seed1717-fail", [("probe /count", False, "got 4")])
    keep_attempt(attempts, "20261129-102000-seed4242-pass", [("probe /count", True, "5")])
    keep_attempt(attempts, "20261129-102500.recording", [])  # a grading under way
    room.records.append(seat_record("learner1", passed=True))
    wait_for(lambda: bool(platform.scores["11"]), why="Ada's score")
    wait_delivered(room.server.lti, why="the LMS's answer to Ada's score")
    # No dashboard runs here at all: the attempts are read from the seat's folder, and
    # the time the seat's dashboard counted from the file it keeps beside its progress.
    totals = {"version": 1, "seconds": {f"exercise:{EXERCISE}": 754}}
    (room.progress_root / "learner1").mkdir(parents=True, exist_ok=True)
    (room.progress_root / "learner1" / "learner1.time.json").write_text(json.dumps(totals))

    grid = request("GET", room.server.gradebook_url)
    [cell] = re.findall(r'href="(gradebook/attempts\?[^"]+)"', grid.body)
    # The cell counts the finished gradings read from the folder (not the one under way).
    assert "2 graded attempts, the last 2026-11-29 10:20 UTC" in html.unescape(grid.body)
    assert 'href="gradebook.csv"' in grid.body
    table = request("GET", room.server.gradebook_url.replace("/gradebook?", "/gradebook.csv?"))
    assert table.status == 200, table.body
    assert table.body.splitlines()[0].startswith("learner,lms_name,seat,activity")
    assert any(",exercise," in row and ",754," in row for row in table.body.splitlines()[1:])
    page = request("GET", f"{room.urls.base}/{html.unescape(cell)}&token={TEACHER_TOKEN}")
    assert page.status == 200, page.body
    words = html.unescape(re.sub(r"<[^>]+>", " ", page.body))
    assert "Ada Lovelace" in words and "dashboard learner1" in words and "✓ sent" in words
    code = room.progress_root / "learner1" / "learner1.code" / f"{EXERCISE}.py"
    body = words.split("Graded attempts", 1)[1]
    assert body.index("--seed 4242") < body.index("--seed 1717")  # newest first
    assert f"ros2-classroom exercise check {EXERCISE} {code} --seed 4242" in words
    assert "probe /count: got 4" in words and "2 shown: 1 passed, 1 failed" in words
    assert "Time spent on it: 12 min" in words
    assert f"recorded in {attempts}" in words
    assert (
        "no replay button here: it would run the learner's code on the classroom's server" in words
    )

    # Without the teacher's token: refused; a learner the classroom never seated: a page.
    assert request("GET", f"{room.urls.base}/{html.unescape(cell)}").status == 403
    nobody = request(
        "GET",
        f"{room.urls.base}/gradebook/attempts?learner=lti-nobody&activity=exercise:{EXERCISE}"
        f"&token={TEACHER_TOKEN}",
    )
    assert nobody.status == 404 and "no learner 'lti-nobody'" in html.unescape(nobody.body)


def test_the_classroom_serves_lti_only_when_given_its_address(tmp_path: Path) -> None:
    learners = plan(2, base_port=free_port(), base_domain=20, progress_root=tmp_path, site=SITE)
    room = Classroom(learners, {})
    teacher = TeacherPlan(free_port(), TEACHER_TOKEN, 101, tmp_path)
    assert start_lti(room, teacher, list, {}) is None
    with pytest.raises(ValueError, match="LMSes only talk to LTI tools over https"):
        start_lti(room, teacher, list, {"CLASSROOM_LTI_URL": "http://classroom.school.edu"})
    port = free_port()
    env = {
        "CLASSROOM_LTI_URL": f"http://127.0.0.1:{port}",
        "CLASSROOM_LTI_PORT": str(port),
        "CLASSROOM_LTI_DIR": str(tmp_path / "lti"),
    }
    server = start_lti(room, teacher, list, env)
    assert server is not None
    try:
        keys: Answer = request("GET", f"http://127.0.0.1:{port}/lti/jwks")
        assert keys.status == 200 and json.loads(keys.body)["keys"]
        assert server.lti.learner_urls == {ln.name: ln.url("127.0.0.1") for ln in learners}
        assert server.lti.tool.folder == tmp_path / "lti" and (tmp_path / "lti" / "keys").is_dir()
        assert server.lti.progress_root == tmp_path  # where each seat keeps its attempts
    finally:
        server.close()

"""A class on a real JupyterHub in the lab mode: three learners, a teacher, the hub's login.

One hub for the module (deploy/jupyterhub_config.py with local overrides,
tests/hub/local_hub.py): jupyterhub from PyPI, configurable-http-proxy from
npm, DummyAuthenticator with one password, ClassroomLocalSpawner (each
learner's server as this account with its own HOME and ROS domain id), and
each learner's single-user server is JupyterLab. In headless Chromium each
learner logs in, lands in JupyterLab and clicks the launcher's "ROS 2
Classroom" tile, which opens their dashboard in a new tab through
jupyter-server-proxy. The teacher (a member of the hub's teachers group, not
an admin) logs in to the teacher service with the hub's OAuth and sees every
row move. The lean mode (the dashboard as the server) is test_lean_hub.py.
"""

from __future__ import annotations

import http.client
import itertools
import os
import re
import time
from collections.abc import Iterator
from dataclasses import dataclass, field, replace
from urllib.parse import parse_qs, urlsplit

import pytest
from playwright.sync_api import Browser, BrowserContext, Page, expect

from app.dds import configure_dds_env
from app.teacher.http_report import to_json
from app.teacher.record import COLUMNS, LearnerRecord
from tests.browser.helpers import (
    answer_quiz,
    choose,
    click,
    click_next,
    expect_text,
    open_lesson,
    open_tab,
)
from tests.browser.test_exercise import EXERCISE, _open_editor
from tests.conftest import ARTIFACTS, fail_on_leftover_nodes, in_private_netns, wait_until
from tests.course_data import shared_course
from tests.hub.local_hub import LocalHub, log_in

# A watchdog, not a budget: the first test also spawns three learners' servers, which
# on two busy shared cores has taken minutes.
pytestmark = [pytest.mark.browser, pytest.mark.ros, pytest.mark.timeout(480)]

LEARNERS = ("alice", "bob", "carol")
# Besides the talker everyone starts, a node only this learner runs: seeing it
# anywhere else would mean two learners share a ROS graph.
OWN_NODE = {"alice": "listener", "bob": "listener2", "carol": "minimal_node"}
TEACHER = "teacher"
SERVICE = "/services/classroom-teacher/"
TILE = "ROS 2 Classroom"
ICON_DRAWN = "t => [...t.querySelectorAll('img')].some(i => i.complete && i.naturalWidth > 0)"


def vertex(page: Page, node: str):
    """A node's box on the learner's stage graph."""
    return page.locator(f'svg.stage-graph g.sg-vertex[data-name="/{node}"]')


@dataclass
class Room:
    """Everyone's browser: each learner's JupyterLab tab and Classroom tab, the teacher's page."""

    contexts: dict[str, BrowserContext] = field(default_factory=dict)
    labs: dict[str, Page] = field(default_factory=dict)
    classrooms: dict[str, Page] = field(default_factory=dict)
    urls: dict[str, list[str]] = field(default_factory=dict)  # every request each browser made
    teacher: Page | None = None


@pytest.fixture(scope="module")
def hub(tmp_path_factory) -> Iterator[LocalHub]:
    if not in_private_netns():
        pytest.fail("the hub test runs learners' DDS: run it with tests/run.py")
    env = dict(os.environ)
    configure_dds_env(env, domain_id=59, network=False)  # the hub's own processes
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    hub = LocalHub(
        tmp_path_factory.mktemp("hub"),
        env,
        learners=list(LEARNERS),
        teachers=[TEACHER],
        first_domain_id=60,
        log_path=ARTIFACTS / "jupyterhub.log",
        singleuser="lab",
    )
    try:
        hub.wait_ready()
        yield hub
    finally:
        alive = hub.stop()
        assert not alive, f"outlived the hub: {alive}"
        fail_on_leftover_nodes("the hub")


def _log_in(hub: LocalHub, page: Page, user: str, after: str = "") -> None:
    log_in(page, f"{hub.base}/hub/login{after}", user)


@pytest.fixture(scope="module")
def room(hub: LocalHub, browser: Browser) -> Iterator[Room]:
    """The teacher on the teacher's page; each learner logged in (their server spawning)."""
    room = Room()
    try:
        for user in (TEACHER, *LEARNERS):
            context = browser.new_context(viewport={"width": 1400, "height": 900})
            room.contexts[user] = context
            room.urls[user] = []
            context.on("request", lambda request, u=user: room.urls[u].append(request.url))
            page = context.new_page()
            # The teacher goes straight to the teacher service and starts no server;
            # a learner's login spawns their server, whose default URL is JupyterLab.
            _log_in(hub, page, user, after=f"?next={SERVICE}" if user == TEACHER else "")
            if user == TEACHER:
                room.teacher = page
            else:
                room.labs[user] = page
        yield room
    finally:
        for user, page in [*room.labs.items(), *room.classrooms.items()]:
            kind = "lab" if page in room.labs.values() else "classroom"
            page.screenshot(path=str(ARTIFACTS / f"hub-{user}-{kind}.png"))
        if room.teacher is not None:
            room.teacher.screenshot(path=str(ARTIFACTS / "hub-teacher.png"))
        for context in room.contexts.values():
            context.close()


def test_each_learner_opens_the_classroom_from_the_launcher(hub, room):
    started = time.monotonic()
    for user in LEARNERS:  # the three servers spawned together while we logged in
        lab = room.labs[user]
        lab.wait_for_url(f"**/user/{user}/lab**", timeout=120_000)
        tile = lab.locator(".jp-LauncherCard", has_text=TILE)
        expect(tile).to_be_visible(timeout=90_000)
        # Its icon drawn (a blank tile is what a learner would not recognise).
        wait_until(lambda tile=tile: tile.evaluate(ICON_DRAWN), timeout=30, what="the tile's icon")
        with room.contexts[user].expect_page(timeout=30_000) as new_tab:
            tile.click()  # the tile opens the dashboard in a new browser tab
        room.classrooms[user] = new_tab.value
    for user in LEARNERS:
        page = room.classrooms[user]
        page.wait_for_url(f"**/user/{user}/ros2-classroom/**", timeout=60_000)
        expect_text(page, "ros2 node list", timeout=120_000)  # the websocket is up
        # The websocket goes through the hub's proxy and the learner's own server.
        socket = parse_qs(urlsplit(page.url).query)["websocket"][0]
        assert socket.startswith(f"ws://127.0.0.1:{hub.port}/user/{user}/ros2-classroom/"), socket
    print(f"three learners in their Classrooms {time.monotonic() - started:.1f} s after login")
    room.labs["alice"].screenshot(path=str(ARTIFACTS / "hub-launcher.png"))
    # The hub's login is a cookie: no token ever travels in a URL.
    for user in LEARNERS:
        tokened = [u for u in room.urls[user] if re.search(r"[?&](token|access_token)=", u)]
        assert not tokened, tokened
    # Every learner's server has a ROS domain of its own; progress lives in their home.
    domains = {u: p.environ()["ROS_DOMAIN_ID"] for u, p in hub.dashboards().items()}
    assert sorted(domains) == sorted(LEARNERS) and len(set(domains.values())) == 3, domains
    for user in LEARNERS:
        assert (hub.homes / user / "ros2-classroom" / "progress").is_dir()


def _row(page: Page, user: str):
    return page.locator(f"#class tbody tr[data-learner='{user}']")


def _seen_after_start(page: Page, teacher: Page, user: str, node: str) -> tuple[float, float]:
    """Seconds from a Start click until the learner's page, and the teacher's row, show it.

    Both are watched in one loop so a slow row can be told from a slow Start.
    """
    clicked = time.monotonic()
    started = page.get_by_text(f"Started {node}").filter(visible=True)
    row = _row(teacher, user)
    seen: dict[str, float] = {}
    while len(seen) < 2 and time.monotonic() - clicked < 60:
        if "learner" not in seen and started.count():
            seen["learner"] = time.monotonic() - clicked
        if "teacher" not in seen and node in (row.text_content() or ""):
            seen["teacher"] = time.monotonic() - clicked
        time.sleep(0.05)
    assert len(seen) == 2, f"after 60 s only {seen} showed {node} started"
    return seen["learner"], seen["teacher"]


def test_each_learner_sees_only_their_own_nodes_and_the_teacher_sees_rows_move(hub, room):
    teacher = room.teacher
    assert teacher is not None
    teacher.goto(f"{hub.base}{SERVICE}")  # the hub's OAuth (done at login), then the page
    expect(teacher.get_by_text(f"Signed in through the hub as {TEACHER}")).to_be_visible()
    for user in LEARNERS:
        expect(_row(teacher, user)).to_be_visible(timeout=60_000)
    for user in LEARNERS:
        page = room.classrooms[user]
        open_tab(page, "Nodes")
        for node in ("talker", OWN_NODE[user]):
            choose(page, "Catalog node", node)
            click(page, "Start")
            learner_saw, teacher_saw = _seen_after_start(page, teacher, user, node)
            print(
                f"{user}: {node} Started on the learner's page after {learner_saw:.2f} s, "
                f"on the teacher's row after {teacher_saw:.2f} s"
            )
            # The teacher's row follows the learner's own page within 2 s. The Start itself
            # is the learner's dashboard's work, and on a loaded machine it is slower
            # (the CI of 2026-12-03: 2.19 s on the learner's page, the row 0.48 s later).
            assert teacher_saw - learner_saw <= 2.0, (user, node, learner_saw, teacher_saw)
    for user in LEARNERS:  # the talker and their own node, on their own stage graph
        page = room.classrooms[user]
        for node in ("talker", OWN_NODE[user]):
            expect(vertex(page, node)).to_be_visible(timeout=30_000)
    # Every learner's graph has had time to hear everyone's nodes: no pair shares one.
    for user, other in itertools.permutations(LEARNERS, 2):
        expect(vertex(room.classrooms[user], OWN_NODE[other])).to_have_count(0)
    # A box on the stage is a page link (classroom/act/...): through the hub's proxy too.
    alice = room.classrooms["alice"]
    vertex(alice, OWN_NODE["alice"]).locator("a").click()
    inspected = alice.get_by_text(f"Node /{OWN_NODE['alice']}", exact=True)
    expect(inspected.filter(visible=True)).to_be_visible()


def _type_code(page: Page, frame_locator, code: str) -> None:
    """Paste ``code`` into the editor and wait for its save (three learners save at once)."""
    frame_locator.locator(".ace_content").click()
    page.keyboard.press("Control+A")
    page.keyboard.insert_text(code)
    expect(frame_locator.locator("#status")).to_have_text("saved ✓", timeout=45_000)


def test_each_learner_passes_a_lesson_step_and_an_exercise(hub, room):
    teacher = room.teacher
    assert teacher is not None
    lesson = shared_course().lessons[0]
    for user in LEARNERS:
        page = room.classrooms[user]
        open_tab(page, "Lessons")
        open_lesson(page, lesson)
        for check in lesson.steps[0].checks:
            if check.kind == "quiz":
                answer_quiz(page, check)
        expect(page.get_by_text("✓ step done").filter(visible=True)).to_be_visible(timeout=45_000)
        click_next(page)
        expect(_row(teacher, user)).to_contain_text(
            f"{lesson.unit} · 2/{len(lesson.steps)}", timeout=2_000
        )
    # Each learner's code runs in their own server; the three run side by side.
    for user in LEARNERS:
        page = room.classrooms[user]
        frame_locator, _frame = _open_editor(page)
        _type_code(page, frame_locator, EXERCISE.reference)
        click(page, "Run my node")
    for user in LEARNERS:
        expect_text(
            room.classrooms[user], re.compile(r"running \(pid \d+\) · on the graph"), 60_000
        )
        click(room.classrooms[user], "Check my node")
    for user in LEARNERS:
        expect_text(room.classrooms[user], "All checks pass. Exercise done!", timeout=90_000)
        expect(_row(teacher, user)).to_contain_text("1 passed", timeout=2_000)
    # The exercises across the class, as on `classroom`'s teacher page.
    expect(teacher.locator("#exercises")).to_contain_text(
        f"{EXERCISE.slug}: {len(LEARNERS)} passed, 0 trying", timeout=2_000
    )

    # The CSV export and a learner's code, as on `classroom`'s teacher page.
    csv = _teacher_get(hub, teacher, "progress.csv")
    assert csv.status == 200 and all(f"hub,{u}," in csv.text() for u in LEARNERS)
    detail = _teacher_get(hub, teacher, "learner.json?key=hub/bob")
    assert detail.status == 200 and detail.json()["key"] == "hub/bob"
    assert "multiply" in detail.json()["code"]

    # A message to Carol reaches Carol's dashboard, not Alice's.
    teacher.select_option("#to", "hub/carol")
    teacher.fill("#text", "Look at the QoS of your subscriber")
    teacher.get_by_role("button", name="Send").click()
    expect(teacher.locator("#sent")).to_have_text("Sent.")
    expect_text(room.classrooms["carol"], "Look at the QoS of your subscriber", timeout=10_000)
    expect(
        room.classrooms["alice"].get_by_text("Look at the QoS of your subscriber")
    ).to_have_count(0)


def test_the_hub_refuses_other_learners_and_non_teachers(hub, room):
    pages = {user: room.contexts[user].new_page() for user in LEARNERS}
    try:
        for user, other in itertools.permutations(LEARNERS, 2):
            for path in (f"/user/{other}/ros2-classroom/", f"/user/{other}/lab"):
                answer = pages[user].goto(f"{hub.base}{path}")
                assert answer is not None and answer.status == 403, (user, path, answer)
                expect(pages[user].get_by_text("ros2 node list")).to_have_count(0)
        for user in LEARNERS:  # a learner is not a teacher
            answer = pages[user].goto(f"{hub.base}{SERVICE}")
            assert answer is not None and answer.status == 403, (user, answer)
            assert "not allowed" in pages[user].content() or "403" in pages[user].content()
    finally:
        for page in pages.values():
            page.close()


def _teacher_get(hub: LocalHub, teacher: Page, path: str):
    """A request with the teacher's hub cookie; the hub wants its XSRF token beside it."""
    xsrf = teacher.evaluate("xsrf")
    return teacher.request.get(f"{hub.base}{SERVICE}{path}", headers={"X-XSRFToken": xsrf})


def _tokens(hub: LocalHub) -> dict[str, str]:
    """Each learner's hub API token, as their dashboard has it."""
    return {
        user: proc.environ()["JUPYTERHUB_API_TOKEN"]
        for user, proc in hub.single_user_servers().items()
    }


def _teacher_table(hub: LocalHub, room: Room) -> dict[str, list]:
    """The teacher's table as the teacher's logged-in browser fetches it."""
    assert room.teacher is not None
    answer = _teacher_get(hub, room.teacher, "progress.json")
    assert answer.status == 200, answer.text()
    return {row[0]: row for row in answer.json()["rows"]}


def _shown(row: list) -> tuple:
    """What a forged report would change: where Bob is and which nodes he runs."""
    return (row[0], row[1], row[2], row[COLUMNS.index("nodes")])


def test_bad_input_is_refused_with_a_clear_status(hub, room):
    tokens = _tokens(hub)
    assert sorted(tokens) == sorted(LEARNERS), tokens
    wait_until(lambda: sorted(_teacher_table(hub, room)) == sorted(LEARNERS), 30, what="3 rows")
    bob_before = _shown(_teacher_table(hub, room)["bob"])

    # A forged user: Alice's token, a report about Bob.
    forged = replace(LearnerRecord(site="hub", learner="bob"), steps_passed=99)
    status, body = hub.api("POST", f"{SERVICE}api/progress", raw=to_json(forged),
                           token=tokens["alice"])  # fmt: skip
    assert status == 403 and "alice's" in body["error"] and "'bob'" in body["error"], body
    # No token, a token the hub does not know, and a report that is not a record.
    assert hub.api("POST", f"{SERVICE}api/progress", raw=to_json(forged), token=None)[0] == 401
    status, body = hub.api("POST", f"{SERVICE}api/progress", raw=b"{}", token="x" * 32)
    assert status == 403 and "no user" in body["error"], body
    status, body = hub.api("POST", f"{SERVICE}api/progress", raw=b'{"learner": "alice", '
                           b'"steps_passed": "lots"}', token=tokens["alice"])  # fmt: skip
    assert status == 400 and "steps_passed" in body["error"], body
    status, body = hub.api("POST", f"{SERVICE}api/progress", raw=b"[1,", token=tokens["alice"])
    assert status == 400 and "JSON" in body["error"], body
    # Nothing of Bob's progress was lost or changed (Alice's row keeps moving on its own).
    time.sleep(1.0)
    assert _shown(_teacher_table(hub, room)["bob"]) == bob_before

    # A learner's token on another learner's server, and on the teacher service.
    status, body = hub.api("GET", "/user/bob/api/status", token=tokens["alice"])
    assert status == 403, (status, body)  # Bob's server asks the hub whose token it is
    assert hub.api("GET", "/user/alice/api/status", token=tokens["alice"])[0] == 200
    status, body = hub.api("GET", f"{SERVICE}progress.json", token=tokens["alice"])
    assert status == 403 and "alice is not allowed" in body["error"], body

    # A proxy path climbing out of Alice's server with "..": never Bob's, never a crash.
    for path in (
        "/user/alice/ros2-classroom/../../bob/ros2-classroom/",
        "/user/alice/ros2-classroom/%2e%2e/%2e%2e/bob/api/status",
        "/user/alice/proxy/..%2F..%2Fbob/api/status",
        "/services/classroom-teacher/../../user/bob/api/status",
        "/services/classroom-teacher/..%2F..%2Fuser/bob/api/status",
    ):
        connection = http.client.HTTPConnection("127.0.0.1", hub.port, timeout=15)
        connection.request("GET", path, headers={"Authorization": f"token {tokens['alice']}"})
        response = connection.getresponse()
        text = response.read().decode(errors="replace")
        connection.close()
        assert 400 <= response.status < 500, (path, response.status, text[:300])
        assert "ros2 node list" not in text and '"started"' not in text, (path, text[:300])
    assert _shown(_teacher_table(hub, room)["bob"]) == bob_before

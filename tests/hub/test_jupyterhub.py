"""A class on a real JupyterHub: three learners, a teacher, the hub's login and proxy.

One hub for the module (deploy/jupyterhub_config.py with local overrides,
tests/hub/local_hub.py): jupyterhub from PyPI, configurable-http-proxy from
npm, DummyAuthenticator with one password, ClassroomLocalSpawner (each
learner's server as this account with its own HOME and ROS domain id). In
headless Chromium each learner logs in and lands in their own Classroom; the
teacher (a member of the hub's teachers group, not an admin) logs in to the
teacher service with the hub's OAuth and sees every row move.
"""

from __future__ import annotations

import http.client
import os
import re
import time
from collections.abc import Iterator
from dataclasses import replace

import pytest
from playwright.sync_api import Browser, BrowserContext, Page, expect

from app.dds import configure_dds_env
from app.hub.reports import to_json
from app.lessons.schema import load_course
from app.teacher.record import LearnerRecord
from tests.browser.helpers import choose, click, expect_text, open_tab, start_node
from tests.browser.test_exercise import EXERCISE, _open_editor, _type_code
from tests.conftest import ARTIFACTS, fail_on_leftover_nodes, in_private_netns, wait_until
from tests.hub.local_hub import PASSWORD, LocalHub

pytestmark = [pytest.mark.browser, pytest.mark.ros]

LEARNERS = ("alice", "bob", "carol")
TEACHER = "teacher"
SERVICE = "/services/classroom-teacher/"


@pytest.fixture(scope="module")
def hub(tmp_path_factory) -> Iterator[LocalHub]:
    if not in_private_netns():
        pytest.fail("the hub test runs learners' DDS: run it with tests/run.py")
    env = dict(os.environ)
    configure_dds_env(env, domain_id=59, network=False)  # the hub's own processes
    ARTIFACTS.mkdir(exist_ok=True)
    hub = LocalHub(
        tmp_path_factory.mktemp("hub"),
        env,
        learners=list(LEARNERS),
        teachers=[TEACHER],
        first_domain_id=60,
        log_path=ARTIFACTS / "jupyterhub.log",
    )
    try:
        hub.wait_ready()
        yield hub
    finally:
        alive = hub.stop()
        assert not alive, f"outlived the hub: {alive}"
        fail_on_leftover_nodes("the hub")


@pytest.fixture(scope="module")
def pages(hub: LocalHub, browser: Browser) -> Iterator[dict[str, Page]]:
    """Each learner logged in through the hub's form, in a browser context of their own."""
    contexts: list[BrowserContext] = []
    pages: dict[str, Page] = {}
    try:
        for user in (*LEARNERS, TEACHER):
            context = browser.new_context(viewport={"width": 1400, "height": 900})
            contexts.append(context)
            page = context.new_page()
            # A learner lands in their Classroom (spawned on login); the teacher goes
            # straight to the teacher service and starts no server of their own.
            after = f"?next={SERVICE}" if user == TEACHER else ""
            page.goto(f"{hub.base}/hub/login{after}")
            page.get_by_label("Username").fill(user)
            page.get_by_label("Password").fill(PASSWORD)
            # Logging in spawns the server; the spawn page then goes to default_url.
            with page.expect_navigation(wait_until="commit"):
                page.get_by_role("button", name="Sign in").click()
            pages[user] = page
        yield pages
    finally:
        for user, page in pages.items():
            page.screenshot(path=str(ARTIFACTS / f"hub-{user}.png"))
        for context in contexts:
            context.close()


def test_each_learner_gets_their_own_classroom(hub, pages):
    for user in LEARNERS:  # the three servers spawned while we logged in
        page = pages[user]
        page.wait_for_url(f"**/user/{user}/ros2-classroom/**", timeout=120_000)
        expect_text(page, "ros2 node list", timeout=90_000)  # the websocket is up

    # Alice runs a talker, Bob a listener: each sees their own node...
    start_node(pages["alice"], "talker")
    start_node(pages["bob"], "listener")
    for user, mine in (("alice", "/talker"), ("bob", "/listener")):
        open_tab(pages[user], "Graph")
        expect(pages[user].get_by_text(mine, exact=True).filter(visible=True).first).to_be_visible(
            timeout=30_000
        )
    # ...and, with their own node discovered (the other's ran for seconds by then), not the other's.
    expect(pages["alice"].get_by_text("/listener", exact=True)).to_have_count(0)
    expect(pages["bob"].get_by_text("/talker", exact=True)).to_have_count(0)

    # Every learner's server has a ROS domain of its own.
    domains = {u: p.environ()["ROS_DOMAIN_ID"] for u, p in hub.dashboards().items()}
    assert sorted(domains) == sorted(LEARNERS) and len(set(domains.values())) == 3, domains
    for user in LEARNERS:  # progress lives in each learner's own home
        assert (hub.homes / user / "ros2-classroom" / "progress").is_dir()


def _row(page: Page, user: str):
    return page.locator(f"#class tbody tr[data-learner='{user}']")


def test_the_teacher_sees_every_row_move_within_two_seconds(hub, pages):
    teacher = pages[TEACHER]
    teacher.goto(f"{hub.base}{SERVICE}")  # the hub's OAuth (done at login), then the page
    expect(teacher.get_by_text(f"Signed in through the hub as {TEACHER}")).to_be_visible()
    for user in LEARNERS:
        expect(_row(teacher, user)).to_be_visible(timeout=60_000)
    for user in LEARNERS:
        page = pages[user]
        open_tab(page, "Nodes")
        choose(page, "Catalog node", "listener2")
        click(page, "Start")
        clicked = time.monotonic()
        expect(_row(teacher, user)).to_contain_text("listener2", timeout=2_000)
        print(f"{user}: the teacher's row moved {time.monotonic() - clicked:.2f} s after Start")
        expect_text(page, "Started listener2")
    # Carol passes a lesson step in her Classroom; her row shows the next step.
    lesson = load_course().lessons[0]
    step = lesson.steps[0]
    carol = pages["carol"]
    open_tab(carol, "Lessons")
    choose(carol, "Lesson", f"{lesson.unit:02d} · {lesson.title}")
    for check in step.checks:
        if check.kind == "quiz":
            choose(carol, check["question"], check["answer"])
    expect(carol.get_by_text("✓ step done")).to_be_visible(timeout=45_000)
    click(carol, "Next")
    expect(_row(teacher, "carol")).to_contain_text(
        f"{lesson.unit} · 2/{len(lesson.steps)}", timeout=2_000
    )

    # Bob passes an exercise (his code runs in his own server); his row counts it.
    bob = pages["bob"]
    frame_locator, _frame = _open_editor(bob)
    _type_code(bob, frame_locator, EXERCISE.reference)
    click(bob, "Run my node")
    expect_text(bob, re.compile(r"running \(pid \d+\) · on the graph"), timeout=30_000)
    click(bob, "Check my node")
    expect_text(bob, "All checks pass. Exercise done!", timeout=30_000)
    expect(_row(teacher, "bob")).to_contain_text("1 passed", timeout=2_000)

    # The CSV export and a learner's code, as on `classroom`'s teacher page.
    csv = _teacher_get(hub, teacher, "progress.csv")
    assert csv.status == 200 and all(f"hub,{u}," in csv.text() for u in LEARNERS)
    detail = _teacher_get(hub, teacher, "learner.json?key=hub/bob")
    assert detail.status == 200 and detail.json()["key"] == "hub/bob"

    # A message to Carol reaches Carol's dashboard, not Alice's.
    teacher.select_option("#to", "hub/carol")
    teacher.fill("#text", "Look at the QoS of your subscriber")
    teacher.get_by_role("button", name="Send").click()
    expect(teacher.locator("#sent")).to_have_text("Sent.")
    expect_text(pages["carol"], "Look at the QoS of your subscriber", timeout=10_000)
    expect(pages["alice"].get_by_text("Look at the QoS of your subscriber")).to_have_count(0)


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


def _teacher_table(hub: LocalHub, pages: dict[str, Page]) -> dict[str, list]:
    """The teacher's table as the teacher's logged-in browser fetches it."""
    answer = _teacher_get(hub, pages[TEACHER], "progress.json")
    assert answer.status == 200, answer.text()
    return {row[0]: row for row in answer.json()["rows"]}


def _shown(row: list) -> tuple:
    """What a forged report would change: where Bob is and which nodes he runs."""
    return (row[0], row[1], row[2], row[5])


def test_bad_input_is_refused_with_a_clear_status(hub, pages):
    tokens = _tokens(hub)
    assert sorted(tokens) == sorted(LEARNERS), tokens
    wait_until(lambda: sorted(_teacher_table(hub, pages)) == sorted(LEARNERS), 30, what="3 rows")
    bob_before = _shown(_teacher_table(hub, pages)["bob"])

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
    assert _shown(_teacher_table(hub, pages)["bob"]) == bob_before

    # A learner's token on another learner's server, and on the teacher service.
    status, body = hub.api("GET", "/user/bob/api/status", token=tokens["alice"])
    assert status == 403, (status, body)  # Bob's server asks the hub whose token it is
    assert hub.api("GET", "/user/alice/api/status", token=tokens["alice"])[0] == 200
    status, body = hub.api("GET", f"{SERVICE}progress.json", token=tokens["alice"])
    assert status == 403 and "alice is not allowed" in body["error"], body

    # In the browser: Alice on Bob's Classroom URL, and on the teacher's page.
    alice = pages["alice"]
    answer = alice.goto(f"{hub.base}/user/bob/ros2-classroom/")
    assert answer is not None and answer.status in (403, 404), answer and answer.status
    answer = alice.goto(f"{hub.base}{SERVICE}")
    assert answer is not None and answer.status == 403, answer and answer.status

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
    assert _shown(_teacher_table(hub, pages)["bob"]) == bob_before

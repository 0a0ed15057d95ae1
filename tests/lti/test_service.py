"""LTI end to end in the teacher service: the test LMS and the real tornado app, over HTTP.

The LMS's side (login initiation, signed launches, the deep-linking return,
the token and score endpoints) is tests/lti/platform.py; the tool's side is
``make_app`` with its LTI handlers, as JupyterHub runs it. The hub's own part
of a launch, trading the handoff ticket for a login, is the authenticator of
app/hub/lti_login.py, called as the hub calls it.
"""

from __future__ import annotations

import asyncio
import base64
import concurrent.futures
import html
import json
import re
import time
import urllib.parse
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import jwt
import pytest

from app.hub.lti_catalog import course_activities
from app.hub.lti_login import LTI_USER_PREFIX, ClassroomLtiAuthenticator
from app.lti import claims
from app.lti.learners import hub_user_name
from app.lti.registration import load_registrations
from app.lti.tool import PLATFORMS_FILE
from app.teacher.record import LearnerRecord
from tests.course_data import shared_course, shared_exercises
from tests.lti.platform import CLIENT_ID, DEPLOYMENT_ID, TestPlatform
from tests.lti.service import (
    PREFIX,
    Answer,
    Clock,
    ServiceUnderTest,
    ToolUnderTest,
    request,
    wait_for,
)

INSTRUCTOR = "http://purl.imsglobal.org/vocab/lis/v2/membership#Instructor"
EXERCISE = "counter_publisher"  # lessons/05_topics/exercises/counter_publisher
LESSON = "05_topics"


def write_platforms(folder: Path, platform: TestPlatform) -> None:
    """What the administrator writes from the LMS's tool page."""
    r = platform.registration()
    folder.mkdir(parents=True, exist_ok=True)
    (folder / PLATFORMS_FILE).write_text(
        "[[platform]]\n"
        f'issuer = "{r.issuer}"\n'
        f'client_id = "{r.client_id}"\n'
        f'deployment_ids = ["{DEPLOYMENT_ID}"]\n'
        f'jwks_url = "{r.jwks_url}"\n'
        f'auth_login_url = "{r.auth_login_url}"\n'
        f'auth_token_url = "{r.auth_token_url}"\n'
    )


def start(folder: Path, platform: TestPlatform, clock: Clock | None = None) -> ServiceUnderTest:
    write_platforms(folder, platform)
    service = ServiceUnderTest(folder, clock)
    # The teacher set the LMS up with our keyset URL: the LMS knows the tool's key from it.
    platform.tool_jwks = json.loads(request("GET", service.urls.jwks).body)
    return service


@pytest.fixture
def service(platform: TestPlatform, tmp_path: Path) -> Iterator[ServiceUnderTest]:
    running = start(tmp_path / "lti", platform)
    yield running
    running.close()


# The LMS's side of a launch ------------------------------------------------------------


def login(service: ToolUnderTest, platform: TestPlatform, target: str) -> tuple[str, str]:
    """The LMS's login initiation; the state and nonce our redirect hands its auth step."""
    query = urllib.parse.urlencode(
        {
            "iss": platform.issuer,
            "login_hint": "hint-1",
            "target_link_uri": target,
            "client_id": CLIENT_ID,
            "lti_deployment_id": DEPLOYMENT_ID,
        }
    )
    answer = request("GET", f"{service.urls.login}?{query}")
    assert answer.status == 302, answer.body
    assert answer.location.startswith(f"{platform.url}/auth?")
    found = urllib.parse.parse_qs(urllib.parse.urlsplit(answer.location).query)
    assert found["redirect_uri"] == [target]
    return found["state"][0], found["nonce"][0]


def launch(
    service: ToolUnderTest, platform: TestPlatform, *, to: str = "", **claims_: Any
) -> Answer:
    target = to or service.urls.launch
    state, nonce = login(service, platform, target)
    token = platform.id_token(nonce, **{claims.TARGET_LINK_URI: target, **claims_})
    return request("POST", target, form={"id_token": token, "state": state})


def graded_link(item: str, custom: dict[str, str], link: str = "link-3") -> dict[str, Any]:
    return {
        claims.CUSTOM: custom,
        claims.RESOURCE_LINK: {"id": link},
        claims.AGS_ENDPOINT: {
            "scope": [claims.SCORE_SCOPE],
            "lineitem": f"{item}",
        },
    }


def hub_login(service: ServiceUnderTest, answer: Answer) -> dict[str, Any] | None:
    """What the hub's handoff page does with the launch's redirect: trade the ticket."""
    assert answer.status == 303, answer.body
    parts = urllib.parse.urlsplit(answer.location)
    assert parts.path == "/hub/lti-handoff"
    [ticket] = urllib.parse.parse_qs(parts.query)["ticket"]
    authenticator = ClassroomLtiAuthenticator(lti_service_url=service.url + PREFIX)
    trade = authenticator.get_authenticated_user(None, {"lti_ticket": ticket})
    # In a thread of its own: this worker's thread may hold a running event loop (a browser
    # test's Playwright ran on it before), where asyncio.run refuses to start.
    with concurrent.futures.ThreadPoolExecutor(1) as pool:
        found: dict[str, Any] | None = pool.submit(asyncio.run, trade).result(timeout=60)
    return found


# What a learner's dashboard reports ----------------------------------------------------


def exercise_record(name: str, passed: bool, slug: str = EXERCISE) -> LearnerRecord:
    return LearnerRecord(
        site="hub",
        learner=name,
        lesson_id=LESSON,
        unit=5,
        lesson_title="Topics: publishers and subscribers",
        step=3,
        steps=6,
        check_states=("pass", "fail"),
        check_reasons=("talker runs", "no listener yet"),
        exercise=slug,
        exercise_attempts_here=4,
        exercise_failed_here=3 if passed else 4,
        exercise_passed_here=passed,
        exercise_passed_seed=4242 if passed else 0,
        last_activity=time.time(),
    )


def lesson_record(name: str, step: int, states: tuple[str, ...]) -> LearnerRecord:
    return LearnerRecord(
        site="hub",
        learner=name,
        lesson_id=LESSON,
        unit=5,
        lesson_title="Topics: publishers and subscribers",
        step=step,
        steps=6,
        check_states=states,
        check_reasons=tuple(f"check {i + 1} ok" for i in range(len(states))),
    )


def refusal(answer: Answer) -> str:
    """The sentence of a refusal page, after checking it is a page and not a traceback."""
    assert answer.status == 400
    assert answer.headers["content-type"].startswith("text/html")
    assert "Traceback" not in answer.body and "location" not in answer.headers
    found = re.search(r'<p class="why">(.*?)</p>', answer.body, re.S)
    assert found, answer.body
    return html.unescape(found.group(1))


# Launches ------------------------------------------------------------------------------


def test_a_learner_launch_ends_logged_in_at_their_own_server(
    service: ServiceUnderTest, platform: TestPlatform
) -> None:
    answer = launch(
        service, platform, **graded_link(platform.lineitem_url("11"), {"exercise": EXERCISE})
    )
    user = hub_login(service, answer)
    name = hub_user_name(platform.issuer, "learner-42")
    assert user is not None
    # Their own server, opened at the launched exercise (the dashboard's ?exercise=).
    landing = f"/user/{name}/?exercise={EXERCISE}"
    assert (user["name"], user["lti_next"], user["lti_teacher"]) == (name, landing, False)
    assert re.fullmatch(r"lti-[a-z2-7]{16}", name) and name.startswith(LTI_USER_PREFIX)
    # The same person again (another link, another day) is the same learner; another is not.
    again = hub_login(service, launch(service, platform, **{claims.CUSTOM: {"lesson": LESSON}}))
    other = hub_login(service, launch(service, platform, sub="learner-43"))
    assert again is not None and again["name"] == name
    assert again["lti_next"] == f"/user/{name}/?lesson={LESSON}"
    assert other is not None and other["name"] == hub_user_name(platform.issuer, "learner-43")
    assert other["name"] != name


def test_a_handoff_ticket_logs_in_once(service: ServiceUnderTest, platform: TestPlatform) -> None:
    answer = launch(service, platform)
    assert hub_login(service, answer) is not None
    assert hub_login(service, answer) is None  # a copied redirect opens nothing


def test_an_instructor_launch_goes_to_the_teacher_page(
    service: ServiceUnderTest, platform: TestPlatform
) -> None:
    answer = launch(service, platform, sub="teacher-1", **{claims.ROLES: [INSTRUCTOR]})
    user = hub_login(service, answer)
    assert user is not None
    assert user["name"] == hub_user_name(platform.issuer, "teacher-1")
    assert (user["lti_next"], user["lti_teacher"]) == (PREFIX, True)


def _tampered(token: str) -> str:
    header, payload, signature = token.split(".")
    body = json.loads(base64.urlsafe_b64decode(payload + "=" * (-len(payload) % 4)))
    body["sub"] = "someone-else"  # the signature no longer covers what the token says
    forged = base64.urlsafe_b64encode(json.dumps(body).encode()).rstrip(b"=").decode()
    return f"{header}.{forged}.{signature}"


def test_a_tampered_expired_or_replayed_launch_gets_a_page_that_says_why(
    service: ServiceUnderTest, platform: TestPlatform
) -> None:
    url = service.urls.launch
    state, nonce = login(service, platform, url)
    token = _tampered(platform.id_token(nonce, **{claims.TARGET_LINK_URI: url}))
    answer = request("POST", url, form={"id_token": token, "state": state})
    assert "signature does not match the platform's key" in refusal(answer)

    state, nonce = login(service, platform, url)
    now = int(time.time())
    token = platform.id_token(nonce, exp=now - 3600, iat=now - 3900)
    assert "the id_token expired at" in refusal(
        request("POST", url, form={"id_token": token, "state": state})
    )

    state, nonce = login(service, platform, url)
    form = {"id_token": platform.id_token(nonce), "state": state}
    assert request("POST", url, form=form).status == 303
    assert "this launch is a replay" in refusal(request("POST", url, form=form))

    assert "no id_token" in refusal(request("POST", url, form={"state": state}))
    garbage = request("POST", url, form={"id_token": "not-a-jwt", "state": state})
    assert "not a readable JWT" in refusal(garbage)


def test_a_login_from_an_unknown_lms_gets_a_page(
    service: ServiceUnderTest, platform: TestPlatform
) -> None:
    query = urllib.parse.urlencode(
        {
            "iss": "https://lms.elsewhere.edu",
            "login_hint": "x",
            "target_link_uri": service.urls.launch,
        }
    )
    answer = request("GET", f"{service.urls.login}?{query}")
    assert "is not a platform registered with this tool" in refusal(answer)
    assert "This login from your course was refused" in answer.body


# Deep linking --------------------------------------------------------------------------


def test_a_teacher_picks_an_exercise_the_lms_makes_its_line_item_and_gets_its_grade(
    service: ServiceUnderTest, platform: TestPlatform
) -> None:
    settings = {
        "deep_link_return_url": f"{platform.url}/deep-link-return",
        "accept_types": ["ltiResourceLink"],
        "accept_multiple": False,
        "data": "opaque-platform-data",
    }
    picker = launch(
        service,
        platform,
        to=service.urls.deep_link,
        sub="teacher-1",
        **{
            claims.MESSAGE_TYPE: claims.DEEP_LINKING_REQUEST,
            claims.DEEP_LINKING_SETTINGS: settings,
            claims.RESOURCE_LINK: None,
            claims.AGS_ENDPOINT: None,
            claims.ROLES: [INSTRUCTOR],
        },
    )
    assert picker.status == 200 and picker.headers["content-type"].startswith("text/html")
    # Every lesson and exercise of the course, one to pick (the LMS takes one here).
    for activity in course_activities():
        assert f'value="{activity.kind}:{activity.slug}"' in picker.body
    assert 'type="radio" name="pick"' in picker.body and 'type="checkbox"' not in picker.body
    action = html.unescape(re.findall(r'<form method="post" action="([^"]+)"', picker.body)[0])
    token = html.unescape(re.findall(r'name="token" value="([^"]+)"', picker.body)[0])
    assert action == service.urls.deep_link + "/return"
    picks = {"token": token, "pick": f"exercise:{EXERCISE}", f"points-exercise:{EXERCISE}": "5"}
    back = request("POST", action, form=picks)
    assert back.status == 200, back.body
    # The page the browser auto-submits to the LMS: its return URL, our signed answer.
    return_url = html.unescape(re.findall(r'action="([^"]+)"', back.body)[0])
    response_jwt = html.unescape(re.findall(r'name="JWT" value="([^"]+)"', back.body)[0])
    assert return_url == settings["deep_link_return_url"]
    assert request("POST", return_url, form={"JWT": response_jwt}).status == 200
    assert platform.deep_link_refusals == []
    [link] = platform.links
    assert link["type"] == "ltiResourceLink" and link["url"] == service.urls.launch
    assert link["custom"] == {"exercise": EXERCISE, "score_maximum": "5"}
    assert link["lineItem"] == {
        "scoreMaximum": 5,
        "label": "Exercise (lesson 5): A counter on a topic",
        "resourceId": f"exercise:{EXERCISE}",
    }
    # The picker answers once: a second submit of the same form is refused.
    assert "already used" in refusal(request("POST", action, form=picks))

    # A learner opens the new link, passes, and the LMS's new column gets 5 of 5.
    lineitem = platform.lineitem_url(link["lineitem_id"])
    opened = launch(
        service, platform, **graded_link(lineitem, link["custom"], link["resource_link_id"])
    )
    user = hub_login(service, opened)
    assert user is not None
    assert service.report(exercise_record(user["name"], passed=True)).status == 200
    wait_for(lambda: bool(platform.scores[link["lineitem_id"]]), why="the score")
    [score] = platform.scores[link["lineitem_id"]]
    assert (score["userId"], score["scoreGiven"], score["scoreMaximum"]) == ("learner-42", 5, 5)


def test_a_picker_form_naming_no_activity_of_ours_is_refused(
    service: ServiceUnderTest, platform: TestPlatform
) -> None:
    picker = launch(
        service,
        platform,
        to=service.urls.deep_link,
        **{
            claims.MESSAGE_TYPE: claims.DEEP_LINKING_REQUEST,
            claims.DEEP_LINKING_SETTINGS: {"deep_link_return_url": f"{platform.url}/r"},
            claims.ROLES: [INSTRUCTOR],
        },
    )
    token = html.unescape(re.findall(r'name="token" value="([^"]+)"', picker.body)[0])
    action = service.urls.deep_link + "/return"
    forged = request("POST", action, form={"token": token, "pick": "exercise:rm_rf"})
    assert "'exercise:rm_rf' is not a lesson or exercise of this course" in refusal(forged)
    assert "nothing was picked" in refusal(request("POST", action, form={"token": token}))
    assert "already used" in refusal(request("POST", action, form={"token": "made-up"}))


# Grades ----------------------------------------------------------------------------------


def test_a_passed_exercise_reaches_its_line_item_once_and_a_worse_result_never_replaces_it(
    service: ServiceUnderTest, platform: TestPlatform
) -> None:
    exercise_link = graded_link(
        platform.lineitem_url("11"), {"exercise": EXERCISE, "score_maximum": "5"}
    )
    user = hub_login(service, launch(service, platform, **exercise_link))
    assert user is not None
    name = user["name"]
    assert service.report(exercise_record(name, passed=False)).status == 200
    assert service.report(exercise_record(name, passed=True)).status == 200
    wait_for(lambda: bool(platform.scores["11"]), why="the exercise's score")
    [score] = platform.scores["11"]
    assert score["userId"] == "learner-42"
    assert (score["scoreGiven"], score["scoreMaximum"]) == (5, 5)
    assert (score["activityProgress"], score["gradingProgress"]) == ("Completed", "FullyGraded")
    assert f"Exercise {EXERCISE} passed" in score["comment"]
    assert "live ROS 2 graph" in score["comment"]
    assert "(4 grading run(s), 3 failed check(s) before the pass)" in score["comment"]
    assert f"exercise check {EXERCISE} FILE --seed 4242`" in score["comment"]
    assert "+00:00" in score["timestamp"]

    # Later: the exercise shows as not passed (reset), then passed again; and a learner who
    # never came from the LMS passes too. None of it reaches the LMS.
    assert service.report(exercise_record(name, passed=False)).status == 200
    assert service.report(exercise_record(name, passed=True)).status == 200
    assert service.report(exercise_record("alice", passed=True)).status == 200
    # A result that does count, to another column, shows the rounds ran meanwhile.
    user = hub_login(
        service,
        launch(
            service,
            platform,
            **graded_link(platform.lineitem_url("12"), {"lesson": LESSON}, "link-4"),
        ),
    )
    assert service.report(lesson_record(name, step=5, states=("pass",))).status == 200
    assert service.report(lesson_record(name, step=6, states=("pass", "fail"))).status == 200
    assert (
        service.report(lesson_record(name, step=6, states=("pass", "pass", "pass"))).status == 200
    )
    wait_for(lambda: bool(platform.scores["12"]), why="the lesson's score")
    [lesson_score] = platform.scores["12"]
    assert (lesson_score["scoreGiven"], lesson_score["scoreMaximum"]) == (1, 1)
    assert (
        "Lesson 5 (Topics: publishers and subscribers) done: all 6 steps" in lesson_score["comment"]
    )
    assert "check 3 ok" in lesson_score["comment"]
    assert platform.scores["11"] == [score]  # still the one pass, sent once
    assert len([r for r in platform.score_requests if r[0] == "/lineitems/11/scores"]) == 1


def test_an_lms_that_is_down_gets_the_score_later_even_across_a_restart(
    platform: TestPlatform, tmp_path: Path
) -> None:
    folder, clock = tmp_path / "lti", Clock()
    first = start(folder, platform, clock)
    try:
        link = graded_link(platform.lineitem_url("11"), {"exercise": EXERCISE})
        user = hub_login(first, launch(first, platform, **link))
        assert user is not None
        name = user["name"]
        lesson_link = graded_link(platform.lineitem_url("12"), {"lesson": LESSON}, "link-4")
        assert hub_login(first, launch(first, platform, **lesson_link)) is not None
        platform.fail_next("11", 503, "maintenance")
        assert first.report(exercise_record(name, passed=True)).status == 200
        wait_for(lambda: len(platform.score_requests) == 1, why="the first try")
    finally:
        first.close()  # the service stops while the score waits for its retry
    assert platform.scores["11"] == []

    second = start(folder, platform, clock)  # a new process on the same folder
    try:
        clock.ahead += 6  # past the first retry's wait (5 s)
        wait_for(lambda: bool(platform.scores["11"]), why="the retried score")
        # The launches survived too: a lesson finished now reaches its own column.
        done = lesson_record(name, step=6, states=("pass", "pass", "pass"))
        assert second.report(done).status == 200
        wait_for(lambda: bool(platform.scores["12"]), why="the lesson's score")
        assert len(platform.scores["11"]) == 1
        assert len(platform.score_requests) == 3  # the 503, the retry, the lesson
    finally:
        second.close()


# Set-up pieces -----------------------------------------------------------------------------


def test_the_jwks_url_serves_the_key_that_signs_the_tools_answers(
    service: ServiceUnderTest,
) -> None:
    answer = request("GET", service.urls.jwks)
    assert answer.status == 200 and answer.headers["content-type"] == "application/json"
    served = json.loads(answer.body)
    assert served == service.tool.keys.public_jwks()
    signed = service.tool.keys.sign({"iss": CLIENT_ID})
    key = jwt.PyJWKSet.from_dict(served)[jwt.get_unverified_header(signed)["kid"]]
    assert jwt.decode(signed, key, algorithms=["RS256"])["iss"] == CLIENT_ID
    assert "d" not in served["keys"][0]


def test_the_picker_lists_exactly_what_the_course_loaders_load() -> None:
    # The loaders check lessons against the ROS layer, so this imports it (no ROS runs).

    listed = [(a.kind, a.slug) for a in course_activities()]
    course, book = shared_course(), shared_exercises()
    assert sorted(s for k, s in listed if k == "lesson") == sorted(
        lesson.id for lesson in course.lessons
    )
    assert sorted(s for k, s in listed if k == "exercise") == sorted(e.slug for e in book.exercises)
    titles = {(a.kind, a.slug): a.title for a in course_activities()}
    counter = next(e for e in book.exercises if e.slug == EXERCISE)
    assert titles[("exercise", EXERCISE)].endswith(counter.title)


def test_the_platforms_file_is_read_and_a_mistake_is_named(
    platform: TestPlatform, tmp_path: Path
) -> None:
    write_platforms(tmp_path, platform)
    [registration] = load_registrations(tmp_path / PLATFORMS_FILE)
    assert registration == platform.registration()
    assert list(load_registrations(tmp_path / "absent.toml")) == []
    broken = tmp_path / "broken.toml"
    broken.write_text('[[platform]]\nissuer = "https://lms.edu"\nclient_id = "x"\n')
    with pytest.raises(ValueError, match="platform 1: jwks_url must be a non-empty string"):
        load_registrations(broken)
    broken.write_text(
        (tmp_path / PLATFORMS_FILE).read_text().replace("deployment_ids", "deployments")
    )
    with pytest.raises(ValueError, match="unknown field\\(s\\) deployments"):
        load_registrations(broken)


def test_the_hub_config_for_lti_wires_the_authenticator_and_the_service(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from traitlets.config.loader import PyFileConfigLoader

    from app import PROJECT_ROOT

    monkeypatch.setenv("CLASSROOM_LTI_URL", "https://hub.example.edu/services/classroom-teacher")
    monkeypatch.delenv("CLASSROOM_SAME_ACCOUNT", raising=False)
    monkeypatch.delenv("CLASSROOM_LTI_DIR", raising=False)
    deploy = PROJECT_ROOT / "deploy"
    (tmp_path / "hub_config.py").write_text(
        f"load_subconfig({str(deploy / 'jupyterhub_config.py')!r})\n"
        f"load_subconfig({str(deploy / 'lti_tool_config.py')!r})\n"
    )
    c = PyFileConfigLoader("hub_config.py", path=str(tmp_path)).load_config()
    assert c.JupyterHub.authenticator_class == "app.hub.lti_login.ClassroomLtiAuthenticator"
    (service,) = c.JupyterHub.services
    assert service["environment"] == {
        "CLASSROOM_LTI_URL": "https://hub.example.edu/services/classroom-teacher"
    }
    # The hub reaches the service where the service listens.
    assert c.ClassroomLtiAuthenticator.lti_service_url == service["url"] + PREFIX
    assert c.JupyterHub.spawner_class == "app.hub.spawner.ClassroomLocalSpawner"

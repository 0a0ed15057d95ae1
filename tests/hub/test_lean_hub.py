"""The lean mode on a real JupyterHub: the dashboard itself is each learner's single-user server.

deploy/jupyterhub_config.py with CLASSROOM_SINGLEUSER=dashboard: the spawner
runs ``ros2-classroom serve --jupyterhub`` as each learner's server, and the
dashboard logs learners in with the hub's OAuth (app/hub/singleuser_auth.py).
One hub for the module, two learners and a teacher in headless Chromium; the
lab mode (JupyterLab and its launcher) is test_jupyterhub.py.
"""

from __future__ import annotations

import os
import re
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from datetime import datetime, timezone

import pytest
import websockets.sync.client as ws_client
from playwright.sync_api import Browser, BrowserContext, Page, expect
from websockets.exceptions import InvalidStatus

from app.dds import configure_dds_env
from tests.browser.helpers import choose, click, expect_text, open_tab
from tests.conftest import ARTIFACTS, fail_on_leftover_nodes, in_private_netns, wait_until
from tests.hub.local_hub import ADMIN_TOKEN, LocalHub, log_in

# A watchdog, not a budget: the first test also spawns two learners' servers, which
# on two busy shared cores has taken minutes.
pytestmark = [pytest.mark.browser, pytest.mark.ros, pytest.mark.timeout(480)]

LEARNERS = ("dora", "erik")
TEACHER = "tess"
SERVICE = "/services/classroom-teacher/"
ACTIVITY_SEC = 1  # how often a dashboard reports activity here (the hub's default is 300)


@pytest.fixture(scope="module")
def hub(tmp_path_factory) -> Iterator[LocalHub]:
    if not in_private_netns():
        pytest.fail("the hub test runs learners' DDS: run it with tests/run.py")
    env = dict(os.environ)
    configure_dds_env(env, domain_id=69, network=False)  # the hub's own processes
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    hub = LocalHub(
        tmp_path_factory.mktemp("lean-hub"),
        env,
        learners=list(LEARNERS),
        teachers=[TEACHER],
        first_domain_id=70,
        log_path=ARTIFACTS / "jupyterhub-lean.log",
        singleuser="dashboard",
        activity_interval=ACTIVITY_SEC,
    )
    try:
        hub.wait_ready()
        yield hub
    finally:
        alive = hub.stop()
        assert not alive, f"outlived the hub: {alive}"
        fail_on_leftover_nodes("the lean hub")


class Browsers:
    def __init__(self) -> None:
        self.contexts: dict[str, BrowserContext] = {}
        self.pages: dict[str, Page] = {}
        self.urls: dict[str, list[str]] = {}  # every request and websocket each browser opened


@pytest.fixture(scope="module")
def room(hub: LocalHub, browser: Browser) -> Iterator[Browsers]:
    """Each learner logged in through the hub's form (their server spawning), and the teacher."""
    room = Browsers()
    try:
        for user in (*LEARNERS, TEACHER):
            context = browser.new_context(viewport={"width": 1400, "height": 900})
            room.contexts[user] = context
            urls = room.urls[user] = []
            context.on("request", lambda request, urls=urls: urls.append(request.url))
            page = context.new_page()
            page.on("websocket", lambda socket, urls=urls: urls.append(socket.url))
            log_in(
                page,
                f"{hub.base}/hub/login" + (f"?next={SERVICE}" if user == TEACHER else ""),
                user,
            )
            room.pages[user] = page
        yield room
    finally:
        for user, page in room.pages.items():
            page.screenshot(path=str(ARTIFACTS / f"hub-lean-{user}.png"))
        for context in room.contexts.values():
            context.close()


def vertex(page: Page, node: str):
    return page.locator(f'svg.stage-graph g.sg-vertex[data-name="/{node}"]')


def _service_url(hub: LocalHub, user: str) -> str:
    """Where the learner's dashboard listens, past the hub's proxy."""
    return hub.single_user_servers()[user].environ()["JUPYTERHUB_SERVICE_URL"]


def test_each_learner_lands_in_their_own_dashboard_through_the_hubs_oauth(hub, room):
    started = time.monotonic()
    for user in LEARNERS:
        page = room.pages[user]
        page.wait_for_url(f"**/user/{user}/**", timeout=120_000)
        expect_text(page, "ros2 node list", timeout=120_000)  # the websocket is up
    print(f"two lean learners in their Classrooms {time.monotonic() - started:.1f} s after login")
    for user in LEARNERS:
        urls = room.urls[user]
        # The hub's OAuth round trip, then the page and its websocket under the base path.
        assert any(u.startswith(f"{hub.base}/hub/api/oauth2/authorize?") for u in urls), urls
        assert any(u.startswith(f"{hub.base}/user/{user}/oauth_callback?code=") for u in urls)
        assert f"ws://127.0.0.1:{hub.port}/user/{user}/" in urls, urls
        tokened = [u for u in urls if re.search(r"[?&](token|access_token)=", u)]
        assert not tokened, tokened  # the login is a cookie: no token ever in a URL
        (cookie,) = [
            c for c in room.contexts[user].cookies() if c["name"] == f"jupyterhub-user-{user}"
        ]
        assert cookie["path"] == f"/user/{user}/" and cookie["httpOnly"], cookie
        # The dashboard is the learner's server itself: no Jupyter server in between.
        server = hub.single_user_servers()[user]
        assert "--jupyterhub" in server.cmdline() and hub.dashboards()[user].pid == server.pid
        # A fork of the hub's one warm parent (app/hub/spawner.py), yet the hub's own child.
        log = hub.log_tail(10**7)
        assert f"warm start: this dashboard (pid {server.pid}) is a fork" in log, log[-3000:]
        assert server.ppid() == hub.proc.pid

    # Each learner's nodes on their own graph only, both ways (the websocket works both ways).
    dora, erik = room.pages["dora"], room.pages["erik"]
    for page, node in ((dora, "talker"), (erik, "listener")):
        open_tab(page, "Nodes")
        choose(page, "Catalog node", node)
        click(page, "Start")
    for page, mine, theirs in ((dora, "talker", "listener"), (erik, "listener", "talker")):
        expect(vertex(page, mine)).to_be_visible(timeout=30_000)
        expect(vertex(page, theirs)).to_have_count(0)
    # A stage box is a page link (classroom/act/...): it works under the hub's base path.
    # Clicked once the picture is steady: the talker listed by DDS, its topic's rate drawn
    # (each of those redraws the picture; a click across a redraw lands on no link).
    expect(vertex(dora, "talker")).to_have_attribute("data-state", "on-graph", timeout=30_000)
    expect(dora.locator("svg.stage-graph").get_by_text("2.0 Hz")).to_be_visible(timeout=30_000)
    vertex(dora, "talker").locator("a").click()
    node_card = dora.get_by_text("Node /talker", exact=True).filter(visible=True)
    expect(node_card).to_be_visible(timeout=20_000)

    # Progress reaches the teacher service as in the lab mode (HTTP with the hub's token).
    teacher = room.pages[TEACHER]
    teacher.wait_for_url(f"**{SERVICE}**")
    for user, node in (("dora", "talker"), ("erik", "listener")):
        row = teacher.locator(f"#class tbody tr[data-learner='{user}']")
        expect(row).to_contain_text(node, timeout=10_000)


def _get(url: str, headers: dict[str, str] | None = None) -> tuple[int, dict[str, str], str]:
    """One GET that does not follow redirects: status, headers, body."""

    class NoRedirect(urllib.request.HTTPRedirectHandler):
        def redirect_request(self, *args, **kwargs):
            return None

    opener = urllib.request.build_opener(NoRedirect)
    request = urllib.request.Request(url, headers=headers or {})
    try:
        with opener.open(request, timeout=15) as answer:
            return answer.status, dict(answer.headers), answer.read().decode(errors="replace")
    except urllib.error.HTTPError as error:
        return error.code, dict(error.headers), error.read().decode(errors="replace")


def _socket_status(url: str, headers: dict[str, str] | None = None) -> int:
    """The status a websocket upgrade gets (101 when it opens)."""
    try:
        with ws_client.connect(url, additional_headers=headers, open_timeout=15):
            return 101
    except InvalidStatus as error:
        return error.response.status_code


def test_another_learner_and_strangers_are_refused(hub, room):
    dora = room.contexts["dora"].new_page()
    try:  # Dora opens Erik's Classroom: Erik's server sends her to the hub, which refuses
        answer = dora.goto(f"{hub.base}/user/erik/")
        assert answer is not None and answer.status == 403, answer and answer.status
        assert "/hub/api/oauth2/authorize" in dora.url, dora.url
        expect(dora.get_by_text("ros2 node list")).to_have_count(0)
        answer = dora.goto(f"{hub.base}{SERVICE}")  # and she is no teacher
        assert answer is not None and answer.status == 403, answer and answer.status
    finally:
        dora.close()

    tokens = {u: p.environ()["JUPYTERHUB_API_TOKEN"] for u, p in hub.single_user_servers().items()}
    erik_url = _service_url(hub, "erik")  # http://127.0.0.1:PORT/user/erik/
    erik_socket = erik_url.replace("http://", "ws://")
    # Dora's own token works on her server, not on Erik's; the hub's own admin token does.
    status, _, body = _get(f"{hub.base}/user/erik/", {"Authorization": f"token {tokens['dora']}"})
    assert status == 403 and "dora may not open erik's" in body, (status, body)
    status, _, body = _get(f"{hub.base}/user/dora/", {"Authorization": f"token {tokens['dora']}"})
    assert status == 200 and "<html" in body.lower(), status
    assert _get(f"{hub.base}/user/erik/", {"Authorization": f"token {ADMIN_TOKEN}"})[0] == 200
    # Every answer says the connection ends (websockets closes it): the hub's proxy must
    # not keep the socket for a websocket upgrade ("503 socket hang up" otherwise).
    status, headers, _ = _get(_service_url(hub, "erik"), {"Authorization": f"token {ADMIN_TOKEN}"})
    assert status == 200 and headers.get("Connection") == "close", headers
    # Past the proxy, straight at Erik's port: without his cookie, no page and no websocket.
    status, headers, _ = _get(erik_url)
    assert status == 302 and "/hub/api/oauth2/authorize?" in headers["Location"], headers
    assert "client_id=jupyterhub-user-erik" in headers["Location"]
    assert _socket_status(erik_socket) == 401
    # Dora's cookie (signed by her server) passed off as Erik's, or a made-up one: refused.
    (dora_cookie,) = [
        c for c in room.contexts["dora"].cookies() if c["name"] == "jupyterhub-user-dora"
    ]
    for value in (dora_cookie["value"], "x|1|00", ""):
        assert _socket_status(erik_socket, {"Cookie": f"jupyterhub-user-erik={value}"}) == 401
    # A token in the URL is never taken (it would leak into logs and history).
    status, headers, _ = _get(f"{erik_url}?token={tokens['erik']}")
    assert status == 302 and "oauth2/authorize" in headers["Location"], (status, headers)
    # A callback whose state this browser never started, and one the hub refused.
    status, _, body = _get(f"{erik_url}oauth_callback?code=abc&state=forged")
    assert status == 400 and "OAuth state" in body, (status, body)
    status, _, body = _get(f"{erik_url}oauth_callback?error=access_denied")
    assert status == 403 and "access_denied" in body, (status, body)
    # Paths that climb out of the base path, even for an admin: nothing served, no crash.
    root = erik_url.split("/user/")[0]
    admin = {"Authorization": f"token {ADMIN_TOKEN}"}
    for path in ("/user/erik/%2e%2e/%2e%2e/etc/passwd", "/user/erik/../../etc/passwd", "/etc/"):
        status, _, body = _get(root + path, admin)
        assert status == 404 and "root:" not in body, (path, status, body[:200])
    # Erik's dashboard still serves Erik: a reload comes straight back with his cookie.
    erik = room.pages["erik"]
    before = len(room.urls["erik"])
    erik.reload()
    expect_text(erik, "ros2 node list", timeout=60_000)
    assert not [u for u in room.urls["erik"][before:] if "oauth" in u], room.urls["erik"][before:]


def _last_activity(hub: LocalHub, user: str) -> datetime:
    stamp = hub.api("GET", f"/hub/api/users/{user}")[1]["servers"][""]["last_activity"]
    return datetime.fromisoformat(stamp.replace("Z", "+00:00"))


def _settled(hub: LocalHub, user: str, quiet_sec: float, within_sec: float) -> datetime:
    """The user's last activity once it has stood still for ``quiet_sec`` (a page just
    loaded sends its first camera and layout messages for a few seconds)."""
    last, since = _last_activity(hub, user), time.monotonic()
    deadline = since + within_sec
    while time.monotonic() < deadline:
        time.sleep(0.5)
        now = _last_activity(hub, user)
        if now != last:
            last, since = now, time.monotonic()
        elif time.monotonic() - since >= quiet_sec:
            return last
    pytest.fail(f"{user}'s idle page kept reporting activity for {within_sec:.0f} s")


def test_the_learners_clicks_reach_the_hub_as_activity(hub, room):
    """The hub's idle culler stops servers whose last activity is old: an idle page must
    go quiet, a click must count (the hub's own proxy polling is off in the test hub)."""
    erik = room.pages["erik"]
    _settled(hub, "erik", quiet_sec=4 * ACTIVITY_SEC, within_sec=60)
    clicked = datetime.now(timezone.utc)
    open_tab(erik, "Nodes")
    choose(erik, "Catalog node", "talker")  # a choice the dashboard hears
    wait_until(
        lambda: _last_activity(hub, "erik") >= clicked,
        timeout=10 * ACTIVITY_SEC + 5,
        what="Erik's click to reach the hub's activity record",
    )

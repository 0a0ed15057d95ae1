"""Serving beyond loopback needs --allow-remote and a token; without it nothing is visible.

The dashboard binds 0.0.0.0 here, which is safe: tests/run.py gives this
test a private network namespace whose only card is loopback, and we reach
the server as 127.0.0.2, an address other than the default 127.0.0.1.
"""

from __future__ import annotations

import urllib.error
import urllib.request

import pytest
from websockets.exceptions import InvalidStatus

from tests.browser.helpers import expect_text, open_tab
from tests.conftest import DashboardProcess, free_port, started_by, wait_until
from tests.wire_client import WireClient

pytestmark = [pytest.mark.browser, pytest.mark.ros]

TOKEN = "classroom-test-token-0123456789"


@pytest.fixture
def remote_dashboard(ros_env, progress_dir):
    port = free_port()
    extra = ["--host", "0.0.0.0", "--allow-remote", "--token", TOKEN]
    dash = DashboardProcess(ros_env, port, [*extra, "--progress-dir", str(progress_dir)])
    dash.url = f"http://127.0.0.2:{port}"
    yield dash
    dash.stop()


def _get(url: str, headers: dict[str, str] | None = None) -> tuple[int, dict[str, str], str]:
    request = urllib.request.Request(url, headers=headers or {})
    try:
        with urllib.request.urlopen(request, timeout=10) as response:
            body = response.read(200).decode(errors="replace")
            return response.status, dict(response.headers), body
    except urllib.error.HTTPError as err:
        return err.code, dict(err.headers), err.read().decode(errors="replace")


def test_without_the_token_nothing_is_served_or_accepted(remote_dashboard):
    url = remote_dashboard.url
    assert f"/?token={TOKEN}" in remote_dashboard.log()  # the URL to hand out
    for path in ("/", "/?token=wrong-token-0123456789", "/index.html", "/../etc/passwd"):
        status, _headers, body = _get(url + path)
        assert status == 401, (path, status)
        assert "access token" in body and "<script" not in body
    for ws_url in (url, url + "/?token=nope"):
        with pytest.raises(InvalidStatus) as info:
            WireClient(ws_url)
        assert info.value.response.status_code == 401
    with pytest.raises(InvalidStatus):  # a forged cookie is no better
        WireClient(url, headers={"Cookie": f"classroom_token_{remote_dashboard.port}=guess"})
    assert started_by(remote_dashboard.proc.pid) == []
    # ...and the server still serves whoever has the token.
    status, headers, _body = _get(f"{url}/?token={TOKEN}")
    assert status == 200
    assert "HttpOnly" in headers["Set-Cookie"] and "SameSite=Strict" in headers["Set-Cookie"]


def test_with_the_token_a_client_watches_and_controls(remote_dashboard):
    url = remote_dashboard.url
    client = WireClient(f"{url}/?token={TOKEN}")
    try:
        wait_until(lambda: client.find("Start", "GuiButtonMessage"), what="the Nodes panel")
        client.click("Start")  # the catalog's first node, talker
        wait_until(
            lambda: started_by(remote_dashboard.proc.pid),
            what="the talker process",
        )
        wait_until(lambda: "Started **talker**" in client.markdown(), what="the start message")
    finally:
        client.close()
    cookie = {"Cookie": f"classroom_token_{remote_dashboard.port}={TOKEN}"}
    by_cookie = WireClient(url, headers=cookie)
    by_cookie.close()
    with pytest.raises(InvalidStatus) as info:  # another site's page, even with the cookie
        WireClient(url, headers={**cookie, "Origin": "http://evil.example"})
    assert info.value.response.status_code == 403


def test_a_browser_needs_the_token_url(browser, remote_dashboard):
    context = browser.new_context()
    try:
        page = context.new_page()
        page.goto(remote_dashboard.url)
        assert "access token" in page.content()
        page.goto(f"{remote_dashboard.url}/?token={TOKEN}")
        open_tab(page, "Nodes")
        expect_text(page, "Catalog node")  # the websocket carried the cookie
        page.goto(remote_dashboard.url)  # the cookie alone now admits this browser
        open_tab(page, "Nodes")
        expect_text(page, "Catalog node")
    finally:
        context.close()


def test_the_exercise_editor_is_behind_the_token_too(remote_dashboard):
    import json

    from websockets.sync.client import connect

    url = remote_dashboard.url
    cookie = {"Cookie": f"classroom_token_{remote_dashboard.port}={TOKEN}"}
    for path in (
        "/classroom/editor/editor.html?slug=multiply_service",
        "/classroom/editor/ace/ace.js",
    ):
        assert _get(url + path)[0] == 401, path
        assert _get(url + path, cookie)[0] == 200, path
    socket_url = url.replace("http://", "ws://") + "/classroom/editor/ws?slug=multiply_service"
    with pytest.raises(InvalidStatus) as info:
        connect(socket_url, open_timeout=10)
    assert info.value.response.status_code == 401
    with connect(socket_url, additional_headers=cookie, open_timeout=10) as editor:
        first = json.loads(editor.recv(timeout=10))
    assert first["type"] == "load" and "class Multiplier(Node)" in first["code"]


def test_learner_code_does_not_run_on_a_served_dashboard_without_consent(browser, remote_dashboard):
    context = browser.new_context()
    try:
        page = context.new_page()
        page.goto(f"{remote_dashboard.url}/?token={TOKEN}")
        open_tab(page, "Exercise")
        page.get_by_role("button", name="Run my node", exact=True).click()
        expect_text(page, "learner code runs only when the teacher starts it")
    finally:
        context.close()
    assert started_by(remote_dashboard.proc.pid) == []

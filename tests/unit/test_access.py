"""The token gate's rules, without a server: what the CLI refuses, and what a request needs."""

from __future__ import annotations

import pytest
from websockets.datastructures import Headers
from websockets.http11 import Request

from app.access import AccessError, TokenGate, check_token, new_token
from tests.unit.test_cli import run_cli


def test_serving_elsewhere_needs_allow_remote_and_a_sane_token():
    refused = run_cli("serve", "--host", "0.0.0.0", "--port", "1")
    assert refused.returncode == 2 and "--allow-remote" in refused.stderr
    weak = run_cli("serve", "--host", "0.0.0.0", "--allow-remote", "--token", "abc")
    assert weak.returncode == 2 and "16-128 characters" in weak.stderr
    assert "Traceback" not in weak.stderr + refused.stderr


def test_generated_tokens_are_url_safe_and_differ():
    tokens = {new_token() for _ in range(20)}
    assert len(tokens) == 20 and all(check_token(t) for t in tokens)
    for bad in ("", "short", "a" * 200, "token with spaces here!", "x" * 15 + "/"):
        with pytest.raises(AccessError):
            check_token(bad)


class _Conn:
    def respond(self, status, text):
        return (int(status), text)


def _request(path: str, **headers: str) -> Request:
    return Request(path, Headers(headers))


def test_gate_admits_only_the_token_by_query_or_cookie():
    token = "T" * 20
    gate = TokenGate(token, 8080)
    served = gate.wrap(lambda conn, req: None)  # viser's part: None lets the websocket open
    conn = _Conn()
    assert served(conn, _request("/"))[0] == 401
    assert served(conn, _request("/?token=" + "U" * 20))[0] == 401
    assert served(conn, _request("/", Cookie="classroom_token_8081=" + token))[0] == 401
    assert served(conn, _request("/", Cookie="garbage;;;=\\"))[0] == 401
    assert served(conn, _request(f"/?token={token}")) is None
    assert served(conn, _request("/", Cookie=f"a=b; classroom_token_8080={token}")) is None
    cross = _request(
        f"/?token={token}", Upgrade="websocket", Origin="http://evil.example", Host="h:8080"
    )
    assert served(conn, cross)[0] == 403
    assert gate.rejected == 5

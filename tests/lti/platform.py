"""A small LMS for the LTI tests: a real HTTP server in a thread, with its own key pair.

It plays the platform's side of LTI 1.3 the way the specifications describe
it: a JWKS endpoint with its public key, id_tokens it signs for launches, an
OAuth 2 token endpoint that accepts only a client assertion signed by the
tool's key (checked against the tool's JWKS, as pasted by a teacher), and
AGS line items that keep the scores posted to them. A test can make a line
item answer errors for a while, revoke the tokens it issued, or rotate its key.
"""

from __future__ import annotations

import json
import secrets
import threading
import time
import urllib.parse
from collections import defaultdict
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any

import jwt
from cryptography.hazmat.primitives.asymmetric import rsa

from app.lti import claims
from app.lti.registration import PlatformRegistration

CLIENT_ID = "classroom-tool-1"
DEPLOYMENT_ID = "deployment-7"
SCORE_MEDIA_TYPE = "application/vnd.ims.lis.v1.score+json"


_first_key: list[rsa.RSAPrivateKey] = []


def _platform_key() -> rsa.RSAPrivateKey:
    """One key for every test platform of a run: making RSA keys is the slow part."""
    if not _first_key:
        _first_key.append(rsa.generate_private_key(public_exponent=65537, key_size=2048))
    return _first_key[0]


def _public_jwk(key: rsa.RSAPrivateKey, kid: str) -> dict[str, Any]:
    jwk = json.loads(jwt.algorithms.RSAAlgorithm.to_jwk(key.public_key()))
    return {**jwk, "kid": kid, "alg": "RS256", "use": "sig"}


class TestPlatform:
    __test__ = False  # not a test class, whatever its name

    def __init__(self) -> None:
        self._key = _platform_key()
        self.kid = "platform-key-1"
        self.tool_jwks: dict[str, Any] | None = None  # what the teacher pasted
        self.token_life_sec = 3600
        self.tokens: dict[str, float] = {}  # access token -> expires at
        self.token_requests = 0
        self.token_refusals: list[str] = []
        self.jwks_fetches = 0
        self.used_jtis: set[str] = set()
        self.scores: dict[str, list[dict[str, Any]]] = defaultdict(list)  # line item -> bodies
        self.score_requests: list[tuple[str, str, str]] = []  # (path, query, content type)
        self.scripted: dict[str, list[tuple[int, str]]] = defaultdict(list)  # next answers
        # Deep linking: what came back from the tool, and the line items made from it.
        self.deep_link_refusals: list[str] = []
        self.links: list[dict[str, Any]] = []  # content items, each with its made line item
        self.lock = threading.Lock()
        self._server = ThreadingHTTPServer(("127.0.0.1", 0), self._handler())
        self._thread = threading.Thread(
            target=self._server.serve_forever, kwargs={"poll_interval": 0.05}, daemon=True
        )
        self._thread.start()
        self.url = f"http://127.0.0.1:{self._server.server_address[1]}"

    @property
    def issuer(self) -> str:
        return self.url

    def close(self) -> None:
        self._server.shutdown()
        self._server.server_close()
        self._thread.join(timeout=5)

    def registration(self, **changes: Any) -> PlatformRegistration:
        values: dict[str, Any] = {
            "issuer": self.issuer,
            "client_id": CLIENT_ID,
            "deployment_ids": frozenset({DEPLOYMENT_ID}),
            "jwks_url": f"{self.url}/jwks",
            "auth_login_url": f"{self.url}/auth?lms=moodle",
            "auth_token_url": f"{self.url}/token",
        }
        return PlatformRegistration(**{**values, **changes})

    def lineitem_url(self, item: str, query: str = "") -> str:
        return f"{self.url}/lineitems/{item}" + (f"?{query}" if query else "")

    # What the LMS does -----------------------------------------------------------------

    def rotate_key(self) -> None:
        self._key = rsa.generate_private_key(public_exponent=65537, key_size=2048)
        self.kid = f"platform-key-{secrets.token_hex(4)}"

    def launch_claims(self, nonce: str, **overrides: Any) -> dict[str, Any]:
        now = int(time.time())
        body: dict[str, Any] = {
            "iss": self.issuer,
            "aud": CLIENT_ID,
            "sub": "learner-42",
            "exp": now + 300,
            "iat": now,
            "nonce": nonce,
            "name": "Ada Lovelace",
            "email": "ada@example.edu",
            claims.DEPLOYMENT_ID: DEPLOYMENT_ID,
            claims.MESSAGE_TYPE: claims.RESOURCE_LINK_REQUEST,
            claims.VERSION: "1.3.0",
            claims.TARGET_LINK_URI: "https://tool.example.edu/classroom/lti/launch",
            claims.RESOURCE_LINK: {"id": "link-3", "title": "Topics"},
            claims.ROLES: ["http://purl.imsglobal.org/vocab/lis/v2/membership#Learner"],
            claims.CONTEXT: {"id": "course-101", "title": "Robotics 101"},
            claims.CUSTOM: {"lesson": "05_topics"},
            claims.AGS_ENDPOINT: {
                "scope": [claims.SCORE_SCOPE],
                "lineitems": f"{self.url}/lineitems",
                "lineitem": self.lineitem_url("11"),
            },
        }
        body.update(overrides)
        return {k: v for k, v in body.items() if v is not None}

    def id_token(
        self, nonce: str, *, key: rsa.RSAPrivateKey | None = None, **overrides: Any
    ) -> str:
        return jwt.encode(
            self.launch_claims(nonce, **overrides),
            key or self._key,
            algorithm="RS256",
            headers={"kid": self.kid},
        )

    def fail_next(self, item: str, status: int, reason: str, times: int = 1) -> None:
        with self.lock:
            self.scripted[item].extend([(status, reason)] * times)

    def revoke_tokens(self) -> None:
        with self.lock:
            self.tokens.clear()

    # HTTP ------------------------------------------------------------------------------

    def _handler(self) -> type[BaseHTTPRequestHandler]:
        platform = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, format: str, *args: Any) -> None:
                pass

            def _answer(self, status: int, body: object, kind: str = "application/json") -> None:
                data = body if isinstance(body, bytes) else json.dumps(body).encode()
                self.send_response(status)
                self.send_header("Content-Type", kind)
                self.send_header("Content-Length", str(len(data)))
                self.end_headers()
                self.wfile.write(data)

            def do_GET(self) -> None:
                if self.path == "/jwks":
                    with platform.lock:
                        platform.jwks_fetches += 1
                    self._answer(200, {"keys": [_public_jwk(platform._key, platform.kid)]})
                else:
                    self._answer(404, {"error": "not found"})

            def do_POST(self) -> None:
                body = self.rfile.read(int(self.headers.get("Content-Length", "0")))
                parts = urllib.parse.urlsplit(self.path)
                if parts.path == "/token":
                    status, answer = platform._token(body)
                    self._answer(status, answer)
                    return
                if parts.path == "/deep-link-return":
                    status, answer = platform._deep_link_return(body)
                    self._answer(status, answer)
                    return
                segments = parts.path.strip("/").split("/")
                if len(segments) == 3 and segments[0] == "lineitems" and segments[2] == "scores":
                    status, answer = platform._score(
                        segments[1], parts.query, self.headers, body, parts.path
                    )
                    self._answer(status, answer)
                    return
                self._answer(404, {"error": "not found"})

        return Handler

    def _token(self, body: bytes) -> tuple[int, object]:
        form = dict(urllib.parse.parse_qsl(body.decode()))
        with self.lock:
            self.token_requests += 1

        def refuse(why: str) -> tuple[int, object]:
            with self.lock:
                self.token_refusals.append(why)
            return 401, {"error": "invalid_client", "error_description": why}

        if form.get("grant_type") != "client_credentials":
            return 400, {"error": "unsupported_grant_type"}
        if form.get("client_assertion_type") != (
            "urn:ietf:params:oauth:client-assertion-type:jwt-bearer"
        ):
            return refuse("wrong client_assertion_type")
        if self.tool_jwks is None:
            return refuse("no tool key registered")
        assertion = form.get("client_assertion", "")
        try:
            kid = jwt.get_unverified_header(assertion).get("kid")
            key = jwt.PyJWKSet.from_dict(self.tool_jwks)[kid]
            checked = jwt.decode(
                assertion,
                key,
                algorithms=["RS256"],
                audience=f"{self.url}/token",
                issuer=CLIENT_ID,
                options={"require": ["exp", "iat", "jti", "sub"]},
            )
        except (jwt.PyJWTError, KeyError) as error:
            return refuse(f"client assertion refused: {error}")
        if checked["sub"] != CLIENT_ID:
            return refuse("sub is not the client id")
        with self.lock:
            if checked["jti"] in self.used_jtis:
                return refuse("jti reused")
            self.used_jtis.add(checked["jti"])
            if claims.SCORE_SCOPE not in form.get("scope", "").split():
                return 400, {"error": "invalid_scope"}
            token = secrets.token_urlsafe(16)
            self.tokens[token] = time.time() + self.token_life_sec
        return 200, {
            "access_token": token,
            "token_type": "Bearer",
            "expires_in": self.token_life_sec,
            "scope": claims.SCORE_SCOPE,
        }

    def _score(
        self, item: str, query: str, headers: Any, body: bytes, path: str
    ) -> tuple[int, object]:
        auth = headers.get("Authorization", "")
        kind = headers.get("Content-Type", "")
        with self.lock:
            self.score_requests.append((path, query, kind))
            token = auth.removeprefix("Bearer ")
            if not auth.startswith("Bearer ") or self.tokens.get(token, 0) < time.time():
                return 401, {"error": "invalid_token"}
            if self.scripted[item]:
                status, reason = self.scripted[item].pop(0)
                return status, {"error": reason}
            if kind != SCORE_MEDIA_TYPE:
                return 415, {"error": f"content type {kind!r}"}
            score = json.loads(body)
            earlier = self.scores[item]
            same_user = [s for s in earlier if s["userId"] == score["userId"]]
            # Moodle's rule: a timestamp not newer than the stored one is a conflict.
            if same_user and score["timestamp"] <= same_user[-1]["timestamp"]:
                return 409, {"error": "timestamp not newer than the stored score"}
            earlier.append(score)
        return 200, {}

    def _deep_link_return(self, body: bytes) -> tuple[int, object]:
        """Check the tool's signed answer as an LMS does, and make a line item per link."""
        form = dict(urllib.parse.parse_qsl(body.decode()))

        def refuse(why: str) -> tuple[int, object]:
            with self.lock:
                self.deep_link_refusals.append(why)
            return 400, {"error": why}

        if self.tool_jwks is None:
            return refuse("no tool key registered")
        try:
            token = form["JWT"]
            key = jwt.PyJWKSet.from_dict(self.tool_jwks)[jwt.get_unverified_header(token)["kid"]]
            checked = jwt.decode(
                token,
                key,
                algorithms=["RS256"],
                audience=self.issuer,
                issuer=CLIENT_ID,
                options={"require": ["exp", "iat", "nonce"]},
            )
        except (jwt.PyJWTError, KeyError) as error:
            return refuse(f"deep-linking response refused: {error}")
        if checked.get(claims.MESSAGE_TYPE) != claims.DEEP_LINKING_RESPONSE:
            return refuse("not a deep-linking response")
        if checked.get(claims.DEPLOYMENT_ID) != DEPLOYMENT_ID:
            return refuse("unknown deployment")
        with self.lock:
            for item in checked.get(claims.CONTENT_ITEMS, []):
                number = f"dl-{len(self.links) + 1}"
                self.links.append(
                    {**item, "resource_link_id": f"link-{number}", "lineitem_id": number}
                )
        return 200, {"added": len(checked.get(claims.CONTENT_ITEMS, []))}

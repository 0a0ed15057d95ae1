"""An LMS built on ``lti1p3platform`` (PyPI), served over HTTP for the real-platform tests.

Every LTI message of the platform's side is made or checked by that
library, not by us: the OIDC login initiation (``OIDCLoginAbstract``), the
signed id_token of a launch or a deep-linking request
(``LTIAdvantageMessageLaunchAbstract``, with its AGS and deep-linking
claims), the JWKS (``LTI1P3PlatformConfAbstract.get_jwks``), the OAuth 2
token endpoint with the tool's client assertion checked against the tool's
keyset URL (``get_access_token``), the deep-linking response checked the
same way (``validate_deeplinking_resp``), and the AGS score endpoint with its
bearer token checked (``AssignmentsGradesService.handle_update_score``).

What is ours here is what the library leaves to its framework adapters
(Django, FastAPI): reading an HTTP request into its ``Request``, writing its
answers back, and the storage its abstract methods ask for (users, resource
links, line items, the scores received). The library does not check the
content of a posted score ("TODO: validate score" in its source), so
``update_score`` below checks it against the library's own ``ActivityProgress``
and ``GradeProgress`` enums and refuses a user the course does not know, as
an LMS does.
"""

from __future__ import annotations

import json
import secrets
import threading
import urllib.parse
from collections import defaultdict
from dataclasses import dataclass, field
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any

from cryptography.hazmat.primitives import serialization
from cryptography.hazmat.primitives.asymmetric import rsa
from lti1p3platform.exceptions import (
    LineItemNotFoundException,
    UnsupportedGrantType,
)
from lti1p3platform.framework.templates import template as launch_form_template
from lti1p3platform.ltiplatform import LTI1P3PlatformConfAbstract
from lti1p3platform.message_launch import LTIAdvantageMessageLaunchAbstract
from lti1p3platform.oidc_login import OIDCLoginAbstract
from lti1p3platform.registration import Registration
from lti1p3platform.request import Request, TRequest
from lti1p3platform.score import ActivityProgress, GradeProgress, UpdateScoreStatus
from lti1p3platform.service_connector import AssignmentsGradesService, TPage

from app.lti.routes import ToolUrls

CLIENT_ID = "pypi-platform-client-1"
DEPLOYMENT_ID = "pypi-deployment-1"
LEARNER_ROLE = "http://purl.imsglobal.org/vocab/lis/v2/membership#Learner"
INSTRUCTOR_ROLE = "http://purl.imsglobal.org/vocab/lis/v2/membership#Instructor"

_keys: list[tuple[str, str]] = []


def key_pair() -> tuple[str, str]:
    """(private PEM, public PEM): the library wants PEM text; made once per run (slow)."""
    key = rsa.generate_private_key(public_exponent=65537, key_size=2048)
    private = key.private_bytes(
        serialization.Encoding.PEM,
        serialization.PrivateFormat.PKCS8,
        serialization.NoEncryption(),
    ).decode()
    public = (
        key.public_key()
        .public_bytes(serialization.Encoding.PEM, serialization.PublicFormat.SubjectPublicKeyInfo)
        .decode()
    )
    return private, public


def _shared_key_pair(index: int) -> tuple[str, str]:
    while len(_keys) <= index:
        _keys.append(key_pair())
    return _keys[index]


class _Config(LTI1P3PlatformConfAbstract):
    """The library's platform configuration, holding one registration (the tool's)."""

    def init_platform_config(self, **kwargs: Any) -> None:
        self._wanted: Registration = kwargs["registration"]

    def get_registration_by_params(self, **kwargs: Any) -> Registration:
        return self._wanted


class _Request(Request):
    """An http.server request as the library's ``Request`` (what its Django adapter does)."""

    def build_metadata(self, request: Any) -> TRequest:
        handler, body = request
        parts = urllib.parse.urlsplit(handler.path)
        kind = handler.headers.get("Content-Type", "") or ""
        form = dict(urllib.parse.parse_qsl(body.decode())) if "form" in kind else {}
        return {
            "method": handler.command,
            "form_data": form,
            "get_data": dict(urllib.parse.parse_qsl(parts.query)),
            "headers": handler.headers,
            "content_type": kind,
            "path": parts.path,
            "json": json.loads(body) if body and "json" in kind else None,
        }


class _Login(OIDCLoginAbstract):
    def set_lti_message_hint(self, **kwargs: Any) -> None:
        self._lti_message_hint = kwargs["hint"]

    def get_redirect(self, url: str) -> str:
        return url  # the HTTP layer answers 302 to it


class _Launch(LTIAdvantageMessageLaunchAbstract):
    def render_launch_form(self, launch_data: dict[str, Any], **kwargs: Any) -> str:
        rendered: str = launch_form_template.render(launch_data)  # the library's own page
        return rendered


@dataclass
class Link:
    """A resource link in a course, with its grade column when it has one."""

    custom: dict[str, str]
    lineitem: str | None = None
    title: str = "Activity"


@dataclass
class LaunchQuirk:
    """What the next launch does wrong, for the refusal tests (all done through the library)."""

    registration: Registration | None = None  # sign with this one instead (another key)
    extra_claims: dict[str, Any] = field(default_factory=dict)  # claims over the library's
    expires_in: int | None = None  # the id_token's life in seconds (negative: expired)


class PypiPlatform:
    """The LMS. ``start(user, link)`` is the URL an activity's link has on a course page."""

    __test__ = False

    def __init__(self, *, key_index: int = 0) -> None:
        self.private_key, self.public_key = _shared_key_pair(key_index)
        self.users: dict[str, tuple[str, list[str]]] = {
            "learner-1": ("Ada Lovelace", [LEARNER_ROLE]),
            "learner-2": ("Alan Turing", [LEARNER_ROLE]),
            "teacher-1": ("Grace Hopper", [INSTRUCTOR_ROLE]),
        }
        self.links: dict[str, Link] = {}
        self.lineitems: dict[str, dict[str, Any]] = {}
        self.scores: dict[str, list[dict[str, Any]]] = defaultdict(list)  # line item -> scores
        self.score_answers: list[int] = []  # every status the AGS endpoint answered
        self.token_answers: list[int] = []
        self.deep_link_refusals: list[str] = []
        self.next_quirk: LaunchQuirk | None = None
        # Dynamic registration (not in the library: this part is ours, a stand-in LMS).
        self.client_id = CLIENT_ID
        self.registration_token = "registration-token-1"
        self.configuration_changes: dict[str, Any] = {}
        self.registration_reply: tuple[int, bytes] | None = None  # instead of a real answer
        self.registrations_received: list[dict[str, Any]] = []
        self._pending: dict[str, tuple[str, str | None]] = {}  # message hint -> (user, link)
        self.lock = threading.Lock()
        self._server = ThreadingHTTPServer(("127.0.0.1", 0), self._handler())
        self._thread = threading.Thread(
            target=self._server.serve_forever, kwargs={"poll_interval": 0.05}, daemon=True
        )
        self._thread.start()
        self.url = f"http://127.0.0.1:{self._server.server_address[1]}"
        self.tool: ToolUrls | None = None
        self._registration: Registration | None = None

    def register_tool(self, tool: ToolUrls) -> None:
        """The administrator adds the tool: its login, launch, deep-linking and keyset URLs."""
        self.tool = tool
        self._registration = self.tool_registration(tool, self.private_key, self.public_key)

    @property
    def registration(self) -> Registration:
        assert self._registration is not None, "register_tool first"
        return self._registration

    def platforms_toml(self) -> str:
        """What the tool's administrator pastes from this LMS's tool page (platforms.toml)."""
        return (
            "[[platform]]\n"
            f'issuer = "{self.issuer}"\n'
            f'client_id = "{CLIENT_ID}"\n'
            f'deployment_ids = ["{DEPLOYMENT_ID}"]\n'
            f'jwks_url = "{self.url}/jwks"\n'
            f'auth_login_url = "{self.url}/auth"\n'
            f'auth_token_url = "{self.url}/token"\n'
        )

    def tool_registration(self, tool: ToolUrls, private: str, public: str) -> Registration:
        """What the LMS administrator typed about our tool, in the library's terms."""
        return (
            Registration()
            .set_iss(self.url)
            .set_client_id(self.client_id)
            .set_deployment_id(DEPLOYMENT_ID)
            .set_oidc_login_url(tool.login)
            .set_launch_url(tool.launch)
            .set_deeplink_launch_url(tool.deep_link)
            .set_tool_key_set_url(tool.jwks)
            .set_platform_private_key(private)
            .set_platform_public_key(public)
        )

    def config(self, registration: Registration | None = None) -> _Config:
        config = _Config(registration=registration or self.registration)
        config.get_registration()
        return config

    def close(self) -> None:
        self._server.shutdown()
        self._server.server_close()
        self._thread.join(timeout=5)

    # What the LMS's pages hold --------------------------------------------------------

    @property
    def issuer(self) -> str:
        return self.url

    def lineitem_url(self, item: str) -> str:
        return f"{self.url}/lineitems/{item}"

    def add_link(self, link_id: str, custom: dict[str, str], item: str | None = None) -> None:
        if item is not None:
            self.lineitems.setdefault(item, {"id": self.lineitem_url(item), "scoreMaximum": 1})
        self.links[link_id] = Link(custom, self.lineitem_url(item) if item else None)

    def start(self, user: str, link: str | None = None) -> str:
        """The course page's link: a resource link launch, or the picker (no link) for a teacher."""
        query = {"user": user, **({"link": link} if link else {})}
        return f"{self.url}/start?{urllib.parse.urlencode(query)}"

    # The platform's endpoints, each made by the library -------------------------------

    def _start(self, request: _Request) -> str:
        user, link = request.get_data["user"], request.get_data.get("link")
        hint = secrets.token_urlsafe(12)
        with self.lock:
            self._pending[hint] = (user, link)
        login = _Login(request, self.config())
        login.set_lti_message_hint(hint=hint)
        if link is None:
            login.set_deeplinking_launch_url()
        return str(login.initiate_login(user))

    def _auth(self, request: _Request) -> tuple[int, str]:
        params = request.get_data or request.form_data
        with self.lock:
            pending = self._pending.pop(params.get("lti_message_hint", ""), None)
            quirk, self.next_quirk = self.next_quirk, None
        if pending is None or pending[0] != params.get("login_hint"):
            return 400, "no such launch here (lti_message_hint or login_hint)"
        user, link_id = pending
        quirk = quirk or LaunchQuirk()
        launch = _Launch(request, self.config(quirk.registration))
        name, roles = self.users[user]
        launch.set_user_data(user, roles, full_name=name, email_address=f"{user}@lms.test")
        launch.set_launch_context_claim("course-1", context_title="Robotics 101")
        if link_id is None:
            launch.set_dl(
                f"{self.url}/deep-link-return",
                title="Add an activity",
                accept_types={"ltiResourceLink"},
            )
        else:
            link = self.links[link_id]
            launch.set_resource_link_claim(link_id, title=link.title)
            launch.set_custom_parameters_claim(link.custom)
            if link.lineitem:
                launch.set_ags(f"{self.url}/lineitems", link.lineitem)
        if quirk.expires_in is not None:
            launch.set_id_token_expiration(quirk.expires_in)
        if quirk.extra_claims:
            launch.set_extra_claims(quirk.extra_claims)
        return 200, str(launch.lti_launch())

    def _token(self, request: _Request) -> tuple[int, object]:
        try:
            answer: object = self.config().get_access_token(request.form_data)
            status = 200
        except UnsupportedGrantType:
            status, answer = 400, {"error": "unsupported_grant_type"}
        # MissingRequiredClaim, LtiException, and PyJWT's errors: the library lets them out.
        except Exception as error:
            status, answer = 401, {"error": "invalid_client", "error_description": str(error)}
        with self.lock:
            self.token_answers.append(status)
        return status, answer

    def _deep_link_return(self, request: _Request) -> tuple[int, object]:
        try:
            items = self.config().validate_deeplinking_resp(request.form_data)
        # LtiDeepLinkingResponseException, LtiException, PyJWT's errors, a missing JWT field.
        except Exception as error:
            with self.lock:
                self.deep_link_refusals.append(f"{type(error).__name__}: {error}")
            return 400, {"error": str(error)}
        with self.lock:
            for item in items:
                number = f"dl-{len(self.lineitems) + 1}"
                made = item.get("lineItem")
                if made:
                    self.lineitems[number] = {**made, "id": self.lineitem_url(number)}
                self.links[f"link-{number}"] = Link(
                    dict(item.get("custom", {})),
                    self.lineitem_url(number) if made else None,
                    item.get("title", "Activity"),
                )
        return 200, {"added": len(items)}

    def _scores(self, request: _Request, item: str) -> tuple[int, object]:
        service = _Grades(
            request, self.config(), f"{self.url}/lineitems", self.lineitem_url(item), self
        )
        answer = service.handle_resp(service.handle_update_score, line_item_id=item)
        with self.lock:
            self.score_answers.append(answer.code)
        return answer.code, answer.result if answer.code < 300 else {"error": answer.message}

    # Dynamic registration: a stand-in, as lti1p3platform has none --------------------

    @property
    def openid_configuration(self) -> str:
        return f"{self.url}/.well-known/openid-configuration"

    def _configuration(self) -> dict[str, Any]:
        return {
            "issuer": self.issuer,
            "authorization_endpoint": f"{self.url}/auth",
            "token_endpoint": f"{self.url}/token",
            "jwks_uri": f"{self.url}/jwks",
            "registration_endpoint": f"{self.url}/register",
            "scopes_supported": ["openid", "https://purl.imsglobal.org/spec/lti-ags/scope/score"],
            "https://purl.imsglobal.org/spec/lti-platform-configuration": {
                "product_family_code": "lti1p3platform",
                "version": "0.1.8",
                "messages_supported": [
                    {"type": "LtiResourceLinkRequest"},
                    {"type": "LtiDeepLinkingRequest"},
                ],
            },
            **self.configuration_changes,
        }

    def _register(self, headers: Any, body: bytes) -> tuple[int, bytes]:
        if headers.get("Authorization", "") != f"Bearer {self.registration_token}":
            return 401, b'{"error": "invalid_token"}'
        if self.registration_reply is not None:
            return self.registration_reply
        client = json.loads(body)
        with self.lock:
            self.registrations_received.append(client)
            self.client_id = f"dynamic-client-{len(self.registrations_received)}"
        tool = client["https://purl.imsglobal.org/spec/lti-tool-configuration"]
        answer = {
            **client,
            "client_id": self.client_id,
            "https://purl.imsglobal.org/spec/lti-tool-configuration": {
                **tool,
                "deployment_id": DEPLOYMENT_ID,
            },
        }
        return 200, json.dumps(answer).encode()

    # HTTP plumbing --------------------------------------------------------------------

    def _handler(self) -> type[BaseHTTPRequestHandler]:
        platform = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, format: str, *args: Any) -> None:
                pass

            def _answer(self, status: int, body: object, kind: str = "application/json") -> None:
                if isinstance(body, str):
                    data, kind = body.encode(), "text/html; charset=utf-8"
                else:
                    data = json.dumps(body).encode()
                self.send_response(status)
                self.send_header("Content-Type", kind)
                self.send_header("Content-Length", str(len(data)))
                self.end_headers()
                self.wfile.write(data)

            def _request(self) -> _Request:
                body = self.rfile.read(int(self.headers.get("Content-Length", "0") or 0))
                return _Request((self, body))

            def do_GET(self) -> None:
                request = self._request()
                if request.path == "/jwks":
                    self._answer(200, platform.config().get_jwks())
                elif request.path == "/start":
                    self.send_response(302)
                    self.send_header("Location", platform._start(request))
                    self.send_header("Content-Length", "0")
                    self.end_headers()
                elif request.path == "/auth":
                    self._answer(*platform._auth(request))
                elif request.path == "/.well-known/openid-configuration":
                    self._answer(200, platform._configuration())
                else:
                    self._answer(404, {"error": "not found"})

            def do_POST(self) -> None:
                if self.path == "/register":
                    body = self.rfile.read(int(self.headers.get("Content-Length", "0") or 0))
                    status, data = platform._register(self.headers, body)
                    self.send_response(status)
                    self.send_header("Content-Type", "application/json")
                    self.send_header("Content-Length", str(len(data)))
                    self.end_headers()
                    self.wfile.write(data)
                    return
                request = self._request()
                segments = request.path.strip("/").split("/")
                if request.path == "/auth":
                    self._answer(*platform._auth(request))
                elif request.path == "/token":
                    self._answer(*platform._token(request))
                elif request.path == "/deep-link-return":
                    status, answer = platform._deep_link_return(request)
                    self._answer(status, f"<p id='lms'>{json.dumps(answer)}</p>")
                elif len(segments) == 3 and segments[0] == "lineitems" and segments[2] == "scores":
                    self._answer(*platform._scores(request, segments[1]))
                else:
                    self._answer(404, {"error": "not found"})

        return Handler


class _Grades(AssignmentsGradesService):
    """The library's AGS service; the storage behind it is the platform's dicts."""

    def __init__(
        self,
        request: Request,
        config: LTI1P3PlatformConfAbstract,
        lineitems_url: str,
        lineitem_url: str,
        platform: PypiPlatform,
    ) -> None:
        super().__init__(request, config, lineitems_url, lineitem_url)
        self.platform = platform

    def update_score(self, line_item_id: str, score: Any) -> UpdateScoreStatus:
        platform = self.platform
        if line_item_id not in platform.lineitems:
            raise LineItemNotFoundException(line_item_id)
        try:
            ActivityProgress(score["activityProgress"])
            GradeProgress(score["gradingProgress"])
            given, maximum = float(score["scoreGiven"]), float(score["scoreMaximum"])
            stamp = str(score["timestamp"])
        except (KeyError, TypeError, ValueError):
            return UpdateScoreStatus.NOTAPPLIED
        if score.get("userId") not in platform.users or not 0 <= given <= maximum:
            return UpdateScoreStatus.NOTAPPLIED
        with platform.lock:
            earlier = [s for s in platform.scores[line_item_id] if s["userId"] == score["userId"]]
            if earlier and stamp <= earlier[-1]["timestamp"]:
                return UpdateScoreStatus.OLD_TIMESTAMP  # Moodle's 409
            platform.scores[line_item_id].append(score)
        return UpdateScoreStatus.SUCCESS

    # What the score tests never ask of the service.
    def find_lineitems(self, *args: Any, **kwargs: Any) -> TPage:
        return {"content": list(self.platform.lineitems.values()), "has_next": False}

    def find_lineitem(self, line_item_id: str) -> Any:
        return self.platform.lineitems[line_item_id]

    def create_lineitem(self, creation_data: Any) -> Any:
        raise NotImplementedError

    def update_lineitem(self, update_data: Any) -> Any:
        raise NotImplementedError

    def delete_lineitem(self, line_item_id: str) -> None:
        raise NotImplementedError

    def get_results(self, *args: Any, **kwargs: Any) -> TPage:
        raise NotImplementedError

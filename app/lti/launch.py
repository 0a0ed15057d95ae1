"""Checking an LMS launch (the id_token it posts) and reading what it says.

Order matters: the signature and the token's life are checked before any
claim is trusted, and the nonce is spent last, so a forged or broken token
can never use up a real learner's login.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from datetime import datetime, timezone
from typing import cast

import jwt

from app.lti import claims
from app.lti.nonces import NonceStore
from app.lti.platform_keys import PlatformKeys
from app.lti.registration import PlatformRegistration, Registrations
from app.lti.rejection import LaunchRejected

LEEWAY_SEC = 60  # clocks of an LMS and a hub may disagree by this much
MESSAGE_TYPES = (claims.RESOURCE_LINK_REQUEST, claims.DEEP_LINKING_REQUEST)

# Roles that see the teacher's page: those who teach, assist or run the course or site.
_TEACHING_ROLES = frozenset(
    {
        "http://purl.imsglobal.org/vocab/lis/v2/membership#Instructor",
        "http://purl.imsglobal.org/vocab/lis/v2/membership#Administrator",
        "http://purl.imsglobal.org/vocab/lis/v2/membership#ContentDeveloper",
        "http://purl.imsglobal.org/vocab/lis/v2/membership/Instructor#TeachingAssistant",
        "http://purl.imsglobal.org/vocab/lis/v2/institution/person#Administrator",
        "http://purl.imsglobal.org/vocab/lis/v2/system/person#Administrator",
        "Instructor",  # the short names some platforms still send
        "Administrator",
    }
)


@dataclass(frozen=True)
class GradeService:
    """The AGS claim: where this resource link's scores go, and what we may do there."""

    lineitem: str | None  # the line item of this link, when the LMS made one
    lineitems: str | None  # the course's line item container
    scopes: tuple[str, ...]

    @property
    def can_post_scores(self) -> bool:
        return self.lineitem is not None and claims.SCORE_SCOPE in self.scopes


@dataclass(frozen=True)
class DeepLinkingSettings:
    """What the LMS accepts back when a teacher picks activities (Deep Linking 2.0)."""

    return_url: str
    accept_types: tuple[str, ...]
    accept_multiple: bool
    data: str | None  # opaque, returned unchanged in our response


@dataclass(frozen=True)
class Launch:
    """A checked launch: who came, from which LMS and link, to do what."""

    registration: PlatformRegistration
    message_type: str
    deployment_id: str
    user_id: str  # the platform's `sub`: stable per learner and platform
    name: str | None  # `name`, else `given_name` and `family_name`: for the teacher's pages
    email: str | None
    roles: tuple[str, ...]
    context_id: str | None
    resource_link_id: str | None
    target_link_uri: str | None
    grade_service: GradeService | None
    deep_linking: DeepLinkingSettings | None
    custom: Mapping[str, str] = field(default_factory=dict)
    context_title: str | None = None  # the course, as the LMS names it
    link_title: str | None = None  # the activity, as the LMS names it (its grade column's label)

    @property
    def is_instructor(self) -> bool:
        return any(role in _TEACHING_ROLES for role in self.roles)

    @property
    def lesson(self) -> str | None:
        return self.custom.get("lesson")

    @property
    def exercise(self) -> str | None:
        return self.custom.get("exercise")


class LaunchValidator:
    """Checks id_tokens from the registered platforms; one instance per service."""

    def __init__(
        self,
        registrations: Registrations,
        nonces: NonceStore,
        *,
        leeway_sec: float = LEEWAY_SEC,
        platform_keys: Callable[[str], PlatformKeys] = PlatformKeys,
    ) -> None:
        self._registrations, self._nonces, self._leeway = registrations, nonces, leeway_sec
        self._new_keys = platform_keys  # one key cache per platform JWKS URL
        self._keys: dict[str, PlatformKeys] = {}

    def validate(self, id_token: str, state: str) -> Launch:
        """The launch in ``id_token``, or ``LaunchRejected`` with the reason."""
        try:
            header = jwt.get_unverified_header(id_token)
            unverified = jwt.decode(id_token, options={"verify_signature": False})
        except jwt.PyJWTError:
            raise LaunchRejected("the id_token is not a readable JWT") from None
        if header.get("alg") != "RS256":
            raise LaunchRejected(
                f"the id_token is signed with {header.get('alg')!r}; LTI 1.3 launches must be RS256"
            )
        registration = self._registration(unverified)
        verified = self._verified(id_token, header, registration)
        self._check_audience(verified, registration)
        deployment_id = _text(verified, claims.DEPLOYMENT_ID)
        if deployment_id not in registration.deployment_ids:
            raise LaunchRejected(
                f"deployment {deployment_id!r} of {registration.issuer} is not registered with "
                "this tool: add its deployment id to the registration"
            )
        message_type = _text(verified, claims.MESSAGE_TYPE)
        if message_type not in MESSAGE_TYPES:
            raise LaunchRejected(
                f"the message type {message_type!r} is not one this tool handles "
                f"({' or '.join(MESSAGE_TYPES)})"
            )
        version = _text(verified, claims.VERSION)
        if version != claims.LTI_VERSION:
            raise LaunchRejected(
                f"the launch says LTI version {version!r}; this tool speaks {claims.LTI_VERSION}"
            )
        launch = _read_launch(verified, registration, message_type, deployment_id or "")
        self._nonces.redeem(state, str(verified["nonce"]))
        return launch

    def _registration(self, unverified: Mapping[str, object]) -> PlatformRegistration:
        issuer = unverified.get("iss")
        if not isinstance(issuer, str) or not issuer:
            raise LaunchRejected("the id_token names no issuer (iss)")
        candidates = self._registrations.for_issuer(issuer)
        if not candidates:
            raise LaunchRejected(
                f"the issuer {issuer!r} is not a platform registered with this tool"
            )
        audience = unverified.get("aud")
        audiences = (
            [audience]
            if isinstance(audience, str)
            else list(cast("Iterable[object]", audience or []))
        )
        for registration in candidates:
            if registration.client_id in audiences:
                return registration
        raise LaunchRejected(
            f"the id_token is meant for audience {audience!r}, not for this tool's client id "
            f"at {issuer!r} ({', '.join(r.client_id for r in candidates)})"
        )

    def _verified(
        self, id_token: str, header: Mapping[str, object], registration: PlatformRegistration
    ) -> dict[str, object]:
        keys = self._keys.get(registration.jwks_url)
        if keys is None:
            keys = self._keys.setdefault(
                registration.jwks_url, self._new_keys(registration.jwks_url)
            )
        key = keys.key_for(cast("str | None", header.get("kid")))  # a JWT header's kid is text
        try:
            return jwt.decode(
                id_token,
                key,
                algorithms=["RS256"],
                audience=registration.client_id,
                issuer=registration.issuer,
                leeway=self._leeway,
                options={"require": ["exp", "iat", "iss", "aud", "nonce", "sub"]},
            )
        except jwt.InvalidSignatureError:
            raise LaunchRejected(
                "the id_token's signature does not match the platform's key: it was forged or "
                "altered after signing"
            ) from None
        except jwt.ExpiredSignatureError:
            raise LaunchRejected(
                f"the id_token expired at {_when(id_token, 'exp')}: launch again from the LMS "
                "(or check this server's clock)"
            ) from None
        except (jwt.ImmatureSignatureError, jwt.InvalidIssuedAtError):
            raise LaunchRejected(
                f"the id_token was issued in the future ({_when(id_token, 'iat')}): the LMS's "
                "clock or this server's is wrong"
            ) from None
        except jwt.MissingRequiredClaimError as error:
            raise LaunchRejected(f"the id_token lacks the {error.claim!r} claim") from None
        except jwt.PyJWTError as error:
            raise LaunchRejected(f"the id_token was refused: {error}") from None

    def _check_audience(
        self, verified: Mapping[str, object], registration: PlatformRegistration
    ) -> None:
        # OpenID Connect: with several audiences, `azp` names the one the token was issued to.
        audience = verified["aud"]
        azp = verified.get("azp")
        several = isinstance(audience, list) and len(audience) > 1
        if several and azp is None:
            raise LaunchRejected("the id_token has several audiences but no authorized party (azp)")
        if azp is not None and azp != registration.client_id:
            raise LaunchRejected(
                f"the id_token's authorized party (azp) is {azp!r}, not this tool's client id "
                f"{registration.client_id!r}"
            )


def _text(values: Mapping[str, object], name: str) -> str | None:
    value = values.get(name)
    return value if isinstance(value, str) else None


def _person_name(verified: Mapping[str, object]) -> str | None:
    """The OIDC ``name``; else ``given_name`` and ``family_name`` (some LMSes send only those)."""
    full = (_text(verified, "name") or "").strip()
    if full:
        return full
    parts = [(_text(verified, claim) or "").strip() for claim in ("given_name", "family_name")]
    return " ".join(p for p in parts if p) or None


def _object(values: Mapping[str, object], name: str) -> Mapping[str, object]:
    value = values.get(name)
    return value if isinstance(value, dict) else {}


def _when(id_token: str, claim: str) -> str:
    value = jwt.decode(id_token, options={"verify_signature": False}).get(claim)
    if not isinstance(value, (int, float)):
        return "an unreadable time"
    return datetime.fromtimestamp(value, timezone.utc).isoformat(timespec="seconds")


def _read_launch(
    verified: Mapping[str, object],
    registration: PlatformRegistration,
    message_type: str,
    deployment_id: str,
) -> Launch:
    user_id = verified["sub"]
    if not isinstance(user_id, str) or not user_id:
        raise LaunchRejected("the id_token names no user (sub); anonymous launches get no grade")
    link = _object(verified, claims.RESOURCE_LINK)
    resource_link_id = _text(link, "id")
    if message_type == claims.RESOURCE_LINK_REQUEST and not resource_link_id:
        raise LaunchRejected("the resource link launch has no resource link id")
    deep_linking = None
    if message_type == claims.DEEP_LINKING_REQUEST:
        settings = _object(verified, claims.DEEP_LINKING_SETTINGS)
        return_url = _text(settings, "deep_link_return_url")
        if not return_url:
            raise LaunchRejected("the deep-linking request has no deep_link_return_url")
        deep_linking = DeepLinkingSettings(
            return_url=return_url,
            accept_types=tuple(
                str(t) for t in cast("Iterable[object]", settings.get("accept_types") or ())
            ),
            accept_multiple=settings.get("accept_multiple") is not False,
            data=_text(settings, "data"),
        )
    endpoint = verified.get(claims.AGS_ENDPOINT)
    grade_service = None
    if isinstance(endpoint, dict):
        grade_service = GradeService(
            lineitem=_text(endpoint, "lineitem"),
            lineitems=_text(endpoint, "lineitems"),
            scopes=tuple(str(s) for s in cast("Iterable[object]", endpoint.get("scope") or ())),
        )
    roles = verified.get(claims.ROLES)
    return Launch(
        registration=registration,
        message_type=message_type,
        deployment_id=deployment_id,
        user_id=user_id,
        name=_person_name(verified),
        email=_text(verified, "email"),
        roles=tuple(str(r) for r in roles) if isinstance(roles, list) else (),
        context_id=_text(_object(verified, claims.CONTEXT), "id"),
        resource_link_id=resource_link_id,
        target_link_uri=_text(verified, claims.TARGET_LINK_URI),
        grade_service=grade_service,
        deep_linking=deep_linking,
        # Custom values are strings in LTI; some platforms send numbers, read them as text.
        custom={str(k): str(v) for k, v in _object(verified, claims.CUSTOM).items()},
        context_title=_text(_object(verified, claims.CONTEXT), "title"),
        link_title=_text(link, "title"),
    )

"""Who an LMS launch is, on our side, and which graded activities each learner came for.

An LMS names a learner by its issuer (``iss``) and the learner's id there
(``sub``): stable for as long as the account lives, but opaque, long, and
not unique across LMSes. Our learner is a hub user whose name is derived
from that pair alone, so the same person launching again (from another
course, another day, another browser) is always the same learner with the
same server and progress, and two LMSes never share a name.

Each launch of a graded link is written down (``launches.json`` beside the
outbox): which lesson or exercise it was for, and the line item its score
goes to. A progress report that shows the work done is matched against
these; the file survives a restart of the service, so a learner who passes
an hour after launching still gets the grade.
"""

from __future__ import annotations

import base64
import hashlib
import json
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any, Literal

from app.jsonish import JSONObject
from app.lti.deep_linking import MAX_POINTS, SCORE_MAXIMUM_PARAM
from app.lti.launch import Launch
from app.lti.state_file import save_json

LAUNCHES_FILE = "launches.json"
NAME_PREFIX = "lti-"
_HASH_CHARS = 16  # 80 bits of base32: no two of a school's learners share a name

Kind = Literal["lesson", "exercise"]


def hub_user_name(issuer: str, subject: str) -> str:
    """``lti-`` and 16 base32 letters of SHA-256(issuer, newline, sub): stable, lower case.

    Lower case because JupyterHub lowers user names; nothing else of the launch
    (name, email, course) goes in, since those change while the person does not.
    """
    digest = hashlib.sha256(f"{issuer}\n{subject}".encode()).digest()
    return NAME_PREFIX + base64.b32encode(digest).decode("ascii").lower()[:_HASH_CHARS]


def activity_of(launch: Launch) -> tuple[Kind, str] | None:
    """The lesson or exercise a launch opens (its custom parameter); an exercise wins."""
    if launch.exercise:
        return ("exercise", launch.exercise)
    if launch.lesson:
        return ("lesson", launch.lesson)
    return None


def _points(text: str | None) -> float:
    """The link's points from its custom parameter; 1 when absent or not a sane number."""
    try:
        value = float(text) if text is not None else 1.0
    except ValueError:
        return 1.0
    return value if 0 < value <= MAX_POINTS else 1.0


@dataclass(frozen=True)
class LaunchedItem:
    """One graded link a learner launched: what it opens and where its score goes."""

    kind: Kind
    slug: str
    issuer: str
    client_id: str
    user_id: str  # the LMS's `sub`: the AGS score's userId
    resource_link_id: str
    lineitem: str | None  # None: the LMS takes no score for this link
    score_maximum: float = 1.0  # the picked points (custom score_maximum); the LMS scales
    context_id: str | None = None
    launched_at: float = 0.0
    context_title: str | None = None  # the course, as the LMS names it (the teacher's gradebook)
    link_title: str | None = None  # the activity's name in the LMS, the label of its grade column

    @property
    def graded(self) -> bool:
        return self.lineitem is not None


@dataclass(frozen=True)
class LearnerEntry:
    """What we know of one LMS learner: who, and the links they came through."""

    name: str  # the hub user name
    issuer: str
    user_id: str
    display_name: str | None = None  # as the LMS shares it, for the teacher's page
    email: str | None = None
    items: tuple[LaunchedItem, ...] = ()

    def to_json(self) -> JSONObject:
        return {**asdict(self), "items": [asdict(item) for item in self.items]}

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> LearnerEntry:
        items = tuple(LaunchedItem(**item) for item in data.get("items", []))
        return cls(**{**data, "items": items})


class LaunchBook:
    """Every LMS learner and their graded links, kept in one JSON file (rewritten whole).

    Owned by one thread of one process (the service's event loop): no lock.
    """

    def __init__(self, folder: Path, *, clock: Callable[[], float] = time.time) -> None:
        folder.mkdir(parents=True, exist_ok=True, mode=0o700)
        self.path = folder / LAUNCHES_FILE
        self._clock = clock
        self._learners: dict[str, LearnerEntry] = {}
        if self.path.exists():
            document = json.loads(self.path.read_text(encoding="utf-8"))
            for data in document["learners"]:
                entry = LearnerEntry.from_json(data)
                self._learners[entry.name] = entry

    def record(self, launch: Launch) -> tuple[str, LaunchedItem | None]:
        """Note a resource-link launch; the learner's hub name and the item it was for."""
        issuer = launch.registration.issuer
        name = hub_user_name(issuer, launch.user_id)
        entry = self._learners.get(name) or LearnerEntry(name, issuer, launch.user_id)
        entry = replace(
            entry,
            display_name=launch.name or entry.display_name,
            email=launch.email or entry.email,
        )
        item = None
        activity = activity_of(launch)
        if activity is not None and launch.resource_link_id:
            service = launch.grade_service
            item = LaunchedItem(
                kind=activity[0],
                slug=activity[1],
                issuer=issuer,
                client_id=launch.registration.client_id,
                user_id=launch.user_id,
                resource_link_id=launch.resource_link_id,
                lineitem=service.lineitem if service and service.can_post_scores else None,
                score_maximum=_points(launch.custom.get(SCORE_MAXIMUM_PARAM)),
                context_id=launch.context_id,
                launched_at=self._clock(),
                context_title=launch.context_title,
                link_title=launch.link_title,
            )
            # One entry per link: a relaunch updates it (the LMS may have moved its line item).
            kept = tuple(
                i
                for i in entry.items
                if (i.issuer, i.client_id, i.resource_link_id)
                != (item.issuer, item.client_id, item.resource_link_id)
            )
            entry = replace(entry, items=(*kept, item))
        self._learners[name] = entry
        self._save()
        return name, item

    def learner(self, name: str) -> LearnerEntry | None:
        return self._learners.get(name)

    def learners(self) -> list[LearnerEntry]:
        return list(self._learners.values())

    def _save(self) -> None:
        learners = [e.to_json() for e in self._learners.values()]
        save_json(self.path, {"version": 1, "learners": learners})

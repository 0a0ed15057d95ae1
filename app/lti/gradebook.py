"""The teacher's view of grade passback: per learner and LMS link, what was sent and what waits.

Two files know it between them: the launch book (who launched which link,
and its grade column) and the outbox (the best score per grade column and
learner, and what the LMS made of it). This joins them into one line per
launched link, plus a line for any score whose link the book no longer
lists (the LMS moved the link's grade column since), so nothing in the
outbox is hidden from the teacher. Pure data; app/lti/pages.py draws it.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from datetime import datetime, timezone
from typing import Literal

from app.lti.learners import Kind, LaunchedItem, LearnerEntry, hub_user_name
from app.lti.outbox import OutboxEntry

State = Literal["sent", "waiting", "refused", "not done", "no grade column"]
STATES: tuple[State, ...] = ("sent", "waiting", "refused", "not done", "no grade column")


@dataclass(frozen=True)
class GradebookLine:
    learner: str  # the hub user name, lti-...
    lms_name: str  # as the LMS named the learner at launch; "" when it shares no name
    activity: str  # "exercise counter_publisher" or the catalog's title
    link: str  # the LMS's name for the link, and its course, as far as the launch told
    lineitem: str | None  # the LMS's grade column (None: the link takes no score)
    state: State
    score: str  # "5 of 5", or "" with nothing to send
    queued_at: str  # the score's own timestamp (ISO 8601), the moment it was earned
    sent_at: float | None  # when the LMS took it
    lms_answer: str  # the LMS's answer to the last try ("" for a plain 2xx)
    attempts: int
    next_try: float | None  # when a waiting score is tried again
    launched_at: float
    seat: str = ""  # the classroom mode's learner dashboard this learner sits at
    comment: str = ""  # what the score told the LMS (what was checked, the seed)
    kind: str = ""  # "lesson" or "exercise" ('' : a score whose link no launch names now)
    slug: str = ""  # the lesson's id or the exercise's slug
    # Active seconds the learner's dashboard counted on it (None: none reported). The
    # same for each LMS link of one activity: it is the learner's time, not the link's.
    time_spent: int | None = None
    # The graded attempts known here at an exercise (the attempt history's), and when the
    # newest ran (None: none known, or a lesson, which has no graded attempts).
    graded: int = 0
    last_graded: float | None = None

    def to_json(self) -> dict[str, object]:
        return {name: getattr(self, name) for name in self.__dataclass_fields__}


def _score_text(entry: OutboxEntry) -> str:
    score = entry.score
    return f"{score.score_given:g} of {score.score_maximum:g}"


_BY_STATUS: dict[str, State] = {"delivered": "sent", "pending": "waiting", "failed": "refused"}


def _state(entry: OutboxEntry | None, item: LaunchedItem | None) -> State:
    if entry is None:
        return "no grade column" if item is not None and not item.graded else "not done"
    return _BY_STATUS[entry.status]


def _link_text(item: LaunchedItem | None) -> str:
    if item is None:
        return ""
    parts = [item.link_title or f"LMS link {item.resource_link_id}"]
    if item.context_title or item.context_id:
        parts.append(f"in {item.context_title or item.context_id}")
    return " ".join(parts)


def _line(
    learner: LearnerEntry | None,
    name: str,
    item: LaunchedItem | None,
    entry: OutboxEntry | None,
    titles: Mapping[tuple[Kind, str], str],
) -> GradebookLine:
    activity = ""
    if item is not None:
        activity = titles.get((item.kind, item.slug), f"{item.kind} {item.slug}")
    return GradebookLine(
        learner=name,
        lms_name=(learner.display_name or "") if learner else "",
        activity=activity,
        link=_link_text(item),
        lineitem=entry.lineitem if entry else (item.lineitem if item else None),
        state=_state(entry, item),
        score=_score_text(entry) if entry else "",
        queued_at=entry.score.timestamp if entry else "",
        sent_at=entry.delivered_at if entry and entry.status == "delivered" else None,
        lms_answer=entry.reason if entry else "",
        attempts=entry.attempts if entry else 0,
        next_try=entry.next_try if entry and entry.status == "pending" else None,
        launched_at=item.launched_at if item else 0.0,
        comment=entry.score.comment if entry else "",
        kind=item.kind if item else "",
        slug=item.slug if item else "",
    )


def gradebook(
    learners: Iterable[LearnerEntry],
    entries: Iterable[OutboxEntry],
    titles: Mapping[tuple[Kind, str], str] | None = None,
) -> list[GradebookLine]:
    """One line per launched link and per outbox score, by learner's LMS name, then activity."""
    titles = titles or {}
    outbox = {(e.issuer, e.client_id, e.lineitem, e.score.user_id): e for e in entries}
    book = {learner.name: learner for learner in learners}
    lines: list[GradebookLine] = []
    for learner in book.values():
        for item in learner.items:
            entry = None
            if item.lineitem is not None:
                entry = outbox.pop((item.issuer, item.client_id, item.lineitem, item.user_id), None)
            lines.append(_line(learner, learner.name, item, entry, titles))
    for entry in outbox.values():  # a score whose link now names another grade column
        name = hub_user_name(entry.issuer, entry.score.user_id)
        lines.append(_line(book.get(name), name, None, entry, titles))
    return sorted(lines, key=lambda x: (x.lms_name.lower() or "~", x.learner, x.activity))


def lines_of(
    lines: Iterable[GradebookLine], learner: str, kind: str, slug: str
) -> list[GradebookLine]:
    """One learner's lines for one activity: a line per LMS link (course) that opens it."""
    return [ln for ln in lines if (ln.learner, ln.kind, ln.slug) == (learner, kind, slug)]


def counts(lines: Iterable[GradebookLine]) -> dict[State, int]:
    found: dict[State, int] = dict.fromkeys(STATES, 0)
    for line in lines:
        found[line.state] += 1
    return found


CSV_COLUMNS = (
    "learner", "lms_name", "seat", "activity", "kind", "slug", "lms_link", "grade_column",
    "state", "score", "time_spent_s", "graded_attempts", "last_graded_utc", "earned",
    "sent_utc", "lms_answer", "tries",
)  # fmt: skip


def gradebook_csv(lines: Iterable[GradebookLine]) -> str:
    """The gradebook as a spreadsheet takes it: a row per line, ``CSV_COLUMNS``.

    A cell that a spreadsheet would run as a formula (an LMS's name starting with
    '=', '+', '-' or '@') is written with a leading apostrophe: names come from the
    LMS, and a teacher opens this file in a spreadsheet.
    """
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(CSV_COLUMNS)
    for line in lines:
        row = (
            line.learner, line.lms_name, line.seat, line.activity, line.kind, line.slug,
            line.link, line.lineitem or "", line.state, line.score,
            "" if line.time_spent is None else line.time_spent,
            line.graded if line.kind == "exercise" else "",
            _utc(line.last_graded), line.queued_at, _utc(line.sent_at), line.lms_answer,
            line.attempts,
        )  # fmt: skip
        writer.writerow([_inert(cell) for cell in row])
    return out.getvalue()


def _utc(stamp: float | None) -> str:
    return "" if not stamp else datetime.fromtimestamp(stamp, timezone.utc).isoformat()


def _inert(cell: object) -> object:
    if isinstance(cell, str) and cell[:1] in ("=", "+", "-", "@", "\t", "\r"):
        return "'" + cell
    return cell

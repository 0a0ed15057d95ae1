"""One result for the LMS gradebook, in the form of AGS's score service.

"Better" is what a teacher means: a higher share of the maximum. An equal
share is not better, so a repeated result is never posted again.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from datetime import datetime, timedelta, timezone
from typing import TypedDict

ACTIVITY_PROGRESS = ("Initialized", "Started", "InProgress", "Submitted", "Completed")
GRADING_PROGRESS = ("FullyGraded", "Pending", "PendingManual", "Failed", "NotReady")


def _parse(stamp: str) -> datetime:
    # Python 3.10's fromisoformat does not read a trailing "Z".
    return datetime.fromisoformat(stamp.replace("Z", "+00:00"))


def now_iso() -> str:
    """An ISO 8601 time with its offset, to the millisecond, as AGS wants timestamps."""
    return datetime.now(timezone.utc).isoformat(timespec="milliseconds")


class _AgsScoreRequired(TypedDict):
    userId: str
    scoreGiven: float
    scoreMaximum: float
    activityProgress: str
    gradingProgress: str
    timestamp: str


class AgsScore(_AgsScoreRequired, total=False):
    """A score as AGS carries it: the JSON body of a POST to ``<lineitem>/scores``."""

    comment: str


@dataclass(frozen=True)
class Score:
    user_id: str  # the launch's `sub`
    score_given: float
    score_maximum: float
    comment: str = ""  # what was checked and the seed to replay it
    activity_progress: str = "Completed"
    grading_progress: str = "FullyGraded"
    timestamp: str = ""  # ISO 8601 with offset; empty: now

    def __post_init__(self) -> None:
        if not self.user_id:
            raise ValueError("a score needs the learner's LMS user id")
        if self.score_maximum <= 0 or self.score_given < 0:
            raise ValueError(
                "a score needs 0 <= given and maximum > 0, "
                f"got {self.score_given}/{self.score_maximum}"
            )
        if self.activity_progress not in ACTIVITY_PROGRESS:
            raise ValueError(f"activityProgress must be one of {ACTIVITY_PROGRESS}")
        if self.grading_progress not in GRADING_PROGRESS:
            raise ValueError(f"gradingProgress must be one of {GRADING_PROGRESS}")
        stamp = self.timestamp or now_iso()
        if _parse(stamp).tzinfo is None:
            raise ValueError(f"the timestamp {stamp!r} has no time zone")
        object.__setattr__(self, "timestamp", stamp)

    @property
    def share(self) -> float:
        return self.score_given / self.score_maximum

    def better_than(self, other: Score) -> bool:
        return self.share > other.share

    def later_than(self, other: Score) -> Score:
        """This score, its timestamp moved just past ``other``'s if it is not already later."""
        floor = _parse(other.timestamp) + timedelta(milliseconds=1)
        if _parse(self.timestamp) >= floor:
            return self
        return replace(self, timestamp=floor.isoformat(timespec="milliseconds"))

    def to_ags(self) -> AgsScore:
        """The JSON body of a POST to ``<lineitem>/scores``."""
        return {
            "userId": self.user_id,
            "scoreGiven": self.score_given,
            "scoreMaximum": self.score_maximum,
            "activityProgress": self.activity_progress,
            "gradingProgress": self.grading_progress,
            "timestamp": self.timestamp,
            "comment": self.comment,
        }

    @classmethod
    def from_ags(cls, body: AgsScore) -> Score:
        return cls(
            user_id=str(body["userId"]),
            score_given=float(body["scoreGiven"]),
            score_maximum=float(body["scoreMaximum"]),
            comment=str(body.get("comment", "")),
            activity_progress=str(body["activityProgress"]),
            grading_progress=str(body["gradingProgress"]),
            timestamp=str(body["timestamp"]),
        )

"""Grade passback to the test LMS: the score's fields, the best result only, the outbox."""

from __future__ import annotations

import json
import socket
from datetime import datetime
from pathlib import Path

import pytest

from app.lti.access_tokens import AccessTokens
from app.lti.ags import PostOutcome, ScoreService, scores_url
from app.lti.keys import ToolKeys
from app.lti.outbox import OUTBOX_FILE, Outbox
from app.lti.registration import Registrations
from app.lti.score import Score
from tests.lti.platform import CLIENT_ID, SCORE_MEDIA_TYPE, TestPlatform

COMMENT = "talker_listener: 5/5 checks passed (seed 1234 replays this grading)"


class Clock:
    def __init__(self) -> None:
        self.now = 1_000_000.0

    def __call__(self) -> float:
        return self.now


def _service(platform: TestPlatform, keys: ToolKeys, **changes: str) -> ScoreService:
    registrations = Registrations([platform.registration(**changes)])
    return ScoreService(registrations, AccessTokens(keys))


def _outbox(folder: Path, platform: TestPlatform, keys: ToolKeys, clock: Clock) -> Outbox:
    return Outbox(folder, _service(platform, keys), clock=clock)


def _score(given: float, user: str = "learner-42", maximum: float = 10) -> Score:
    return Score(user, given, maximum, comment=COMMENT)


def _submit(outbox: Outbox, platform: TestPlatform, score: Score, item: str = "11") -> bool:
    return outbox.submit(platform.issuer, CLIENT_ID, platform.lineitem_url(item), score)


def test_scores_url_goes_before_the_query() -> None:
    assert scores_url("https://lms.edu/api/lineitems/7?type_id=3") == (
        "https://lms.edu/api/lineitems/7/scores?type_id=3"
    )
    assert (
        scores_url("https://lms.edu/api/lineitems/7/") == "https://lms.edu/api/lineitems/7/scores"
    )


def test_a_score_reaches_the_platform_with_every_field_right(
    platform: TestPlatform, tool_keys: ToolKeys
) -> None:
    service = _service(platform, tool_keys)
    score = Score("learner-42", 8.5, 10, comment=COMMENT, activity_progress="Submitted")
    lineitem = platform.lineitem_url("11", query="type_id=3")
    outcome = service.post(platform.issuer, CLIENT_ID, lineitem, score)
    assert outcome == PostOutcome("delivered")
    [(path, query, kind)] = platform.score_requests
    assert (path, query, kind) == ("/lineitems/11/scores", "type_id=3", SCORE_MEDIA_TYPE)
    [stored] = platform.scores["11"]
    assert {k: v for k, v in stored.items() if k != "timestamp"} == {
        "userId": "learner-42",
        "scoreGiven": 8.5,
        "scoreMaximum": 10,
        "activityProgress": "Submitted",
        "gradingProgress": "FullyGraded",
        "comment": COMMENT,
    }
    stamp = datetime.fromisoformat(stored["timestamp"])
    assert stamp.tzinfo is not None and stamp.utcoffset() is not None


def test_one_token_serves_many_scores_and_a_revoked_one_is_renewed(
    platform: TestPlatform, tool_keys: ToolKeys
) -> None:
    service = _service(platform, tool_keys)
    for user in ("a", "b", "c"):
        assert service.post(
            platform.issuer, CLIENT_ID, platform.lineitem_url("11"), _score(7, user)
        )
    assert platform.token_requests == 1
    platform.revoke_tokens()
    outcome = service.post(platform.issuer, CLIENT_ID, platform.lineitem_url("11"), _score(7, "d"))
    assert outcome.kind == "delivered"
    assert platform.token_requests == 2
    assert [s["userId"] for s in platform.scores["11"]] == ["a", "b", "c", "d"]


def test_a_token_endpoint_that_refuses_our_key_keeps_the_score_waiting(
    platform: TestPlatform, tool_keys: ToolKeys, tmp_path: Path
) -> None:
    platform.tool_jwks = ToolKeys.load_or_create(tmp_path / "someone-else").public_jwks()
    outcome = _service(platform, tool_keys).post(
        platform.issuer, CLIENT_ID, platform.lineitem_url("11"), _score(5)
    )
    assert outcome.kind == "retry"
    assert "the token endpoint refused us: HTTP 401" in outcome.reason
    assert "client assertion refused" in platform.token_refusals[0]
    assert platform.scores["11"] == []


def test_a_worse_score_is_never_sent_a_better_one_replaces(
    platform: TestPlatform, tool_keys: ToolKeys, outbox_dir: Path
) -> None:
    outbox = _outbox(outbox_dir, platform, tool_keys, Clock())
    assert _submit(outbox, platform, _score(8))
    assert outbox.deliver_due() == 1
    assert not _submit(outbox, platform, _score(5))  # worse
    assert not _submit(outbox, platform, _score(8))  # the same result again
    assert outbox.deliver_due() == 0
    assert _submit(outbox, platform, _score(9))
    assert outbox.deliver_due() == 1
    assert [s["scoreGiven"] for s in platform.scores["11"]] == [8, 9]
    assert [e.score.score_given for e in outbox.entries()] == [9]
    # Another learner and another line item are kept apart.
    assert _submit(outbox, platform, _score(1, user="learner-7"))
    assert _submit(outbox, platform, _score(2), item="12")
    assert outbox.deliver_due() == 2
    assert len(platform.scores["11"]) == 3 and len(platform.scores["12"]) == 1


def test_an_outage_keeps_the_score_until_a_later_retry_delivers_it_once(
    platform: TestPlatform, tool_keys: ToolKeys, outbox_dir: Path
) -> None:
    clock = Clock()
    outbox = _outbox(outbox_dir, platform, tool_keys, clock)
    platform.fail_next("11", 503, "maintenance", times=2)
    _submit(outbox, platform, _score(10))
    assert outbox.deliver_due() == 0
    [entry] = outbox.entries()
    assert (entry.status, entry.attempts) == ("pending", 1)
    assert "HTTP 503" in entry.reason and "maintenance" in entry.reason
    assert outbox.deliver_due() == 0  # not before its backoff
    assert len(platform.score_requests) == 1
    clock.now += 5
    assert outbox.deliver_due() == 0  # still down
    clock.now += 9
    assert outbox.deliver_due() == 0  # the second wait is longer
    clock.now += 1
    assert outbox.deliver_due() == 1  # the platform is back
    clock.now += 3600
    assert outbox.deliver_due() == 0
    assert [s["scoreGiven"] for s in platform.scores["11"]] == [10]
    [entry] = outbox.entries()
    assert (entry.status, entry.attempts) == ("delivered", 3)


def test_an_unreachable_platform_keeps_the_score(
    platform: TestPlatform, tool_keys: ToolKeys, outbox_dir: Path
) -> None:
    with socket.socket() as closed:
        closed.bind(("127.0.0.1", 0))
        dead = f"http://127.0.0.1:{closed.getsockname()[1]}"
    service = _service(platform, tool_keys)
    outbox = Outbox(outbox_dir, service, clock=Clock())
    for user in ("a", "b"):
        outbox.submit(platform.issuer, CLIENT_ID, f"{dead}/lineitems/11", _score(4, user))
    assert outbox.deliver_due() == 0
    entries = outbox.entries()
    assert [e.status for e in entries] == ["pending", "pending"]
    assert "could not be reached" in entries[0].reason
    # The first silence is enough: the second score is not made to wait for its own timeout.
    assert [e.attempts for e in entries] == [1, 0]


def test_a_refusal_is_kept_as_failed_with_the_platforms_reason(
    platform: TestPlatform, tool_keys: ToolKeys, outbox_dir: Path
) -> None:
    clock = Clock()
    outbox = _outbox(outbox_dir, platform, tool_keys, clock)
    platform.fail_next("11", 400, "userId learner-42 is not enrolled in this course")
    _submit(outbox, platform, _score(6))
    assert outbox.deliver_due() == 0
    [entry] = outbox.entries()
    assert entry.status == "failed"
    assert entry.reason == (
        'HTTP 400: {"error": "userId learner-42 is not enrolled in this course"}'
    )
    clock.now += 3600
    assert outbox.deliver_due() == 0  # refused for good: not asked again
    assert len(platform.score_requests) == 1
    assert _submit(outbox, platform, _score(7))  # a better result is tried afresh
    assert outbox.deliver_due() == 1


def test_a_queued_score_survives_the_process(
    platform: TestPlatform, tool_keys: ToolKeys, outbox_dir: Path
) -> None:
    first = _outbox(outbox_dir, platform, tool_keys, Clock())
    _submit(first, platform, _score(9))
    del first  # "killed" between queueing and sending
    on_disk = json.loads((outbox_dir / OUTBOX_FILE).read_text())
    assert [e["score"]["scoreGiven"] for e in on_disk["entries"]] == [9]
    assert [p.name for p in outbox_dir.iterdir()] == [OUTBOX_FILE]  # no half-written draft
    second = _outbox(outbox_dir, platform, tool_keys, Clock())
    assert second.deliver_due() == 1
    assert [s["scoreGiven"] for s in platform.scores["11"]] == [9]
    third = _outbox(outbox_dir, platform, tool_keys, Clock())
    assert third.deliver_due() == 0  # it remembers what was delivered
    assert not _submit(third, platform, _score(8))  # and what the best is
    assert len(platform.scores["11"]) == 1


class KilledAfterSending(BaseException):
    """The process dies right after the platform got the score, before the outbox noted it."""


def test_a_resend_after_a_crash_is_not_a_second_score(
    platform: TestPlatform, tool_keys: ToolKeys, outbox_dir: Path
) -> None:
    service = _service(platform, tool_keys)

    class DyingSender:
        def post(self, issuer: str, client_id: str, lineitem: str, score: Score) -> PostOutcome:
            service.post(issuer, client_id, lineitem, score)
            raise KilledAfterSending

    doomed = Outbox(outbox_dir, DyingSender(), clock=Clock())
    _submit(doomed, platform, _score(7))
    with pytest.raises(KilledAfterSending):
        doomed.deliver_due()
    assert len(platform.scores["11"]) == 1
    restarted = _outbox(outbox_dir, platform, tool_keys, Clock())
    assert restarted.deliver_due() == 1  # the platform says it has it already (409)
    [entry] = restarted.entries()
    assert entry.status == "delivered" and "409" in entry.reason
    assert len(platform.scores["11"]) == 1


def test_results_within_one_millisecond_still_replace(
    platform: TestPlatform, tool_keys: ToolKeys, outbox_dir: Path
) -> None:
    outbox = _outbox(outbox_dir, platform, tool_keys, Clock())
    stamp = "2026-03-01T10:00:00.000+00:00"
    _submit(outbox, platform, Score("learner-42", 3, 10, timestamp=stamp))
    outbox.deliver_due()
    _submit(outbox, platform, Score("learner-42", 4, 10, timestamp=stamp))
    outbox.deliver_due()
    assert [(s["scoreGiven"], s["timestamp"]) for s in platform.scores["11"]] == [
        (3, stamp),
        (4, "2026-03-01T10:00:00.001+00:00"),
    ]


def test_a_score_for_no_registration_is_refused(
    platform: TestPlatform, tool_keys: ToolKeys
) -> None:
    service = ScoreService(Registrations([]), AccessTokens(tool_keys))
    outcome = service.post(platform.issuer, CLIENT_ID, platform.lineitem_url("11"), _score(1))
    assert outcome.kind == "refused" and "no registration" in outcome.reason


def test_a_score_needs_a_time_zone_and_sane_points() -> None:
    with pytest.raises(ValueError, match="no time zone"):
        Score("u", 1, 2, timestamp="2026-03-01T10:00:00")
    with pytest.raises(ValueError, match="maximum > 0"):
        Score("u", 1, 0)
    assert Score("u", 1, 2, timestamp="2026-03-01T10:00:00Z").share == 0.5

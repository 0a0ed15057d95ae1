"""LTI 1.3 in the one-server classroom mode: the teacher service's handlers on their own port.

The classroom's pages are viser's, whose server (websockets) answers GET
only, while an LMS posts every launch as a form. So LTI gets a small tornado
server of its own, on another port, with the very handlers the hub's teacher
service uses (app/hub/lti_service.py, app/hub/lti_gradebook.py) and the same
tool folder (key, platforms.toml, launches, outbox). What differs from the hub:

- **Where a launch goes.** No hub logs anyone in: the classroom has N learner
  dashboards (learner1..N), each at its own address (and token). An LMS
  learner gets a seat, the first dashboard no LMS learner has yet, kept in
  ``seats.json`` so the same person always comes back to the same dashboard
  and its progress. With every seat taken, the launch is refused with a page
  that says so. A teacher goes to the teacher page.
- **Where progress comes from.** The roster (what the dashboards publish on
  the classroom domain) is read every second; the record of a seat of this
  machine's classroom is graded as its LMS learner's.
- **Who is a teacher for the gradebook.** Whoever brings the teacher page's
  token (``?token=``, then a cookie of this server).
- **Where a learner's attempts are.** Every seat's dashboard keeps its graded
  attempts in the classroom's progress folder on this machine, where the
  gradebook's history reads them, dashboard running or not.

All of it runs on the server's one tornado thread, as in the hub's service;
the outbox sends on a thread of its own.
"""

from __future__ import annotations

import asyncio
import hmac
import json
import logging
import os
import threading
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import asdict, replace
from pathlib import Path
from urllib.parse import urlsplit

from tornado import ioloop, web
from tornado.httpserver import HTTPServer
from tornado.netutil import bind_sockets

from app.hub.lti_gradebook import PAGE_PATH, gradebook_routes
from app.hub.lti_service import DEFAULT_DIR, OUTBOX_POLL_SEC, LtiService, opening
from app.lti.deep_linking import Activity
from app.lti.dynamic_registration import registration_url
from app.lti.history import Attempt, AttemptSource, valid_names
from app.lti.rejection import LaunchRejected
from app.lti.routes import ToolUrls
from app.lti.state_file import save_json
from app.lti.tool import LtiTool
from app.teacher.attempt_files import AttemptReader, exercise_folder
from app.teacher.record import MAX_HISTORY, LearnerRecord
from app.teacher.time_spent import activity_key, read_totals
from app.teacher.time_spent import file_for as time_file_for

log = logging.getLogger(__name__)

SEATS_FILE = "seats.json"
ROSTER_POLL_SEC = 1.0


class Seats:
    """Which LMS learner sits at which learner dashboard; one JSON file, rewritten whole."""

    def __init__(self, folder: Path, seats: Sequence[str]) -> None:
        folder.mkdir(parents=True, exist_ok=True, mode=0o700)
        self.path = folder / SEATS_FILE
        self.seats = list(seats)
        self._seat: dict[str, str] = {}  # LMS learner's hub name -> seat, kept across runs
        if self.path.exists():
            self._seat = dict(json.loads(self.path.read_text(encoding="utf-8"))["seats"])

    def seat_of(self, name: str) -> str | None:
        seat = self._seat.get(name)
        return seat if seat in self.seats else None

    def owner_of(self, seat: str) -> str | None:
        return next((n for n, s in self._seat.items() if s == seat), None)

    def take(self, name: str) -> str:
        """``name``'s seat: the one they had, else the first free; ``LaunchRejected`` if none."""
        seat = self.seat_of(name)
        if seat is not None:
            return seat
        taken = set(self._seat.values())
        free = next((s for s in self.seats if s not in taken), None)
        if free is None:
            raise LaunchRejected(
                f"all {len(self.seats)} learner dashboards of this classroom already have a "
                "learner from the LMS: ask the teacher to start the classroom with more "
                "--learners"
            )
        self._seat[name] = free
        self._save()
        log.info("LTI: %s sits at %s", name, free)
        return free

    def _save(self) -> None:
        save_json(self.path, {"version": 1, "seats": dict(self._seat)})


class TeacherToken(web.RequestHandler):
    """Auth for the gradebook: the teacher page's token, in the URL once, then in a cookie."""

    def get_current_user(self) -> str | None:
        expected = str(self.settings["teacher_token"]).encode()
        # Browsers share cookies across the ports of a host: one name per classroom server.
        cookie = f"classroom_lti_teacher_{self.settings['port']}"
        from_url = self.get_argument("token", None)
        given = from_url or self.get_cookie(cookie)
        if not given or not hmac.compare_digest(given.encode(), expected):
            return None
        if from_url:
            self.set_cookie(
                cookie,
                from_url,
                httponly=True,
                samesite="Strict",
                secure=self.request.protocol == "https",
            )
        return "teacher"

    def get_login_url(self) -> str:
        raise web.HTTPError(403)  # no login page: the token is the login


class ClassroomLti(LtiService):
    """The LTI service with the classroom's seats instead of the hub's handoff."""

    def __init__(
        self,
        tool: LtiTool,
        seats: Seats,
        learner_urls: Mapping[str, str],
        teacher_url: str,
        *,
        site: str,
        progress_root: Path | None = None,
        catalog: Sequence[Activity] | None = None,
        poll_sec: float = OUTBOX_POLL_SEC,
    ) -> None:
        super().__init__(tool, service_prefix="/", catalog=catalog, poll_sec=poll_sec)
        self.seats, self.learner_urls = seats, dict(learner_urls)
        self.teacher_url, self.site = teacher_url, site
        self.progress_root = progress_root  # classroom's --progress-dir: seats' folders in it
        self._reader = AttemptReader()

    def learner_destination(self, name: str, activity: tuple[str, str] | None = None) -> str:
        return opening(self.learner_urls[self.seats.take(name)], activity)

    def teacher_destination(self, name: str) -> str:
        return self.teacher_url

    def seat_of(self, name: str) -> str:
        return self.seats.seat_of(name) or ""

    def attempts_source(self, name: str, slug: str) -> AttemptSource:
        """The seat's own attempt folder, read where its dashboard keeps it (app/cli.py)."""
        replay = (
            "it would run the learner's code on the classroom's server, outside the limits "
            "and the containment their dashboard runs it in"
        )
        seat = self.seats.seat_of(name)
        if seat is None or self.progress_root is None or not valid_names(seat, slug):
            where = (
                f"{name} has no dashboard of this classroom now, so no attempt folder to read."
                if seat is None
                else "This classroom was started without a progress folder to read them from."
            )
            return AttemptSource((), where=where, replay=replay)
        folder = exercise_folder(self.progress_root / "bags" / seat, slug)
        kept = self._reader.newest(folder, MAX_HISTORY)
        code = self.progress_root / seat / f"{seat}.code" / f"{slug}.py"
        return AttemptSource(
            tuple(Attempt(**asdict(each)) for each in kept),
            where=(
                f"Read from the attempts {seat}'s dashboard keeps on this machine (its newest "
                f"{MAX_HISTORY} gradings of each exercise), whether or not it runs now."
            ),
            replay=replay,
            code_file=str(code),
            recordings=(
                f"Each of these gradings is recorded in {folder} (a folder per attempt, named "
                "by its time, seed and verdict, with an MCAP file of what the grader sent and "
                "what came back): open one in Foxglove or Lichtblick, or ask the learner to "
                "pick it under Attempt in their Exercise tab and press Watch this attempt."
            ),
        )

    def time_spent_of(self, name: str, kind: str, slug: str) -> int | None:
        """The seat's own totals, read where its dashboard keeps them (the seats report over
        DDS, whose message does not carry them); None without a seat or a progress folder."""
        seat = self.seats.seat_of(name)
        if seat is None or self.progress_root is None or not kind:
            return None
        totals = read_totals(time_file_for(self.progress_root / seat / f"{seat}.json"))
        return totals.get(activity_key(kind, slug))

    def on_seat_records(self, records: Iterable[LearnerRecord]) -> int:
        """The roster's records: each seat of ours that an LMS learner holds is graded as theirs."""
        queued = 0
        for record in records:
            owner = self.seats.owner_of(record.learner) if record.site == self.site else None
            if owner is not None:
                queued += self.on_record(replace(record, learner=owner))
        return queued

    def routes(self, prefix: str) -> list[tuple[str, type[web.RequestHandler], dict[str, object]]]:
        back = (self.teacher_url, "The teacher page")
        return [*self.lms_routes(prefix), *gradebook_routes(prefix, self, TeacherToken, back=back)]


class ClassroomLtiServer:
    """The LTI routes and the gradebook on their own port, on a tornado loop in a thread."""

    def __init__(
        self,
        lti: ClassroomLti,
        host: str,
        port: int,
        teacher_token: str,
        records: Callable[[], Iterable[LearnerRecord]],
        *,
        roster_poll_sec: float = ROSTER_POLL_SEC,
    ) -> None:
        self.lti, self._records, self._roster_poll = lti, records, roster_poll_sec
        self.prefix = (urlsplit(lti.tool.urls.base).path.rstrip("/")) + "/"
        self._sockets = bind_sockets(port, host)  # here: a busy port fails the caller at once
        self.port = self._sockets[0].getsockname()[1]
        self._app = web.Application(
            lti.routes(self.prefix),
            cookie_secret=os.urandom(32),
            xsrf_cookies=True,
            teacher_token=teacher_token,
            port=self.port,
        )
        self._loop = asyncio.new_event_loop()
        self._ready = threading.Event()
        self._thread = threading.Thread(target=self._run, name="classroom-lti", daemon=True)

    @property
    def gradebook_url(self) -> str:
        """The gradebook with the teacher's token: what the classroom prints for the teacher."""
        return f"{self.lti.tool.urls.base}/{PAGE_PATH}?token={self._app.settings['teacher_token']}"

    def start(self) -> None:
        self._thread.start()
        if not self._ready.wait(15):
            raise RuntimeError("the LTI server did not start")

    def _run(self) -> None:
        asyncio.set_event_loop(self._loop)
        self._server = HTTPServer(self._app, xheaders=True)  # behind the school's TLS proxy
        self._server.add_sockets(self._sockets)
        self.lti.start()
        self._roster = ioloop.PeriodicCallback(self._grade_roster, self._roster_poll * 1000)
        self._roster.start()
        self._ready.set()
        self._loop.run_forever()

    def _grade_roster(self) -> None:
        try:
            self.lti.on_seat_records(self._records())
        except Exception:  # a bad record or a full disk: the next round tries again
            log.exception("LTI: grading the classroom's progress failed")

    def close(self) -> None:
        if not self._thread.is_alive():
            for sock in self._sockets:
                sock.close()
            return

        def stop() -> None:
            self._roster.stop()
            self._server.stop()
            self.lti.stop()
            self._loop.stop()

        self._loop.call_soon_threadsafe(stop)
        self._thread.join(timeout=15)
        self._loop.close()


def classroom_lti(
    base_url: str,
    *,
    learner_urls: Mapping[str, str],
    teacher_url: str,
    teacher_token: str,
    site: str,
    host: str,
    port: int,
    records: Callable[[], Iterable[LearnerRecord]],
    folder: Path = DEFAULT_DIR,
    progress_root: Path | None = None,
) -> ClassroomLtiServer:
    """The classroom's LTI server, not yet started; ``ValueError``/``OSError`` say what is wrong."""
    urls = ToolUrls.from_base(base_url)
    tool = LtiTool(folder, urls)
    if not list(tool.registrations):
        log.warning("LTI: no LMS registered in %s: every launch will be refused", folder)
    log.info("LTI: dynamic registration URL (paste it into the LMS): %s",
             registration_url(urls, folder))  # fmt: skip
    lti = ClassroomLti(
        tool,
        Seats(folder, list(learner_urls)),
        learner_urls,
        teacher_url,
        site=site,
        progress_root=progress_root,
    )
    return ClassroomLtiServer(lti, host, port, teacher_token, records)

"""LTI 1.3 in the teacher service: thin tornado handlers around ``app.lti``, and grade passback.

Served under the service's prefix (``/services/classroom-teacher/``):

- ``lti/login`` (GET or POST): the LMS's login initiation, answered with a
  redirect to its auth endpoint;
- ``lti/launch`` and ``lti/deep-link`` (POST): the signed launch. A learner
  is sent through the hub's handoff page (app/hub/lti_login.py) to their own
  server, a teacher to the teacher's page, and a deep-linking request gets
  the activity picker;
- ``lti/deep-link/return`` (POST): the picker's form; the answer posts the
  signed picks back to the LMS;
- ``lti/jwks`` (GET): the tool's public key set;
- ``lti/handoff`` (POST): the hub trades a launch's one-time ticket for the
  user to log in.

Progress reports (``api/progress``) come through ``on_record``: a finished
lesson or a passed exercise of a learner who launched it from an LMS becomes
a score in the outbox, which a thread of its own empties, scheduled from
tornado's loop; the graded attempts a report carries are kept for the
gradebook's history of that learner and exercise (app/lti/history.py).
Checking a launch may fetch the LMS's keys, so it too runs off the loop.
Everything else runs on the loop's thread.
"""

from __future__ import annotations

import json
import logging
import os
from asyncio import Future
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any
from urllib.parse import quote, urlencode, urlsplit, urlunsplit

from tornado import ioloop, web

from app import PROJECT_ROOT
from app.hub.lti_catalog import course_activities
from app.lti import claims
from app.lti.deep_linking import Activity, DeepLinkingError
from app.lti.dynamic_registration import (
    RegistrationRefused,
    close_page,
    register,
    registration_url,
)
from app.lti.gradebook import GradebookLine, gradebook
from app.lti.handoff import Handoff, HandoffRefused, HandoffTickets
from app.lti.history import Attempt, AttemptHistory, AttemptSource
from app.lti.launch import Launch
from app.lti.learners import activity_of, hub_user_name
from app.lti.pages import picker_page, refusal_page
from app.lti.rejection import LaunchRejected
from app.lti.routes import (
    DEEP_LINK_PATH,
    JWKS_PATH,
    LAUNCH_PATH,
    LOGIN_PATH,
    REGISTER_PATH,
    ToolUrls,
)
from app.lti.time_book import TimeBook
from app.lti.tool import GradedResult, LtiTool
from app.teacher.record import MAX_HISTORY, LearnerRecord

if TYPE_CHECKING:
    from typing import TypedDict

    class _Graded(TypedDict, total=False):
        """The fields of a gradebook line that its exercise's attempt history fills."""

        graded: int
        last_graded: float | None


log = logging.getLogger(__name__)

HANDOFF_PAGE = "lti-handoff"  # under the hub's /hub/: app/hub/lti_login.py serves it
HANDOFF_API = "/lti/handoff"
PICK_PATH = DEEP_LINK_PATH + "/return"
OUTBOX_POLL_SEC = 1.0
DEFAULT_DIR = PROJECT_ROOT / "var" / "lti"


def results_in(record: LearnerRecord) -> list[GradedResult]:
    """What a progress report proves done: its lesson's last step passed, its exercise passed.

    A report shows one lesson (the learner's current one, at its current step,
    with that step's checks) and one exercise (the one worked on last). A lesson
    counts as done when the learner is on its last step and every check of that
    step passes (the report says nothing of earlier steps, which Next lets a
    learner skip); an exercise when the grader passed it in this learner's server.
    """
    found: list[GradedResult] = []
    states = record.check_states
    if (
        record.lesson_id
        and record.steps > 0
        and record.step == record.steps
        and states
        and all(state == "pass" for state in states)
    ):
        checked = "; ".join(r for r in record.check_reasons if r)
        found.append(
            GradedResult(
                "lesson",
                record.lesson_id,
                f"Lesson {record.unit} ({record.lesson_title or record.lesson_id}) done: "
                f"all {record.steps} steps; the last step's {len(states)} check(s) passed on "
                f"the learner's live ROS 2 graph: {checked}.",
            )
        )
    if record.exercise and record.exercise_passed_here:
        failed = record.exercise_failed_here
        found.append(
            GradedResult(
                "exercise",
                record.exercise,
                f"Exercise {record.exercise} passed: the grader ran its checks and probes "
                "against the learner's own node on a live ROS 2 graph "
                f"({record.exercise_attempts_here} grading run(s), {failed} failed check(s) "
                f"before the pass).{_replay(record)}",
            )
        )
    return found


def _replay(record: LearnerRecord) -> str:
    """The words that let a teacher replay the passing grading, when its seed is known."""
    seed = record.exercise_passed_seed
    if not seed:
        return ""
    return (
        f" Its hidden inputs came from seed {seed}: `ros2-classroom exercise check "
        f"{record.exercise} FILE --seed {seed}`, with the learner's code as FILE, "
        "replays that grading."
    )


class OutboxPump:
    """Empties the outbox on a thread of its own; tornado's loop decides when.

    A round runs every ``poll_sec`` (the outbox itself holds back what is not yet
    due: 5 s, 10 s, 20 s ... after a failure) and at once when a score is queued.
    Rounds never overlap; a kick during a round asks for one more right after it.
    """

    def __init__(self, tool: LtiTool, poll_sec: float = OUTBOX_POLL_SEC) -> None:
        self._tool, self._poll_sec = tool, poll_sec
        self._executor = ThreadPoolExecutor(1, thread_name_prefix="lti-outbox")
        self._periodic: ioloop.PeriodicCallback | None = None
        self._running = self._again = False

    def start(self) -> None:
        """On the loop's thread: first round now (what a restart left waiting), then every poll."""
        self._periodic = ioloop.PeriodicCallback(self.kick, self._poll_sec * 1000)
        self._periodic.start()
        self.kick()

    def stop(self) -> None:
        if self._periodic is not None:
            self._periodic.stop()
        self._executor.shutdown(wait=True)

    def kick(self) -> None:
        if self._running:
            self._again = True
            return
        self._running = True
        loop = ioloop.IOLoop.current()
        future = loop.run_in_executor(self._executor, self._tool.outbox.deliver_due)
        loop.add_future(future, self._done)

    def _done(self, future: Future[int]) -> None:
        self._running = False
        try:
            delivered = future.result()
        except Exception:  # a bug or a full disk: the scores stay on disk for the next round
            log.exception("sending scores to the LMS failed")
        else:
            if delivered:
                log.info("LTI: %d score(s) delivered to the LMS", delivered)
        if self._again:
            self._again = False
            self.kick()


class LtiService:
    """The teacher service's LTI side: the tool, the course's activities, the hub's paths."""

    def __init__(
        self,
        tool: LtiTool,
        *,
        service_prefix: str,
        hub_base: str = "/",
        catalog: Sequence[Activity] | None = None,
        poll_sec: float = OUTBOX_POLL_SEC,
    ) -> None:
        self.tool = tool
        self.service_prefix = _slashed(service_prefix)
        self.hub_base = _slashed(hub_base)
        self.catalog = list(catalog) if catalog is not None else course_activities()
        self.tickets = HandoffTickets()
        self.pump = OutboxPump(tool, poll_sec)
        self.history = AttemptHistory(tool.folder)
        self.time_book = TimeBook(tool.folder)

    def start(self) -> None:
        self.pump.start()

    def stop(self) -> None:
        self.pump.stop()
        self.time_book.save()

    # -- where people are sent ----------------------------------------------------------

    def learner_url(self, name: str, activity: tuple[str, str] | None = None) -> str:
        """The learner's own server, opened at the launch's lesson or exercise (the
        dashboard's ``?lesson=ID`` / ``?exercise=SLUG``); with none, where they left off."""
        return opening(f"{self.hub_base}user/{quote(name)}/", activity)

    def handoff_url(self, handoff: Handoff) -> str:
        ticket = self.tickets.issue(handoff)
        return f"{self.hub_base}hub/{HANDOFF_PAGE}?{urlencode({'ticket': ticket})}"

    # -- what the handlers hand over ----------------------------------------------------

    def after_launch(self, launch: Launch) -> str:
        """Where a checked resource-link launch goes; ``LaunchRejected`` when nowhere."""
        name = hub_user_name(launch.registration.issuer, launch.user_id)
        if launch.is_instructor:
            log.info("LTI: teacher %s (%s) launched; to the teacher's page", name, launch.name)
            return self.teacher_destination(name)
        # Before anything is written: it may refuse.
        where = self.learner_destination(name, activity_of(launch))
        name, item = self.tool.record_launch(launch)
        if item is None:
            log.info("LTI: learner %s launched a link that names no lesson or exercise", name)
        elif not self._known(item.kind, item.slug):
            log.warning(
                "LTI: %s's link names %s %r, not in this course", name, item.kind, item.slug
            )
        elif not item.graded:
            log.info("LTI: %s launched %s %s; no score goes back", name, item.kind, item.slug)
        else:
            log.info("LTI: %s launched %s %s", name, item.kind, item.slug)
        return where

    def learner_destination(self, name: str, activity: tuple[str, str] | None = None) -> str:
        """The hub's handoff page, which logs ``name`` in and opens their own server."""
        return self.handoff_url(Handoff(name, self.learner_url(name, activity), teacher=False))

    def teacher_destination(self, name: str) -> str:
        """The hub's handoff page, which logs ``name`` in as a teacher and opens this service."""
        return self.handoff_url(Handoff(name, self.service_prefix, teacher=True))

    def on_record(self, record: LearnerRecord) -> int:
        """A learner's progress report: queue the scores it earns; the number queued.

        The graded attempts it carries are kept for the gradebook, for any learner
        who came from the LMS (graded link or not)."""
        if record.exercise_history and self.tool.book.learner(record.learner) is not None:
            attempts = (Attempt(**asdict(each)) for each in record.exercise_history)
            self.history.add(record.learner, record.exercise, attempts)
        if record.time_spent and self.tool.book.learner(record.learner) is not None:
            self.time_book.update(record.learner, record.time_spent)
        if not self.tool.graded_items(record.learner):
            return 0
        queued = sum(self.tool.submit(record.learner, result) for result in results_in(record))
        if queued:
            log.info("LTI: %d score(s) queued for %s", queued, record.learner)
            self.pump.kick()
        return queued

    def _known(self, kind: str, slug: str) -> bool:
        return any((a.kind, a.slug) == (kind, slug) for a in self.catalog)

    # -- the teacher's gradebook ----------------------------------------------------------

    def seat_of(self, name: str) -> str:
        """The learner dashboard ``name`` uses, where the deployment has fixed ones ('')."""
        return ""

    def gradebook(self) -> list[GradebookLine]:
        titles = {(a.kind, a.slug): a.title for a in self.catalog}
        lines = gradebook(self.tool.book.learners(), self.tool.outbox.entries(), titles)
        return [
            replace(
                line,
                seat=self.seat_of(line.learner),
                time_spent=self.time_spent_of(line.learner, line.kind, line.slug),
                **self._graded_of(line),
            )
            for line in lines
        ]

    def _graded_of(self, line: GradebookLine) -> _Graded:
        """How many graded attempts at the line's exercise are known, and the newest's time."""
        if line.kind != "exercise" or not line.slug:
            return {}
        attempts = self.attempts_source(line.learner, line.slug).attempts  # newest first
        return {"graded": len(attempts), "last_graded": attempts[0].at if attempts else None}

    def time_spent_of(self, name: str, kind: str, slug: str) -> int | None:
        """Active seconds on an activity, as the learner's progress reports last told
        (app/teacher/time_spent.py); None when none told it."""
        return self.time_book.of(name, kind, slug) if kind else None

    def attempts_source(self, name: str, slug: str) -> AttemptSource:
        """A learner's graded attempts at an exercise, as the gradebook's history shows them.

        On a hub, only what the learner's progress reports brought: each carries the
        newest attempts of the exercise the dashboard is on (app/teacher/beacon.py).
        """
        return AttemptSource(
            self.history.of(name, slug),
            where=(
                "As the learner's dashboard reported them: it sends the newest "
                f"{MAX_HISTORY} gradings of the exercise it is on, and this service keeps "
                f"the newest {self.history.keep} of each exercise, also once the learner "
                "moved on or their server stopped. A grading made while the dashboard "
                "could not reach this service arrives when the learner is next on that "
                "exercise, if it is still among the newest there."
            ),
            replay=(
                "the teacher service runs no ROS 2 graph and has no copy of the learner's "
                "code (gradings run in the learner's own server)"
            ),
            recordings=(
                "Every grading is also recorded (an MCAP file of what the grader sent and "
                "what came back) in the learner's own server: the learner opens one under "
                "Attempt in their Exercise tab and presses Watch this attempt."
            ),
        )

    def lms_names(self) -> dict[str, str]:
        """Each LMS learner's name as the LMS gave it at launch, by hub user name."""
        return {e.name: e.display_name for e in self.tool.book.learners() if e.display_name}

    def retry_now(self) -> int:
        """The teacher's Retry: every score not yet delivered is sent now; the number."""
        count = self.tool.outbox.retry_now()
        if count:
            log.info("LTI: a teacher asked to retry %d score(s) now", count)
            self.pump.kick()
        return count

    # -- routes -----------------------------------------------------------------------------

    def lms_routes(
        self, prefix: str
    ) -> list[tuple[str, type[web.RequestHandler], dict[str, object]]]:
        """What the LMS and the browsers it sends reach: login, launch, picker, keys."""
        args: dict[str, object] = {"lti": self}
        base = _slashed(prefix).rstrip("/")
        return [
            (base + LOGIN_PATH, LoginHandler, args),
            (base + LAUNCH_PATH, LaunchHandler, args),
            (base + DEEP_LINK_PATH, LaunchHandler, args),
            (base + PICK_PATH, PickHandler, args),
            (base + JWKS_PATH, JwksHandler, args),
            (base + REGISTER_PATH, RegisterHandler, args),
        ]

    def routes(self, prefix: str) -> list[tuple[str, type[web.RequestHandler], dict[str, object]]]:
        """The LMS's routes and the hub's ticket trade (the gradebook's come with its auth)."""
        base = _slashed(prefix).rstrip("/")
        return [*self.lms_routes(prefix), (base + HANDOFF_API, HandoffHandler, {"lti": self})]


def _slashed(path: str) -> str:
    path = path if path.startswith("/") else "/" + path
    return path if path.endswith("/") else path + "/"


class _LtiPage(web.RequestHandler):
    """LMS-facing pages: cross-site form posts (no XSRF cookie), HTML errors, no traceback."""

    def initialize(self, lti: LtiService) -> None:
        self.lti = lti

    def check_xsrf_cookie(self) -> None:
        return  # the LMS posts from its own site; the signed id_token or a one-time token guards

    def refuse(self, sentence: str, *, what: str = "This launch from your course") -> None:
        log.warning("LTI: %s refused: %s", what.lower(), sentence)
        self.set_status(400)
        self.set_header("Content-Type", "text/html; charset=utf-8")
        self.set_header("Cache-Control", "no-store")
        self.finish(refusal_page(sentence, what=what))

    def write_error(self, status_code: int, **kwargs: Any) -> None:
        error = kwargs.get("exc_info", (None, None, None))[1]
        if isinstance(error, web.HTTPError) and error.log_message:
            sentence = error.log_message
        else:
            sentence = (
                f"the tool could not handle this request ({status_code} {self._reason}); "
                "the service's log has the details"
            )
        self.set_header("Content-Type", "text/html; charset=utf-8")
        self.finish(refusal_page(sentence))

    def form(self) -> dict[str, str]:
        """The request's query and form fields, the first value of each."""
        return {k: self.get_argument(k) for k in self.request.arguments}


class LoginHandler(_LtiPage):
    def get(self) -> None:
        self._login()

    def post(self) -> None:
        self._login()

    def _login(self) -> None:
        try:
            redirect = self.lti.tool.login(self.form())
        except LaunchRejected as rejected:
            self.refuse(str(rejected), what="This login from your course")
            return
        self.set_header("Cache-Control", "no-store")
        self.redirect(redirect.url, status=302)


def opening(url: str, activity: tuple[str, str] | None) -> str:
    """``url`` with the query that opens a lesson or an exercise on the dashboard added to
    what its query already says (a classroom's ``?token=``); ``url`` itself for none."""
    if activity is None:
        return url
    parts = urlsplit(url)
    query = "&".join(q for q in (parts.query, urlencode({activity[0]: activity[1]})) if q)
    return urlunsplit(parts._replace(path=parts.path or "/", query=query))


class LaunchHandler(_LtiPage):
    async def post(self) -> None:
        id_token = self.get_body_argument("id_token", "")
        state = self.get_body_argument("state", "")
        error = self.get_body_argument("error", "")
        if error:  # the LMS's auth step said no (OIDC error response)
            why = self.get_body_argument("error_description", "") or error
            self.refuse(f"the LMS did not sign this launch: {why}")
            return
        if not id_token or not state:
            self.refuse("the launch carries no id_token and state: start it from the LMS")
            return
        loop = ioloop.IOLoop.current()
        try:
            launch = await loop.run_in_executor(None, self.lti.tool.validate, id_token, state)
        except LaunchRejected as rejected:
            self.refuse(str(rejected))
            return
        self.set_header("Cache-Control", "no-store")
        if launch.message_type == claims.DEEP_LINKING_REQUEST and launch.deep_linking:
            token = self.lti.tool.open_picker(launch)
            self.set_header("Content-Type", "text/html; charset=utf-8")
            self.finish(
                picker_page(
                    self.lti.catalog,
                    action=self.lti.tool.urls.base + PICK_PATH,
                    token=token,
                    multiple=launch.deep_linking.accept_multiple,
                )
            )
            return
        try:
            where = self.lti.after_launch(launch)
        except LaunchRejected as rejected:
            self.refuse(str(rejected))
            return
        self.redirect(where, status=303)


class PickHandler(_LtiPage):
    def post(self) -> None:
        token = self.get_body_argument("token", "")
        form = {
            k: [v.decode("utf-8", "replace") for v in vs]
            for k, vs in self.request.body_arguments.items()
        }
        try:
            page = self.lti.tool.finish_picker(token, form, self.lti.catalog)
        except DeepLinkingError as error:
            self.refuse(str(error), what="Adding the activity")
            return
        log.info("LTI: deep-linking answer with %s", ", ".join(form.get("pick", [])))
        self.set_header("Content-Type", "text/html; charset=utf-8")
        self.set_header("Cache-Control", "no-store")
        self.finish(page)


class JwksHandler(_LtiPage):
    def get(self) -> None:
        self.set_header("Content-Type", "application/json")
        self.set_header("Cache-Control", "public, max-age=300")
        self.finish(json.dumps(self.lti.tool.keys.public_jwks()))


class RegisterHandler(_LtiPage):
    """LTI Dynamic Registration: the LMS's administrator opens this from the LMS, once."""

    async def get(self) -> None:
        tool = self.lti.tool
        loop = ioloop.IOLoop.current()
        try:  # it asks the LMS twice over HTTP: not on the loop
            registration = await loop.run_in_executor(
                None, register, self.form(), tool.urls, tool.folder
            )
        except RegistrationRefused as refused:
            self.refuse(str(refused), what="This registration from your LMS")
            return
        tool.registrations.add(registration)
        log.info(
            "LTI: registered %s client %s deployment %s (dynamic registration)",
            registration.issuer,
            registration.client_id,
            ", ".join(sorted(registration.deployment_ids)),
        )
        self.set_header("Content-Type", "text/html; charset=utf-8")
        self.set_header("Cache-Control", "no-store")
        self.finish(close_page(registration))


class HandoffHandler(_LtiPage):
    """The hub's authenticator trades a ticket for whom to log in and where to send them."""

    def post(self) -> None:
        try:
            handoff = self.lti.tickets.redeem(self.get_body_argument("ticket", ""))
        except HandoffRefused as refused:
            log.warning("LTI: a hub login was refused: %s", refused)
            self.set_status(403)
            self.finish({"error": str(refused)})
            return
        self.finish({"name": handoff.name, "next": handoff.next_url, "teacher": handoff.teacher})


def from_environment(service_prefix: str) -> LtiService | None:
    """The service's LTI side as the deployment configures it; None when LTI is off.

    CLASSROOM_LTI_URL is the address the LMS has for this service (what
    ``ros2-classroom lti config --base-url`` printed); CLASSROOM_LTI_DIR the folder
    with the key, platforms.toml, launches and the outbox (default var/lti).
    """
    base = os.environ.get("CLASSROOM_LTI_URL", "").strip()
    if not base:
        return None
    urls = ToolUrls.from_base(base)
    folder = Path(os.environ.get("CLASSROOM_LTI_DIR") or DEFAULT_DIR)
    tool = LtiTool(folder, urls)
    if not list(tool.registrations):
        log.warning("LTI: no LMS registered in %s: every launch will be refused", folder)
    service = LtiService(
        tool,
        service_prefix=service_prefix,
        hub_base=os.environ.get("JUPYTERHUB_BASE_URL", "/"),
    )
    log.info(
        "LTI: %s, %d platform(s), %d activities, key %s, data in %s",
        urls.base,
        len(list(tool.registrations)),
        len(service.catalog),
        tool.keys.kid,
        folder,
    )
    log.info("LTI: dynamic registration URL (paste it into the LMS): %s",
             registration_url(urls, folder))  # fmt: skip
    return service

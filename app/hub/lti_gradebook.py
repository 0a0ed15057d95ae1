"""The teacher's gradebook page: what went to the LMS, what waits in the outbox, and Retry.

Five routes under the LTI service's prefix, for teachers only:

- ``gradebook`` (GET): the page (app/lti/pages.py draws it);
- ``gradebook.json`` (GET): the same lines as data;
- ``gradebook.csv`` (GET): the same lines for a spreadsheet;
- ``gradebook/retry`` (POST, with the XSRF field): every score not yet
  delivered is tried now, then back to the page;
- ``gradebook/attempts?learner=NAME&activity=KIND:SLUG`` (GET): what a cell of
  the class grid opens, one learner's history of one activity (their graded
  attempts with the seeds that replay them, and the LMS's side). An address
  that names no learner and activity of the gradebook gets a page that says so.

Who counts as a teacher is the deployment's business, so the handlers here
carry no authentication of their own: ``gradebook_routes`` mixes in the
deployment's (the hub's OAuth in app/hub/teacher_service.py, the teacher's
token in the classroom mode, app/hub/lti_classroom.py). The mixin comes
first in the bases and names the current user (``prepare`` or
``get_current_user``); ``@web.authenticated`` refuses everyone it does not name.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

from tornado import web

from app.lti.gradebook import GradebookLine, gradebook_csv, lines_of
from app.lti.pages import HISTORY_PATH, attempts_page, gradebook_page, not_found_page, refusal_page

if TYPE_CHECKING:
    from app.hub.lti_service import LtiService

PAGE_PATH = "gradebook"
JSON_PATH = "gradebook.json"
CSV_PATH = "gradebook.csv"
RETRY_PATH = "gradebook/retry"


class _GradebookBase(web.RequestHandler):
    def initialize(self, lti: LtiService, back: tuple[str, str] | None = None) -> None:
        self.lti, self.back = lti, back

    def set_default_headers(self) -> None:
        self.set_header("Cache-Control", "no-store")

    def write_error(self, status_code: int, **kwargs: Any) -> None:
        error = kwargs.get("exc_info", (None, None, None))[1]
        if status_code == 403:
            sentence = (
                "the gradebook is for the class's teachers: sign in with a teacher's account "
                "(or open the link the classroom printed, which carries the teacher's token)"
            )
        elif isinstance(error, web.HTTPError) and error.log_message:
            sentence = error.log_message
        else:
            sentence = f"{status_code} {self._reason}; the service's log has the details"
        self.set_header("Content-Type", "text/html; charset=utf-8")
        self.finish(refusal_page(sentence, what="Opening the gradebook"))


class GradebookPage(_GradebookBase):
    @web.authenticated
    def get(self) -> None:
        retried = self.get_argument("retried", "")
        notice = ""
        if retried.isdigit():
            notice = (
                f"Sending {retried} score(s) now: reload in a moment to see what the LMS answered."
                if int(retried)
                else "Nothing waits in the outbox: every score was delivered."
            )
        form = f'<form method="post" action="{RETRY_PATH}">{self.xsrf_form_html()}'
        self.set_header("Content-Type", "text/html; charset=utf-8")
        self.finish(
            gradebook_page(
                self.lti.gradebook(),
                now=time.time(),
                retry_form=form,
                back=self.back,
                notice=notice,
            )
        )


class GradebookJson(_GradebookBase):
    @web.authenticated
    def get(self) -> None:
        self.finish({"lines": [line.to_json() for line in self.lti.gradebook()]})


class GradebookCsv(_GradebookBase):
    @web.authenticated
    def get(self) -> None:
        self.set_header("Content-Type", "text/csv; charset=utf-8")
        self.set_header("Content-Disposition", 'attachment; filename="gradebook.csv"')
        self.finish(gradebook_csv(self.lti.gradebook()))


class GradebookRetry(_GradebookBase):
    @web.authenticated
    def post(self) -> None:
        count = self.lti.retry_now()
        page = self.request.path.removesuffix(RETRY_PATH) + PAGE_PATH
        self.redirect(f"{page}?retried={count}", status=303)


_KINDS = ("lesson", "exercise")


def _shown(text: str) -> str:
    return repr(text if len(text) <= 80 else text[:79] + "…")


class GradebookAttempts(_GradebookBase):
    @web.authenticated
    def get(self) -> None:
        learner = self.get_argument("learner", "")
        kind, _, slug = self.get_argument("activity", "").partition(":")
        lines = self.lti.gradebook()
        found = lines_of(lines, learner, kind, slug)
        if not found:
            self._not_found(learner, kind, slug, [ln for ln in lines if ln.learner == learner])
            return
        source = self.lti.attempts_source(learner, slug) if kind == "exercise" else None
        page = attempts_page(
            found, learner=learner, kind=kind, slug=slug, source=source, now=time.time()
        )
        self.set_header("Content-Type", "text/html; charset=utf-8")
        self.finish(page)

    def _not_found(self, learner: str, kind: str, slug: str, theirs: list[GradebookLine]) -> None:
        if kind not in _KINDS or not slug:
            sentence = (
                "this address names no activity: it needs activity=exercise:SLUG or "
                "activity=lesson:ID, as the class grid's cells link it"
            )
        elif not learner:
            sentence = "this address names no learner: it needs learner=NAME (an lti-... name)"
        elif not theirs:
            sentence = f"no learner {_shown(learner)} has opened anything from the LMS here"
        else:
            who = theirs[0].lms_name or learner
            opened = sorted({ln.activity for ln in theirs if ln.activity})
            sentence = (
                f"{who} has no LMS link to {kind} {_shown(slug)} (it may be another course's "
                f"activity); they opened {', '.join(opened) or 'no activity of ours'}"
            )
        self.set_status(404)
        self.set_header("Content-Type", "text/html; charset=utf-8")
        self.finish(not_found_page(sentence))


def gradebook_routes(
    prefix: str,
    lti: LtiService,
    auth: type,
    *,
    back: tuple[str, str] | None = None,
) -> list[tuple[str, type[web.RequestHandler], dict[str, object]]]:
    """The five routes, each handler behind ``auth`` (a mixin that names the teacher).

    ``back`` is the link from the gradebook to the teacher's page: (address, text).
    """
    base = prefix if prefix.endswith("/") else prefix + "/"
    args: dict[str, object] = {"lti": lti, "back": back}
    return [
        (base + path, type(f"{auth.__name__}{handler.__name__}", (auth, handler), {}), args)
        for path, handler in (
            (PAGE_PATH, GradebookPage),
            (JSON_PATH, GradebookJson),
            (CSV_PATH, GradebookCsv),
            (RETRY_PATH, GradebookRetry),
            (HISTORY_PATH, GradebookAttempts),
        )
    ]

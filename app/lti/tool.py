"""The tool's whole LTI state in one place, for the one process that serves LTI.

It holds the tool key, the registered platforms, the login nonces, the
launch book, the handoff tickets, the open pickers and the score outbox,
all under one folder (``CLASSROOM_LTI_DIR``, default ``var/lti``):

    keys/tool-private-key.pem   the tool's key (as ``ros2-classroom lti config`` made it)
    platforms.toml              the registered LMSes, written by the administrator
    launches.json               each LMS learner and the graded links they launched
    outbox.json                 scores on their way to the LMS

A web layer (app/hub/lti_service.py) hands it each request; nothing here
knows tornado or JupyterHub.
"""

from __future__ import annotations

import secrets
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from app.lti.access_tokens import AccessTokens
from app.lti.ags import ScoreService
from app.lti.deep_linking import (
    Activity,
    DeepLinkingError,
    auto_submit_form,
    deep_linking_response,
    picks_from_form,
)
from app.lti.keys import ToolKeys
from app.lti.launch import Launch, LaunchValidator
from app.lti.learners import Kind, LaunchBook, LaunchedItem
from app.lti.login import LoginRedirect, login_redirect
from app.lti.nonces import NonceStore
from app.lti.outbox import Outbox
from app.lti.registration import Registrations, load_registrations
from app.lti.routes import ToolUrls
from app.lti.score import Score

PLATFORMS_FILE = "platforms.toml"
KEYS_DIR = "keys"
PICKER_LIFE_SEC = 1800.0  # a teacher may take a while to choose
COMMENT_LIMIT = 1000  # LMSes show the comment beside the grade; keep it readable


@dataclass(frozen=True)
class GradedResult:
    """A finished lesson or a passed exercise, as the web layer read it from a progress report."""

    kind: Kind
    slug: str
    comment: str  # what was checked (and the seed that replays the grading, where there is one)


class LtiTool:
    def __init__(
        self,
        folder: Path,
        urls: ToolUrls,
        *,
        registrations: Registrations | None = None,
        keys: ToolKeys | None = None,
        clock: Callable[[], float] = time.time,
    ) -> None:
        folder.mkdir(parents=True, exist_ok=True, mode=0o700)
        self.folder, self.urls, self._clock = folder, urls, clock
        self.keys = keys or ToolKeys.load_or_create(folder / KEYS_DIR)
        self.registrations = (
            registrations
            if registrations is not None
            else load_registrations(folder / PLATFORMS_FILE)
        )
        self.nonces = NonceStore()
        self.validator = LaunchValidator(self.registrations, self.nonces)
        self.book = LaunchBook(folder, clock=clock)
        self.tokens = AccessTokens(self.keys)
        self.outbox = Outbox(folder, ScoreService(self.registrations, self.tokens), clock=clock)
        self._pickers: dict[str, tuple[Launch, float]] = {}
        self._pickers_lock = threading.Lock()

    # -- login and launch ---------------------------------------------------------------

    def login(self, params: Mapping[str, str]) -> LoginRedirect:
        """The LMS's login initiation, answered with the redirect to its auth endpoint."""
        return login_redirect(params, self.registrations, self.nonces, self.urls)

    def validate(self, id_token: str, state: str) -> Launch:
        """A checked launch, or ``LaunchRejected``; may fetch the platform's keys (blocking)."""
        return self.validator.validate(id_token, state)

    def record_launch(self, launch: Launch) -> tuple[str, LaunchedItem | None]:
        """The learner's hub name, and the graded item this launch was for (if any)."""
        return self.book.record(launch)

    # -- deep linking -------------------------------------------------------------------

    def open_picker(self, launch: Launch) -> str:
        """A token that lets one picker form answer this deep-linking request, once."""
        token = secrets.token_urlsafe(24)
        with self._pickers_lock:
            now = self._clock()
            self._pickers = {
                t: v for t, v in self._pickers.items() if now - v[1] <= PICKER_LIFE_SEC
            }
            self._pickers[token] = (launch, now)
        return token

    def picker_launch(self, token: str) -> Launch | None:
        with self._pickers_lock:
            found = self._pickers.get(token)
        if found is None or self._clock() - found[1] > PICKER_LIFE_SEC:
            return None
        return found[0]

    def finish_picker(
        self, token: str, form: Mapping[str, Sequence[str]], catalog: Sequence[Activity]
    ) -> str:
        """The auto-submitting page that carries the signed picks back to the LMS."""
        launch = self.picker_launch(token)
        if launch is None or launch.deep_linking is None:
            raise DeepLinkingError(
                "this picker is older than half an hour or was already used: add the "
                "activity again from the LMS"
            )
        picked = picks_from_form(form, catalog)
        response = deep_linking_response(launch, picked, self.keys, self.urls.launch)
        page = auto_submit_form(launch.deep_linking.return_url, response)
        with self._pickers_lock:
            self._pickers.pop(token, None)  # spent only once the answer is made
        return page

    # -- grades -------------------------------------------------------------------------

    def graded_items(self, name: str) -> list[LaunchedItem]:
        entry = self.book.learner(name)
        return [i for i in entry.items if i.graded] if entry else []

    def submit(self, name: str, result: GradedResult) -> int:
        """Queue full marks for every graded link of ``name`` that opens this activity.

        The outbox keeps only a better result than the best so far, so a repeated
        report of the same pass queues nothing; the number queued is returned.
        """
        queued = 0
        for item in self.graded_items(name):
            if (item.kind, item.slug) != (result.kind, result.slug) or item.lineitem is None:
                continue
            score = Score(
                user_id=item.user_id,
                score_given=item.score_maximum,  # full marks: the work is done
                score_maximum=item.score_maximum,
                comment=_clip(result.comment, COMMENT_LIMIT),
                activity_progress="Completed",
                grading_progress="FullyGraded",
            )
            queued += self.outbox.submit(item.issuer, item.client_id, item.lineitem, score)
        return queued


def _clip(text: str, limit: int) -> str:
    return text if len(text) <= limit else text[: limit - 1] + "…"

"""The teacher page: one row per learner, live; the class's exercises; their code; messages.

A viser page of its own, served by the ``classroom`` command on its own port
and always behind its own token (``app.access``): a learner's URL never
opens it and the teacher's token opens no learner's dashboard. viser gives
the same look, widgets and token gate as the learners' dashboards; two plain
HTTP routes on the same server serve the CSV export and the JSON table that
``classroom status`` prints.

On the machine that keeps the learners' attempts (``classroom``), the
"Learner's attempts" tab lists the chosen learner's kept attempts of their
current exercise, shows one's result lines and plots, and plays it with the
learner's own player (``app.stage.replay_stage.ReplayStage``).

Threads, as in the dashboard (app.ui): one UI thread owns every widget and
the teacher's choices; viser callbacks post intents; the routes run on
viser's asyncio thread and read only the roster's copies and the current
(immutable) stuck rule. Reading a recording to play it is a worker job.
"""

from __future__ import annotations

import contextlib
import http
import io
import json
import logging
import re
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from urllib.parse import urlsplit

import cv2
import numpy as np
import viser
from websockets.asyncio.server import ServerConnection
from websockets.datastructures import Headers
from websockets.http11 import Request, Response

from app.access import Handler, ProcessRequest, make_server
from app.exercises.attempt_folders import (
    ATTEMPTS_FOLDER,
    attempt_heading,
    attempt_label,
    replay_of,
)
from app.stage.replay_stage import ReplayStage
from app.teacher.attempt_files import (
    MOST_PLOTS,
    attempt_markdown,
    kept_attempts,
    plot_files,
)
from app.teacher.record import (
    COLUMNS,
    MAX_NOTICE,
    LearnerRecord,
    StuckRule,
    checks_text,
    class_exercises,
    mistake_words,
    plain_markdown,
    table,
    to_csv,
)
from app.teacher.roster import Roster
from app.ui import MarkdownView, assign, set_options
from app.ui.loop import UiLoop

log = logging.getLogger(__name__)

REFRESH_SEC = 0.5
FRAME_SEC = 0.1  # while an attempt plays: its frames come this often
ROUTES = "/classroom/teacher/"
CSV_PATH = ROUTES + "progress.csv"
JSON_PATH = ROUTES + "progress.json"
EVERYONE = "everyone"
NOBODY = "(choose a learner)"
NO_ATTEMPT = "(no attempt kept)"
NO_ATTEMPTS_HERE = (
    "_Choose a learner on the right: their kept attempts of the exercise they are on show "
    "here, with what each judged, its plots, and **Watch this attempt**._"
)


def _cell(value: str) -> str:
    return plain_markdown(str(value))


def markdown_table(rows: list) -> str:
    head = "| " + " | ".join(COLUMNS) + " |\n|" + "---|" * len(COLUMNS) + "\n"
    return head + "\n".join("| " + " | ".join(_cell(v) for v in row) + " |" for row in rows)


def _fenced(text: str, language: str = "") -> str:
    """A code block whose fence is longer than any run of backticks inside it."""
    longest, run = 0, 0
    for char in text:
        run = run + 1 if char == "`" else 0
        longest = max(longest, run)
    fence = "`" * max(3, longest + 1)
    return f"{fence}{language}\n{text}\n{fence}"


_NAME = re.compile(r"[A-Za-z0-9_-]{1,64}")  # a learner's name (app.lessons.progress)
_SLUG = re.compile(r"[a-z][a-z0-9_]{2,48}")  # an exercise's (app.exercises.model)


@dataclass(frozen=True)
class LocalAttempts:
    """The attempts this machine's learners keep, which a teacher page on it may list.

    ``classroom`` runs every learner's dashboard on this machine, each keeping
    its graded attempts in ``<bags_root>/<learner>/attempts/<exercise>/``
    (app/exercises/attempts.py); learners of other sites keep theirs on their
    machines. The names come from the classroom domain (anyone may publish
    there), so only a learner's and an exercise's names ever reach a path.
    """

    bags_root: Path
    site: str

    def kept(self, record: LearnerRecord) -> list[Path]:
        """The kept attempts of the learner's current exercise, newest first ([]: none here)."""
        if record.site != self.site or not (
            _NAME.fullmatch(record.learner) and _SLUG.fullmatch(record.exercise)
        ):
            return []
        return kept_attempts(self.bags_root / record.learner / ATTEMPTS_FOLDER / record.exercise)

    def newest(self, record: LearnerRecord) -> Path | None:
        """The newest kept attempt of the learner's current exercise (None: none here)."""
        kept = self.kept(record)
        return kept[0] if kept else None


def attempt_text(path: Path) -> str:
    """Where the newest attempt is, for a teacher on this machine to open in Foxglove."""
    mcap = sorted(path.glob("*.mcap"))
    opened = _code(str(mcap[0])) if mcap else "the .mcap file in it"
    text = (
        f"**Newest attempt** ({plain_markdown(attempt_label(path))}): {_code(str(path))}\n\n"
        f"Open {opened} in Foxglove or Lichtblick (Open local file), or pick it under "
        "**Attempt** in the **Learner's attempts** tab and press **Watch this attempt**: "
        "its result lines, its plots and its run, played as the learner sees it."
    )
    command = replay_of(path)  # '' : no seed, or its code was not kept
    if command:
        text += f"\n\nIts grading again, on the code it graded: {_code(command)}"
    return text


def _code(text: str) -> str:
    """Inline code whose backtick fence is longer than any run of backticks inside it."""
    fence = "`" * (max((len(run) for run in re.findall(r"`+", text)), default=0) + 1)
    return f"{fence} {text} {fence}" if "`" in text else f"`{text}`"


def exercises_markdown(records: list[LearnerRecord]) -> str:
    """The "Exercises across the class" section (the lines the hub's page shows too)."""
    lines = class_exercises(records)
    body = "\n".join(f"- {plain_markdown(line)}" for line in lines)
    return "### Exercises across the class\n\n" + (body or "_No learner is on an exercise yet._")


def learner_detail(record: LearnerRecord, newest_attempt: Path | None = None) -> str:
    """One learner, read-only: where they are, why checks fail, their code, their last error
    and (on the machine that keeps it) where their newest attempt is."""
    reasons = "\n".join(
        f"- **{plain_markdown(state)}**: {plain_markdown(reason)}"
        for state, reason in zip(record.check_states, record.check_reasons, strict=False)
    )
    parts = [
        f"### {record.learner} ({record.site}, ROS domain {record.domain_id})",
        f"Lesson {record.unit} · {record.lesson_title} · step {record.step}/{record.steps}: "
        f"{record.step_title}",
        f"**Checks** {checks_text(record)}\n\n{reasons}" if reasons else "**Checks** none",
    ]
    if record.exercise:
        mark = "✓ passed" if record.exercise_passed_here else "not passed yet"
        mistake = mistake_words(record.exercise_mistake)
        why = f"; last failure: {plain_markdown(mistake)}" if mistake else ""
        parts.append(
            f"**Exercise `{record.exercise}`**: {mark}, {record.exercise_attempts_here} checks, "
            f"{record.exercise_failed_here} failed{why}"
        )
        if newest_attempt is not None:
            parts.append(attempt_text(newest_attempt))
        if record.last_error:
            parts.append("**Last error**\n\n" + _fenced(record.last_error))
        parts.append("**Their code** (read-only)\n\n" + _fenced(record.code_excerpt, "python"))
    else:
        parts.append("_No exercise in this unit._")
    return "\n\n".join(p for p in parts if p)


def _plot_images(attempt: Path) -> list[np.ndarray]:
    """The attempt's plots as RGB pixels; one that cannot be read is left out (never raises)."""
    images = []
    for path in plot_files(attempt):
        try:
            pixels = cv2.imread(str(path), cv2.IMREAD_COLOR)
        except Exception:  # cv2 raises its own error for some damaged files
            pixels = None
        if pixels is not None:
            images.append(np.ascontiguousarray(pixels[:, :, ::-1]))
    return images


class TeacherRoutes:
    """``progress.csv`` and ``progress.json`` on the page's server (behind its token)."""

    def __init__(self, roster: Roster) -> None:
        self.roster = roster
        self.rule = StuckRule()  # replaced (never mutated) by the page's UI thread

    def wrap_http(self, inner: ProcessRequest | None) -> ProcessRequest:
        def process_request(connection: ServerConnection, request: Request) -> Response | None:
            path = urlsplit(request.path).path
            if path == CSV_PATH:
                body = to_csv(self.roster.records(), self.rule).encode()
                return _ok(body, "text/csv; charset=utf-8", "classroom-progress.csv")
            if path == JSON_PATH:
                rows = table(self.roster.records(), self.rule)
                body = json.dumps({"columns": COLUMNS, "rows": rows}).encode()
                return _ok(body, "application/json")
            return inner(connection, request) if inner is not None else None

        return process_request

    def wrap_handler(self, inner: Handler) -> Handler:
        return inner


def _ok(body: bytes, content_type: str, filename: str | None = None) -> Response:
    headers = Headers(
        {
            "Content-Type": content_type,
            "Content-Length": str(len(body)),
            "Cache-Control": "no-store",
        }
    )
    if filename:
        headers["Content-Disposition"] = f'attachment; filename="{filename}"'
    return Response(http.HTTPStatus.OK, "OK", headers, body)


class TeacherPage:
    def __init__(
        self,
        host: str,
        port: int,
        token: str,
        roster: Roster,
        *,
        reveal_after: int | None = None,
        rule: StuckRule | None = None,
        attempts: LocalAttempts | None = None,
    ) -> None:
        self.roster = roster
        self.attempts = attempts
        self.routes = TeacherRoutes(roster)
        if rule is not None:
            self.routes.rule = rule
        with contextlib.redirect_stdout(io.StringIO()):  # viser's banner: our command prints
            self.server, _gate = make_server(host, port, token, self.routes)
        self.port = self.server.get_port()
        self.ui = UiLoop()
        self._stop = threading.Event()
        self._build(reveal_after)
        self._thread = threading.Thread(target=self._loop, name="teacher-ui", daemon=True)

    def _build(self, reveal_after: int | None) -> None:
        gui, ui = self.server.gui, self.ui
        gui.configure_theme(titlebar_content=None, control_width="large", show_share_button=False)
        self.server.scene.configure_environment_map(None)
        gui.add_markdown(
            f"## ROS 2 Classroom: teacher's view\n[Download the class's progress (CSV)]({CSV_PATH})"
        )
        # The class table is wide: it gets the big window docked on the left.
        window = gui.add_panel()
        window.dock_left()
        window.set_width(1100)
        with window.add_tab("Class", viser.Icon.USERS):
            self._summary = MarkdownView(gui)
            self._table = MarkdownView(gui, "_Waiting for the learners' dashboards…_")
            self._exercises = MarkdownView(gui)
        with window.add_tab("Learner's code", viser.Icon.CODE):
            self._detail = MarkdownView(gui, "_Choose a learner on the right._")
        with window.add_tab("Learner's attempts", viser.Icon.PLAYER_PLAY):
            self._attempts_note = MarkdownView(gui, NO_ATTEMPTS_HERE)
            self._attempt_pick = gui.add_dropdown("Attempt", [NO_ATTEMPT], visible=False)
            self._attempt_text = MarkdownView(gui, "", visible=False)
            self._watch = gui.add_button(
                "Watch this attempt", icon=viser.Icon.PLAYER_PLAY, visible=False
            )
            # The learner's own player: the same picture, slider and speeds they see.
            self.replay = ReplayStage(gui, ui)
            blank = np.full((8, 8, 3), 255, np.uint8)
            self._plots = [
                gui.add_image(blank, format="png", visible=False) for _ in range(MOST_PLOTS)
            ]
        self._attempt_paths: dict[str, Path] = {}  # the Attempt dropdown's labels
        self._attempt_shown: tuple[str, Path | None] = ("", None)  # (learner, attempt) drawn

        self._learner = gui.add_dropdown("Learner", [NOBODY])
        with gui.add_folder("Message to learners"):
            self._to = gui.add_dropdown("To", [EVERYONE])
            self._text = gui.add_text("Message", "", hint=f"at most {MAX_NOTICE} characters")
            self._send = gui.add_button("Send", icon=viser.Icon.SEND)
            self._sent = MarkdownView(gui)
        with gui.add_folder("Class settings"):
            self._reveal = gui.add_number(
                "Solution after N failed checks (0: each exercise's own)",
                reveal_after or 0,
                min=0,
                max=100,
                step=1,
            )
            self._apply = gui.add_button("Apply to every learner", icon=viser.Icon.CHECK)
            rule = self.routes.rule
            self._stuck_min = gui.add_number(
                "Stuck: minutes without progress while a check fails",
                round(rule.no_progress_sec / 60, 1),
                min=0.1,
                max=240,
                step=0.1,
            )
            self._stuck_fails = gui.add_number(
                "Stuck: failed checks of one exercise", rule.failed_checks, min=1, max=100, step=1
            )
            self._applied = MarkdownView(gui)
        self._learner.on_update(ui.callback(self._show_detail))
        self._attempt_pick.on_update(ui.callback(self._show_attempt))
        self._watch.on_click(ui.callback(self._on_watch))
        self._send.on_click(ui.callback(self._on_send))
        self._apply.on_click(ui.callback(self._on_apply))
        self._stuck_min.on_update(ui.callback(self._on_rule))
        self._stuck_fails.on_update(ui.callback(self._on_rule))

    # -- the UI thread ---------------------------------------------------------------

    def start(self) -> None:
        self._thread.start()

    def _loop(self) -> None:
        next_refresh = 0.0
        while not self._stop.is_set():
            self.ui.wait(FRAME_SEC if self.replay.playing else REFRESH_SEC)
            self.ui.apply_pending()
            try:
                if time.monotonic() >= next_refresh:
                    next_refresh = time.monotonic() + REFRESH_SEC
                    self._refresh()
                self.replay.refresh()
            except Exception:  # keep the page going; the traceback goes to the log
                log.exception("teacher page refresh failed")
            self.server.flush()

    def _refresh(self) -> None:
        records = self.roster.records()
        now = time.time()
        rows = table(records, self.routes.rule, now)
        if rows:
            stuck = sum(1 for row in rows if row[-1])
            self._summary.show(
                f"**{len(rows)} learner{'s' if len(rows) != 1 else ''}**"
                + (f" · **⚠ {stuck} stuck**" if stuck else "")
                + f" · updated {time.strftime('%H:%M:%S')}"
            )
            self._table.show(markdown_table(rows))
            self._exercises.show(exercises_markdown(records))
        keys = sorted(r.key for r in records)
        set_options(self._learner, [NOBODY, *keys])
        set_options(self._to, [EVERYONE, *keys])
        self._show_detail(records)

    def _show_detail(self, records: list[LearnerRecord] | None = None) -> None:
        chosen = self._learner.value
        if chosen == NOBODY:
            self._detail.show("_Choose a learner on the right._")
            self._list_attempts(None)
            return
        by_key = {r.key: r for r in (records or self.roster.records())}
        record = by_key.get(chosen)
        if record is None:
            self._detail.show(f"_{chosen}: no news yet._")
            self._list_attempts(None)
            return
        kept = self.attempts.kept(record) if self.attempts and record.exercise else []
        self._detail.show(learner_detail(record, kept[0] if kept else None))
        self._list_attempts(record, kept)

    # -- the learner's attempts (UI thread) -------------------------------------------

    def _list_attempts(self, record: LearnerRecord | None, kept: list[Path] | None = None) -> None:
        """The Attempt dropdown: the learner's kept attempts of their exercise, newest first,
        labelled as in their own Exercise tab; the teacher's pick stays while it is kept."""
        if record is None:
            note = NO_ATTEMPTS_HERE
        elif self.attempts is None or record.site != self.attempts.site:
            note = (
                f"_{plain_markdown(record.learner)}'s attempts are kept on their own machine "
                f"({plain_markdown(record.site)}): the learner's **Watch this attempt** plays "
                "them there._"
            )
        elif not record.exercise:
            note = f"_{plain_markdown(record.learner)} is on no exercise in this unit._"
        elif not kept:
            note = (
                f"_{plain_markdown(record.learner)} has no graded attempt of "
                f"`{record.exercise}` yet: each **Check my node** keeps one._"
            )
        else:
            note = (
                f"**{plain_markdown(record.learner)}'s attempts at `{record.exercise}`** "
                f"({len(kept)} kept, newest first)"
            )
        self._attempts_note.show(note)
        paths = {attempt_label(path): path for path in (kept or [])}
        if paths != self._attempt_paths:
            self._attempt_paths = paths
            previous = self._attempt_pick.value
            if paths:
                self._attempt_pick.options = list(paths)
                if previous not in paths:  # a new learner, or theirs was pruned: the newest
                    assign(self._attempt_pick, next(iter(paths)))
        self._attempt_pick.visible = self._watch.visible = bool(paths)
        self._attempt_text.handle.visible = bool(paths)
        learner = record.key if record is not None else ""
        if learner != self._attempt_shown[0]:
            self.replay.set_active(False)  # another learner's run is not this one's
        self._show_attempt(learner)

    def _show_attempt(self, learner: str | None = None) -> None:
        """The picked attempt's result lines and plots, read again only when the pick changed."""
        learner = self._attempt_shown[0] if learner is None else learner
        path = self._attempt_paths.get(str(self._attempt_pick.value))
        if (learner, path) == self._attempt_shown:
            return
        self._attempt_shown = (learner, path)
        self._attempt_text.show(attempt_markdown(path) if path is not None else "")
        images = _plot_images(path) if path is not None else []
        for index, handle in enumerate(self._plots):
            if index < len(images):
                handle.image = images[index]
            handle.visible = index < len(images)

    def _on_watch(self) -> None:
        path = self._attempt_paths.get(str(self._attempt_pick.value))
        if path is None:
            return
        learner = plain_markdown(self._attempt_shown[0].rsplit("/", 1)[-1] or "the learner")
        told = attempt_heading(path) or "_Its verdict could not be read: the file is damaged._"
        heading = (
            f"### {learner}'s attempt at {path.parent.name}\n\n"
            f"{plain_markdown(attempt_label(path))}\n\n{told}"
        )
        self.replay.open(path, heading)
        self.replay.set_active(True)

    def _on_send(self) -> None:
        text = self._text.value.strip()
        to = self._to.value
        if not text:
            self._sent.show("⚠ Write a message first.")
            return
        if len(text) > MAX_NOTICE:
            self._sent.show(f"⚠ At most {MAX_NOTICE} characters ({len(text)} now).")
            return
        # The box is emptied before the message leaves, not after: whoever sees it arrive and
        # types the next one at once (ci86's two-host test did, within the loaded UI thread's
        # pause after publishing) must never have the new words wiped by this clear.
        assign(self._text, "")
        try:
            self.roster.send_notice("" if to == EVERYONE else to, text)
        except Exception as error:  # the classroom's DDS closing: the words go back in the box
            log.exception("sending a notice failed")
            assign(self._text, text)
            self._sent.show(
                f"⚠ Not sent ({type(error).__name__}): your message is back in the box."
            )
            return
        self._sent.show(f"Sent to {to} at {time.strftime('%H:%M:%S')}.")

    def _on_apply(self) -> None:
        value = int(self._reveal.value)
        self.roster.set_reveal_after(value)
        what = "each exercise's own number" if value == 0 else f"{value} failed checks"
        self._applied.show(f"Reference solutions now show after {what}.")

    def _on_rule(self) -> None:
        self.routes.rule = StuckRule(
            no_progress_sec=max(6.0, float(self._stuck_min.value) * 60),
            failed_checks=max(1, int(self._stuck_fails.value)),
        )

    def close(self) -> None:
        self._stop.set()
        self.ui.post(lambda: None)
        self._thread.join(timeout=2.0)
        self.replay.close()
        self.ui.close()
        self.server.stop()

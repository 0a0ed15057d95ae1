"""Inside a learner's dashboard: publish where the learner is; show what the teacher says.

Threads, following the dashboard's model (app.ui):

- The beacon's own thread asks the UI thread, once a second, for a
  ``LearnerRecord`` (``ui.post``): lesson position, the step's checks and the
  panels' other state belong to the UI thread, so only it reads them. The
  record comes back through a queue; the beacon thread alone keeps the
  "last activity" stamps and publishes on change, or every
  ``HEARTBEAT_SEC`` so the teacher page can tell a quiet learner from a
  dashboard that is gone.
- Notices and settings arrive on the side participant's executor thread and
  are posted to the UI thread, which shows or applies them.
"""

from __future__ import annotations

import logging
import os
import queue
import threading
import time
from dataclasses import dataclass, replace

from app.exercises import runner
from app.exercises.attempts import attempts_root
from app.exercises.model import Exercise, ExerciseBook
from app.exercises.panel import ExerciseSettings
from app.exercises.workspace import Workspace
from app.lessons.progress import ProgressStore
from app.lessons.runtime import LessonRuntime
from app.lessons.schema import Course
from app.ros.side_participant import SideParticipant
from app.supervisor import Supervisor
from app.teacher import wire
from app.teacher.attempt_files import AttemptReader
from app.teacher.hub_link import HubLink, HubTarget, NoticeSink, ReportRefused, SettingsSink
from app.teacher.record import (
    MAX_CODE,
    MAX_ERROR,
    MAX_MISTAKE,
    LearnerRecord,
    clip,
    plain_markdown,
)
from app.teacher.time_spent import IDLE_AFTER_SEC, TimeSpent, activity_key, file_for
from app.ui import MarkdownView
from app.ui.loop import UiLoop

log = logging.getLogger(__name__)

# How stale the teacher's view of this learner may get. A saved change of progress (a step
# passed, Next, an exercise checked) and a program started or ended are collected at once
# (``collect_on_changes``).
COLLECT_SEC = 1.0
NUDGE_GAP_SEC = 0.2
# How stale "when was this exercise's file last saved" may get: on a lesson without an
# exercise of its own every exercise is a candidate, and a stat of each, each round, was
# half of the beacon's work on the UI thread (issue 43's idle CPU).
SAVED_CHECK_SEC = 5.0
HEARTBEAT_SEC = 10.0


def collect_on_changes(
    progress: ProgressStore, supervisor: Supervisor, due: threading.Event
) -> None:
    """Set ``due`` when progress is saved or a program starts, stops or ends.

    The teacher's row shows both; waiting out the beacon's second made a loaded hub show a
    learner's Next, or a node they started, more than 2 s late.
    """
    progress.on_change(due.set)
    supervisor.on_change(lambda _status: due.set())


@dataclass(frozen=True)
class LearnerSources:
    """What the dashboard knows about its learner (read on the UI thread only)."""

    course: Course
    lessons: LessonRuntime
    book: ExerciseBook
    workspace: Workspace
    supervisor: Supervisor
    settings: ExerciseSettings


class ProgressBeacon:
    """One learner dashboard's link to the teacher, on the classroom domain."""

    def __init__(
        self,
        ui: UiLoop,
        sources: LearnerSources,
        notice_view: MarkdownView,
        *,
        site: str,
        learner: str,
        domain_id: int,
        classroom_domain: int | None = None,
        hub: HubTarget | None = None,
    ) -> None:
        self._ui = ui
        self._sources = sources
        self._notice_view = notice_view
        self._site, self._learner, self._domain_id = site, learner, domain_id
        self._key = f"{site}/{learner}"
        # Each record with when its exercise was last opened, saved or checked.
        self._records: queue.SimpleQueue[tuple[LearnerRecord, float] | None] = queue.SimpleQueue()
        self._stop = threading.Event()
        self._due = threading.Event()  # collect now: something the teacher sees changed
        collect_on_changes(sources.workspace.progress, sources.supervisor, self._due)
        self._crash_key: tuple | None = None  # UI thread: the crash text read once per process
        self._crash_text = ""
        self._saved_at: dict[str, tuple[float, float]] = {}  # UI thread: slug -> (read at, mtime)
        self._attempts = AttemptReader()  # the beacon thread's: the kept attempts' folders
        # The beacon thread's too; kept beside the learner's progress across restarts.
        self._time = TimeSpent(file_for(sources.workspace.progress.path))
        self._link: DdsLink | HubLink
        if hub is not None:  # on a JupyterHub: HTTP to the teacher service
            self._link = HubLink(hub, self._on_notice, self._on_settings)
        elif classroom_domain is not None:  # a LAN class: the classroom domain
            self._link = DdsLink(
                wire.node_name_for(site, learner),
                classroom_domain,
                self._on_notice,
                self._on_settings,
            )
        else:
            raise ValueError("a progress beacon needs a classroom domain or a hub")
        self._thread = threading.Thread(target=self._run, name="progress-beacon", daemon=True)

    def start(self) -> None:
        self._thread.start()

    def close(self) -> None:
        self._stop.set()
        self._due.set()
        self._records.put(None)  # wake the beacon thread now
        self._thread.join(timeout=2.0)
        self._time.save()
        self._link.close()

    # -- the beacon thread --------------------------------------------------------

    def _run(self) -> None:
        last: LearnerRecord | None = None
        activity = progress = time.time()
        acted = 0.0  # the last change the learner made (the start of the dashboard is none)
        sent_at = 0.0
        # At most one collection each NUDGE_GAP_SEC (an editor saving at each pause must not
        # keep the UI thread collecting), and one each COLLECT_SEC at least.
        while not self._stop.wait(NUDGE_GAP_SEC):
            self._due.wait(COLLECT_SEC - NUDGE_GAP_SEC)
            self._due.clear()
            if self._stop.is_set():
                return
            self._ui.post(self._collect, refresh=False)  # reads only: no redraw
            try:
                collected = self._records.get(timeout=COLLECT_SEC * 4)
                while not self._records.empty():  # only the newest counts
                    collected = self._records.get_nowait()
            except queue.Empty:  # the UI thread is busy; try again next round
                continue
            if collected is None:  # closing
                return
            record, exercise_touched = collected
            record = self._with_history(record)
            now = time.time()
            changed = last is None or (
                record.what_changed_ignoring_stamps() != last.what_changed_ignoring_stamps()
            )
            if last is not None and changed:
                activity = acted = now
                if record.position() != last.position():
                    progress = now
            self._time.tick(now, acted, _counted(record, exercise_touched, now))
            if changed or now - sent_at >= self._link.heartbeat_sec:
                stamped = replace(
                    _with_stamps(record, activity, progress), time_spent=self._time.totals()
                )
                try:
                    self._link.send(stamped)
                    sent_at = now
                except ReportRefused as refused:  # it would refuse again: wait a heartbeat
                    sent_at = now
                    log.warning("the teacher service refused this progress report: %s", refused)
                except OSError as error:  # the hub is restarting or unreachable: next round
                    log.warning("could not reach the teacher service: %s", error)
                except Exception:  # shutting down, or a bug: the dashboard keeps going
                    log.exception("publishing progress failed")
            last = record

    def _with_history(self, record: LearnerRecord) -> LearnerRecord:
        """The record with its exercise's newest graded attempts, read off the UI thread."""
        if not record.exercise:
            return record
        try:
            history = self._attempts.newest(attempts_root() / record.exercise)
        except Exception:  # a folder being pruned under us: the next round reads it again
            log.debug("reading the kept attempts failed", exc_info=True)
            return record
        return replace(record, exercise_history=history)

    # -- the UI thread --------------------------------------------------------------

    def _collect(self) -> None:
        try:
            self._records.put(self._snapshot_with_touch())
        except Exception:  # a half-loaded course or a file read error: skip this round
            log.exception("collecting progress failed")

    def _snapshot_with_touch(self) -> tuple[LearnerRecord, float]:
        """The record, and when its exercise was last opened, saved or checked (0: never)."""
        record = self._snapshot()
        if not record.exercise:
            return record, 0.0
        exercise = self._sources.book.get(record.exercise)
        progress = self._sources.workspace.progress.exercise(record.exercise)
        return record, self._touched_at(exercise, progress)

    def _snapshot(self) -> LearnerRecord:
        s = self._sources
        progress = s.workspace.progress
        lessons = s.course.lessons
        lesson = s.course.lesson(progress.current_lesson() or "") or (
            lessons[0] if lessons else None
        )
        fields: dict = {}
        if lesson is not None:
            index = max(0, min(progress.lesson(lesson.id)["step"], len(lesson.steps) - 1))
            step = lesson.steps[index]
            results = [s.lessons.evaluate(check) for check in step.checks]
            fields = dict(
                lesson_id=lesson.id,
                unit=lesson.unit,
                lesson_title=lesson.title,
                step=index + 1,
                steps=len(lesson.steps),
                step_title=step.title,
                check_states=tuple(r.state for r in results),
                check_reasons=tuple(r.reason for r in results),
            )
        records = {e.slug: progress.exercise(e.slug) for e in s.book.exercises}
        exercise = self._current_exercise(lesson.id if lesson else "", records)
        if exercise is not None:
            here = records[exercise.slug]
            fields.update(
                exercise=exercise.slug,
                exercise_attempts_here=here.get("attempts", 0),
                exercise_failed_here=here.get("failed_checks", 0),
                exercise_passed_here="passed_at" in here,
                exercise_passed_seed=int(here.get("passed_seed") or 0),
                exercise_mistake=clip(str(here.get("last_mistake") or ""), MAX_MISTAKE),
                code_excerpt=clip(s.workspace.code(exercise), MAX_CODE),
                last_error=clip(self._last_error(exercise, here), MAX_ERROR),
            )
        return LearnerRecord(
            site=self._site,
            learner=self._learner,
            domain_id=self._domain_id,
            steps_passed=sum(len(progress.lesson(each.id)["passed"]) for each in lessons),
            exercises_passed=sum("passed_at" in r for r in records.values()),
            exercise_attempts=sum(r.get("attempts", 0) for r in records.values()),
            nodes_running=tuple(
                sorted(name for name, st in s.supervisor.statuses().items() if st.active)
            ),
            **fields,
        )

    def _current_exercise(self, lesson_id: str, records: dict[str, dict]) -> Exercise | None:
        """The exercise touched last (code saved or checked); the lesson's own come first."""
        book = self._sources.book
        mine = book.for_lesson(lesson_id)
        candidates = mine or list(book.exercises)
        touched = [(self._touched_at(e, records[e.slug]), e) for e in candidates]
        touched = [(t, e) for t, e in touched if t > 0]
        if touched:
            return max(touched, key=lambda pair: pair[0])[1]
        return mine[0] if mine else None

    def _touched_at(self, exercise: Exercise, record: dict) -> float:
        now = time.monotonic()
        read_at, saved = self._saved_at.get(exercise.slug, (-SAVED_CHECK_SEC, 0.0))
        if now - read_at >= SAVED_CHECK_SEC:
            try:
                saved = os.stat(self._sources.workspace.code_dir / f"{exercise.slug}.py").st_mtime
            except OSError:
                saved = 0.0
            self._saved_at[exercise.slug] = (now, saved)
        return max(saved, record.get("last_checked", 0.0), record.get("first_opened", 0.0))

    def _last_error(self, exercise: Exercise, record: dict) -> str:
        s = self._sources
        status = runner.status(s.supervisor, exercise)
        if status is not None and not status.active:
            key = (exercise.slug, status.pid, status.ended_at)
            if key != self._crash_key:
                script = s.workspace.scratch / f"{exercise.slug}.py"
                crash = runner.crash_of(s.supervisor, exercise, script)
                self._crash_key = key
                self._crash_text = f"{status.describe()}: {crash.describe()}" if crash else ""
            if self._crash_text:
                return self._crash_text
        failed = record.get("failed_checks", 0)
        if failed and "passed_at" not in record:
            return f"{failed} failed check{'s' if failed != 1 else ''}, not passed yet"
        return ""

    # -- the link's thread (DDS executor, or the beacon thread for HTTP) --------------

    def _on_notice(self, to_key: str, text: str, stamp: float) -> None:
        if to_key not in ("", self._key):
            return
        when = time.strftime("%H:%M", time.localtime(stamp))
        to = "to you" if to_key else "to the class"
        shown = f"📣 **Message from your teacher** ({to}, {when}): {plain_markdown(text)}"
        self._ui.post(lambda: self._notice_view.show(shown))

    def _on_settings(self, reveal_solution_after: int) -> None:
        limit = reveal_solution_after or None
        self._ui.post(lambda: _set_reveal_after(self._sources.settings, limit))


class DdsLink:
    """Progress out and the teacher's voice in, on the classroom domain (a LAN class)."""

    heartbeat_sec = HEARTBEAT_SEC  # lets the teacher page tell a quiet learner from a gone one

    def __init__(
        self,
        node_name: str,
        classroom_domain: int,
        on_notice: NoticeSink,
        on_settings: SettingsSink,
    ) -> None:
        self._on_notice_sink, self._on_settings_sink = on_notice, on_settings
        self._side = SideParticipant(node_name, classroom_domain)
        node = self._side.node
        self._publisher = node.create_publisher(
            wire.LearnerProgress, wire.PROGRESS_TOPIC, wire.PROGRESS_PUB_QOS
        )
        node.create_subscription(
            wire.TeacherNotice, wire.NOTICES_TOPIC, self._on_notice, wire.NOTICES_QOS
        )
        node.create_subscription(
            wire.ClassroomSettings, wire.SETTINGS_TOPIC, self._on_settings, wire.SETTINGS_QOS
        )

    def send(self, record: LearnerRecord) -> None:
        self._publisher.publish(wire.to_message(record))

    def close(self) -> None:
        self._side.shutdown()

    def _on_notice(self, msg: wire.TeacherNotice) -> None:
        self._on_notice_sink(msg.to, msg.text, wire.seconds(msg.stamp))

    def _on_settings(self, msg: wire.ClassroomSettings) -> None:
        self._on_settings_sink(msg.reveal_solution_after)


def _counted(record: LearnerRecord, exercise_touched: float, now: float) -> list[str]:
    """The activities whose time this moment counts for: the lesson the dashboard is on,
    and its exercise while the learner works on it (opened, saved or checked lately)."""
    counted = [activity_key("lesson", record.lesson_id)] if record.lesson_id else []
    if record.exercise and now - exercise_touched <= IDLE_AFTER_SEC:
        counted.append(activity_key("exercise", record.exercise))
    return counted


def _with_stamps(record: LearnerRecord, activity: float, progress: float) -> LearnerRecord:
    return replace(record, last_activity=activity, last_progress=progress)


def _set_reveal_after(settings: ExerciseSettings, limit: int | None) -> None:
    """The teacher's number, live; runs on the UI thread, which owns the settings."""
    settings.reveal_after = limit

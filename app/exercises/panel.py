"""Exercise tab: the task, Run / Stop / Check, results, hints, diff, reset, solution.

The code itself is edited in the side window's "Your code" tab (an Ace
editor in an iframe, see ``editor_server``; it also holds the learner's
workspace files in tabs). Run and Check first ask the editor to save, so
they always use what is on screen. Run, Stop and Check
are jobs in one lane: clicks happen in the order made. Check results arrive
one by one, so a learner sees progress during a slow probe.
"""

from __future__ import annotations

import html
import logging
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import viser

from app.bags.folder import bags_dir
from app.containment.policy import RunPolicy
from app.exercises import code_assist, package_grading, plots, runner
from app.exercises.attempt_folders import attempt_heading, attempt_label
from app.exercises.editor_server import EditorHub, editor_url
from app.exercises.explain import panel_line
from app.exercises.grader import Grader
from app.exercises.lint import Problem, lint, refuses_to_run
from app.exercises.mistakes import matched_mistake
from app.exercises.model import Exercise, ExerciseBook
from app.exercises.report import Report, Result
from app.exercises.workspace import Workspace
from app.ros.graph import GraphSnapshot
from app.supervisor import NodeState, NodeStatus, Supervisor
from app.ui import MarkdownView, assign
from app.ui.loop import UiLoop

log = logging.getLogger(__name__)
LOG_LINES = 12
NO_ATTEMPT = "(no attempt kept yet)"
LANE = "exercise"
MOST_PLOTS = 4  # plots shown under the results (a probe's trials; the attempt keeps all)


@dataclass
class ExerciseSettings:
    """What the teacher decides: whether and how code runs, when solutions show.

    ``policy`` is fixed for the dashboard's life. ``reveal_after`` may change
    while it serves (the teacher's page sets it); the UI thread owns it: only
    the UI thread reads or writes it.
    """

    policy: RunPolicy = RunPolicy()
    reveal_after: int | None = None  # None: each exercise's own number


@dataclass(frozen=True)
class CheckOutcome:
    report: Report
    edited_since_run: bool  # the code on screen is not the code that was graded
    plots: list[np.ndarray]  # RGBA pictures of what the probes judged (app/exercises/plots)


@dataclass(frozen=True)
class RunOutcome:
    problems: list[Problem]
    started: bool
    script: Path | None = None


def _label(exercise: Exercise, passed: bool) -> str:
    return f"{exercise.unit:02d} · {exercise.title}" + ("  ✓" if passed else "")


def _problem_lines(problems: list[Problem]) -> str:
    if not problems:
        return ""
    shown = "\n".join(f"- {'✗' if p.fatal else '⚠'} {p.text()}" for p in problems[:12])
    more = f"\n- … and {len(problems) - 12} more" if len(problems) > 12 else ""
    return "**Problems in your code**\n\n" + shown + more


def _result_line(result: Result) -> str:
    mark = "✓" if result.passed else "✗"
    return f"- {mark} **{result.name}**: {result.detail}"


class ExercisePanel:
    calm = True  # once a second while idle (app.ui.Panel): a Check's result wakes the loop
    hidden_work = True  # a grading's results and the program's output keep coming in

    def __init__(
        self,
        gui: viser.GuiApi,
        ui: UiLoop,
        book: ExerciseBook,
        workspace: Workspace,
        supervisor: Supervisor,
        grader: Grader,
        hub: EditorHub,
        side_window: viser.PanelHandle,
        settings: ExerciseSettings | None = None,
        open_code: Callable[[], None] | None = None,
        watch: Callable[[Path, str], None] | None = None,
    ) -> None:
        """``open_code``: put the code window on stage (the editor lives there); ``watch``:
        play a graded attempt's recording on stage, under a heading."""
        self._gui, self._ui, self._book = gui, ui, book
        self._open_code = open_code
        self._watch = watch
        self._attempt_paths: dict[str, Path] = {}  # the Attempt dropdown's labels
        self._workspace, self._supervisor, self._grader = workspace, supervisor, grader
        self._hub, self._settings = hub, settings or ExerciseSettings()
        hub.attach(
            self._load_code,
            self._save_code,
            policy=self._settings.policy,
            scratch=workspace.scratch,
        )
        # Open on the exercise of the lesson the learner is in.
        current = workspace.progress.current_lesson() or ""
        mine = book.for_lesson(current)
        first = mine[0] if mine else (book.exercises[0] if book.exercises else None)
        self._exercise: Exercise | None = first
        self._lesson_seen = current
        if not book.exercises:
            gui.add_markdown("No exercises could be loaded.\n\n" + "\n".join(book.errors))
            return
        self._hints_shown = 0
        self._results: list[Result] = []
        self._verdict = ""
        self._checking = False
        self._problems: list[Problem] = []
        self._message = ""
        self._labels: dict[str, Exercise] = {}
        self._crash_key: tuple[str, int | None, float | None] | None = None
        self._crash_text = ""

        self._selector = gui.add_dropdown("Exercise", self._options())
        # The editor is on the stage's code window; picking an exercise opens it too.
        self._open_code_button = gui.add_button(
            "Open my code", icon=viser.Icon.PENCIL, visible=open_code is not None
        )
        self._header = MarkdownView(gui)
        with gui.add_folder("Task", expand_by_default=True):
            self._statement = MarkdownView(gui)
        self._run = gui.add_button("Run my node", icon=viser.Icon.PLAYER_PLAY, color="green")
        self._stop = gui.add_button("Stop (Ctrl+C)", icon=viser.Icon.PLAYER_STOP, color="gray")
        self._check = gui.add_button("Check my node", icon=viser.Icon.CHECKLIST, color="blue")
        self._status = MarkdownView(gui)
        self._results_view = MarkdownView(gui)
        # Every kept attempt of this exercise, newest first: watch any on stage.
        self._attempt_pick = gui.add_dropdown("Attempt", [NO_ATTEMPT], visible=False)
        self._watch_button = gui.add_button(
            "Watch this attempt", icon=viser.Icon.PLAYER_PLAY, visible=False
        )
        # What the probes judged over time, drawn when a check ends (see app/exercises/plots).
        blank = np.full((8, 8, 4), 255, dtype=np.uint8)
        self._plots = [gui.add_image(blank, format="png", visible=False) for _ in range(MOST_PLOTS)]
        with gui.add_folder("Output of your node", expand_by_default=False):
            self._log = MarkdownView(gui)
        with gui.add_folder("Help", expand_by_default=False):
            self._hint_button = gui.add_button("Show a hint", icon=viser.Icon.BULB)
            self._hints = MarkdownView(gui)
            self._diff_button = gui.add_button("What did I change?", icon=viser.Icon.GIT_COMPARE)
            self._diff = MarkdownView(gui)
            self._reset = gui.add_button("Reset to starter", icon=viser.Icon.RESTORE, color="red")
            self._confirm = gui.add_button("Yes: throw my code away", color="red", visible=False)
            self._cancel = gui.add_button("No, keep my code", visible=False)
            self._solution_button = gui.add_button("Show the reference solution", disabled=True)
            self._solution = MarkdownView(gui)
        with side_window.add_tab("Your code", viser.Icon.PENCIL):
            self._editor = gui.add_html("")

        self._selector.on_update(ui.callback(self._on_pick))
        if open_code is not None:
            self._open_code_button.on_click(ui.callback(open_code))
        self._run.on_click(ui.callback(self._on_run))
        self._stop.on_click(ui.callback(self._on_stop))
        self._check.on_click(ui.callback(self._on_check))
        self._hint_button.on_click(ui.callback(self._on_hint))
        self._diff_button.on_click(ui.callback(self._on_diff))
        self._reset.on_click(ui.callback(self._ask_reset, True))
        self._cancel.on_click(ui.callback(self._ask_reset, False))
        self._confirm.on_click(ui.callback(self._on_reset))
        self._solution_button.on_click(ui.callback(self._on_solution))
        self._watch_button.on_click(ui.callback(self._on_watch))
        if first is not None:
            self._show(first)

    # -- the editor's code source and sink (viser's asyncio thread) -----------

    def _load_code(self, slug: str) -> str:
        return self._workspace.code(self._book.get(slug))

    def _save_code(self, slug: str, code: str) -> None:
        self._workspace.save(self._book.get(slug), code)

    # -- UI thread --------------------------------------------------------------

    def _options(self) -> list[str]:
        self._labels = {_label(e, self._workspace.passed(e)): e for e in self._book.exercises}
        return list(self._labels)

    def open_exercise(self, slug: str) -> bool:
        """Show exercise ``slug`` (a link into the course, such as an LMS's launch); False
        for a slug the book does not have."""
        exercise = next((known for known in self._book.exercises if known.slug == slug), None)
        if exercise is None or self._checking:
            return exercise is not None
        if exercise is not self._exercise:
            self._show(exercise)
        return True

    def _on_pick(self) -> None:
        exercise = self._labels.get(self._selector.value)
        if exercise is not None and exercise is not self._exercise:
            self._show(exercise)
            if self._open_code is not None:
                self._open_code()

    def _show(self, exercise: Exercise) -> None:
        self._exercise = exercise
        self._hints_shown = 0
        self._results, self._verdict, self._problems, self._message = [], "", [], ""
        self._show_plots([])
        self._list_attempts()
        assign(self._selector, next(k for k, e in self._labels.items() if e is exercise))
        self._statement.show(f"{exercise.statement}\n\n*{panel_line(exercise)}*")
        self._hints.show("")
        self._diff.show("")
        self._solution.show("")
        self._editor.content = (
            f'<iframe title="Code editor for {html.escape(exercise.slug)}" '
            f'src="{editor_url(exercise.slug)}" '
            'style="width:100%;height:calc(100vh - 140px);min-height:420px;'
            'border:1px solid #d1d5db;border-radius:4px"></iframe>'
        )

    def _on_run(self) -> None:
        exercise = self._exercise
        if exercise is None:
            return
        if exercise.is_package:
            self._message = package_grading.run_hint(exercise)
            return
        self._message = "Saving and checking your code…"
        self._ui.run_job(lambda: self._run_work(exercise), self._ran, self._failed, lane=LANE)

    def _run_work(self, exercise: Exercise) -> RunOutcome:
        self._hub.flush(exercise.slug)
        code = self._workspace.code(exercise)
        problems = lint(code, f"{exercise.slug}.py")
        self._hub.show_problems(exercise.slug, code_assist.marks(problems))
        if refuses_to_run(problems):
            return RunOutcome(problems, started=False)
        script = self._workspace.script_for_run(exercise)
        runner.start(self._supervisor, exercise, script, self._settings.policy)
        return RunOutcome(problems, started=True, script=script)

    def _ran(self, outcome: RunOutcome) -> None:
        self._problems = outcome.problems
        if outcome.started:
            self._message = "▶ Started your node. Click **Check my node** when it is ready."
        else:
            self._message = "✗ Not started: fix the syntax error first (line shown below)."

    def _failed(self, text: str) -> None:
        self._checking = False
        self._message = f"⚠ {text}"

    def _on_stop(self) -> None:
        exercise = self._exercise
        if exercise is None:
            return
        self._message = "Stopping (Ctrl+C)…"

        def stopped(status: NodeStatus | None) -> None:
            self._message = "■ Stopped." if status else "Your node was not running."

        self._ui.run_job(
            lambda: runner.stop(self._supervisor, exercise), stopped, self._failed, lane=LANE
        )

    def _on_check(self) -> None:
        exercise = self._exercise
        if exercise is None or self._checking:
            return
        self._checking = True
        self._results, self._verdict = [], ""
        self._show_plots([])
        self._message = "Checking… (results appear one by one)"

        def on_result(result: Result) -> None:
            self._ui.post(lambda: self._results.append(result))

        def work() -> CheckOutcome:
            if exercise.is_package:  # the package in the learner's ~/ros2_ws/src, built here
                policy = self._settings.policy
                scratch = self._workspace.scratch
                report = package_grading.grade_learner_package(
                    self._grader, exercise, scratch, policy, on_result
                )
                if not report.problem:
                    self._workspace.record_check(
                        exercise,
                        report.passed,
                        mistake=matched_mistake(exercise, report),
                        seed=report.seed,
                    )
                return CheckOutcome(report, False, _plot_images(report))
            self._hub.flush(exercise.slug)
            script = self._workspace.scratch / f"{exercise.slug}.py"
            report = self._grader.grade(exercise, script, on_result)
            if not report.problem:
                self._workspace.record_check(
                    exercise,
                    report.passed,
                    mistake=matched_mistake(exercise, report),
                    seed=report.seed,
                )
            ran = script.read_text(encoding="utf-8") if script.is_file() else ""
            return CheckOutcome(report, ran != self._workspace.code(exercise), _plot_images(report))

        self._ui.run_job(work, self._checked, self._failed, lane=LANE)

    def _on_watch(self) -> None:
        path = self._attempt_paths.get(str(self._attempt_pick.value))
        exercise = self._exercise
        if path is None or exercise is None or self._watch is None:
            return
        told = attempt_heading(path) or "_Its verdict could not be read._"
        heading = f"### Your attempt at {exercise.title}\n\n{attempt_label(path)}\n\n{told}"
        self._watch(path, heading)

    def _list_attempts(self) -> None:
        """The Attempt dropdown: this exercise's kept attempts, the newest picked."""
        store, exercise = self._grader.attempts, self._exercise
        paths = store.attempts(exercise.slug)[::-1] if store and exercise else []
        self._attempt_paths = {attempt_label(path): path for path in paths}
        shown = bool(self._attempt_paths) and self._watch is not None
        if shown:
            self._attempt_pick.options = list(self._attempt_paths)
            assign(self._attempt_pick, next(iter(self._attempt_paths)))
        self._attempt_pick.visible = self._watch_button.visible = shown

    def _show_plots(self, images: list[np.ndarray]) -> None:
        for index, handle in enumerate(self._plots):
            if index < len(images):
                handle.image = images[index]
            handle.visible = index < len(images)

    def _checked(self, outcome: CheckOutcome) -> None:
        report, edited_since_run = outcome.report, outcome.edited_since_run
        self._show_plots(outcome.plots)
        self._list_attempts()
        self._checking = False
        self._results = list(report.results)
        exercise = self._exercise
        if report.problem:
            self._verdict = f"✗ {report.problem}"
        elif report.passed:
            self._verdict = "✓ **All checks pass. Exercise done!**"
        else:
            self._verdict = (
                f"**{report.summary()}** Read the ✗ lines, change your code, Run, Check."
            )
        self._verdict += attempt_line(report)
        self._message = (
            "⚠ You changed the code after Run: these results are for the code that runs. "
            "Click **Run my node** again to check your edits."
            if edited_since_run and not report.problem
            else ""
        )
        if exercise is not None:
            self._selector.options = self._options()
            assign(self._selector, next(k for k, e in self._labels.items() if e is exercise))

    def _on_hint(self) -> None:
        exercise = self._exercise
        if exercise is None:
            return
        self._hints_shown = min(self._hints_shown + 1, len(exercise.hints))
        shown = exercise.hints[: self._hints_shown]
        more = len(exercise.hints) - len(shown)
        tail = f"\n\n_{more} more hint{'s' if more > 1 else ''}._" if more else ""
        self._hints.show("\n".join(f"{i}. {hint}" for i, hint in enumerate(shown, 1)) + tail)

    def _on_diff(self) -> None:
        exercise = self._exercise
        if exercise is None:
            return

        def done(diff: str) -> None:
            self._diff.show(f"```diff\n{diff}\n```" if diff else "_No changes yet._")

        def work() -> str:
            self._hub.flush(exercise.slug)
            return self._workspace.diff(exercise)

        self._ui.run_job(work, done, self._failed, lane=LANE)

    def _ask_reset(self, asking: bool) -> None:
        self._confirm.visible = asking
        self._cancel.visible = asking
        self._reset.visible = not asking

    def _on_reset(self) -> None:
        exercise = self._exercise
        self._ask_reset(False)
        if exercise is None:
            return

        def work() -> None:
            starter = self._workspace.reset(exercise)
            self._hub.push_code(exercise.slug, starter, note="reset to the starter code")

        def done(_none: None) -> None:
            self._message = "Your code is back to the starter code."
            self._diff.show("")

        self._ui.run_job(work, done, self._failed, lane=LANE)

    def _on_solution(self) -> None:
        exercise = self._exercise
        if exercise is None or not self._may_see_solution(exercise):
            return
        self._solution.show(f"```python\n{exercise.reference}\n```")

    def _may_see_solution(self, exercise: Exercise) -> bool:
        return self._workspace.may_see_solution(exercise, self._settings.reveal_after)

    # -- refresh ----------------------------------------------------------------

    def follow_the_lesson(self) -> None:
        """When the learner moves to another unit, its exercise is the one shown: told by
        the dashboard as the lesson opens (so a pick made just after the learner's Next is
        not undone by a later refresh), and checked at each refresh (after a check that was
        running then)."""
        if self._exercise is None:  # no exercise could be loaded: nothing to follow with
            return
        current = self._workspace.progress.current_lesson() or ""
        if current == self._lesson_seen or self._checking:
            return
        self._lesson_seen = current
        exercises = self._book.for_lesson(current)
        if exercises and self._exercise not in exercises:
            self._show(exercises[0])

    def refresh(self, graph: GraphSnapshot) -> None:
        if self._exercise is None:
            return
        self.follow_the_lesson()
        exercise = self._exercise
        record = self._workspace.progress.exercise(exercise.slug)
        passed = "passed_at" in record
        attempts = record.get("attempts", 0)
        self._header.show(
            f"### {exercise.title}\nLesson {exercise.unit} · your node: `{exercise.node}` · "
            + ("✓ **done**" if passed else f"{attempts} check{'s' if attempts != 1 else ''} so far")
        )
        status = runner.status(self._supervisor, exercise)
        state = status.describe() if status else "not started"
        on_graph = " · on the graph ✓" if graph.has_node(exercise.node) else ""
        lines = runner.output(self._supervisor, exercise, LOG_LINES)
        parts = [f"**Your node:** {state}{on_graph}"]
        if self._message:
            parts.append(self._message)
        if status is not None and not status.active:
            crash = self._crash_of(exercise, status)
            if crash:
                # Ctrl+C with an uncaught KeyboardInterrupt/ExternalShutdownException is a stop.
                how = "It stopped" if status.state == NodeState.STOPPED else "It crashed"
                parts.append(f"**{how}:**\n```\n{crash}\n```")
        problems = _problem_lines(self._problems)
        if problems:
            parts.append(problems)
        self._status.show("\n\n".join(parts))
        results = "\n".join(_result_line(r) for r in self._results)
        if self._checking:
            results = f"**Checking…** {len(self._results)} done so far\n\n" + results
        self._results_view.show("\n\n".join(p for p in (self._verdict, results) if p))
        self._log.show(f"```\n{chr(10).join(lines) or '(no output yet)'}\n```")
        allowed = self._may_see_solution(exercise)
        self._solution_button.disabled = not allowed
        limit = self._settings.reveal_after or exercise.reveal_after
        self._solution_button.label = (
            "Show the reference solution"
            if allowed
            else f"Reference solution: after passing or {limit} failed checks"
        )
        self._run.disabled = self._check.disabled = self._checking

    def _crash_of(self, exercise: Exercise, status: NodeStatus) -> str:
        """The ended process's traceback, read once per process (not at every refresh)."""
        key = (exercise.slug, status.pid, status.ended_at)
        if key != self._crash_key:
            script = self._workspace.scratch / f"{exercise.slug}.py"
            crash = runner.crash_of(self._supervisor, exercise, script)
            self._crash_key, self._crash_text = key, crash.describe() if crash else ""
        return self._crash_text

    def close(self) -> None:
        """The learner's process belongs to the supervisor, which stops it on shutdown."""


def _plot_images(report: Report) -> list[np.ndarray]:
    """The first traces' plots, drawn on the grading's thread (a plot takes ~0.1 s)."""
    shown = []
    for trace in report.traces()[:MOST_PLOTS]:
        try:
            shown.append(plots.pixels(trace))
        except Exception:  # a plot that cannot be drawn never hides the verdict
            log.exception("could not draw the plot %r", trace.title)
    return shown


def attempt_line(report: Report) -> str:
    """Where this grading's recording went, as the Console's `ros2 bag` commands take it."""
    if report.attempt_note:
        return f"\n\n_{report.attempt_note}_"
    if not report.attempt:
        return ""
    name = Path(report.attempt)
    try:
        name = name.relative_to(bags_dir())
    except ValueError:
        pass
    return (
        "\n\nThis attempt was recorded: in the Console, `ros2 bag info "
        f"{name}` lists what the grader sent and your node answered, and `ros2 bag play "
        f"{name}` replays it (an MCAP file: Foxglove opens it too)."
    )

"""Lessons tab: course outline, the current step, its buttons, live checks, Back/Next.

Step buttons run ``LessonRuntime.perform`` as jobs in one lane, so two quick
clicks happen in the order made; everything else runs on the UI thread.
"""

from __future__ import annotations

import base64
import html
import re
from collections import Counter
from collections.abc import Callable
from contextlib import AbstractContextManager, nullcontext
from functools import lru_cache
from typing import Final

import viser

from app.catalog import UnknownNodeError, lookup_group
from app.lessons import step_code
from app.lessons.checks.quiz import answer_order
from app.lessons.progress import ProgressStore
from app.lessons.registry import CheckResult
from app.lessons.runtime import FAIL, PASS, WAITING, LessonRuntime
from app.lessons.schema import IMAGE_TYPES, STATIC_DIR, Course, Lesson, Spec
from app.ros.graph import GraphSnapshot
from app.supervisor import OWN_PROGRAM, NodeStatus, own_program_key
from app.ui import MarkdownView, assign
from app.ui.loop import UiLoop
from app.ui.starting import StartRequests

# How a check reads on the card. Not passed yet is "to do", not "fail": most steps open
# with their checks unmet, and a learner who has not acted yet has failed nothing.
_MARKS = {PASS: "✓", FAIL: "○", WAITING: "…"}
_WORDS = {PASS: "pass", FAIL: "to do", WAITING: "waiting"}
# A step button's icon says what it does; the label says it in words.
_ACTION_ICONS = {
    "open_panel": viser.Icon.EXTERNAL_LINK,
    "stop": viser.Icon.PLAYER_STOP,
    "stop_group": viser.Icon.PLAYER_STOP,
    "stop_own": viser.Icon.PLAYER_STOP,
    "console": viser.Icon.TERMINAL,
    "workspace_command": viser.Icon.TERMINAL,
    "workspace_edit": viser.Icon.PENCIL,
    "workspace_write": viser.Icon.PENCIL,
    "call_service": viser.Icon.SEND,
    "send_goal": viser.Icon.SEND,
    "publish": viser.Icon.SEND,
    "set_param": viser.Icon.ADJUSTMENTS,
}
_ANSWER_COLOUR: Final = "gray"
_CHOSEN_COLOUR: Final = "blue"


def action_button_label(action: Spec) -> str:
    """A step action's button: its own label, or its kind in words."""
    return str(action.get("label") or action.kind.replace("_", " "))


def answer_button_label(option: str, chosen: bool) -> str:
    """A quiz answer's button: a radio mark, then the answer's whole text."""
    return f"{'●' if chosen else '○'} {option}"


# How the screen works, said once, on the first step of the course.
FIRST_SCREEN = (
    "_New here?_ The **stage** on the left shows what the current step is about. The "
    "**step card** below explains the step, then gives its buttons and live checks (✓ "
    "when done); the tools are in the tabs under it."
)


_SECTION = re.compile(r"^#{1,6} (.+?)\s*#*\s*$")  # a Markdown heading line


def _without_title(markdown: str) -> str:
    """Drop a leading '# Title' line: the step title is already shown above. A section
    heading inside ('## Try it') is drawn in bold: as a heading it came out larger than the
    step's own title (code blocks, whose '#' lines are comments, are left as they are)."""
    first, _, rest = markdown.lstrip().partition("\n")
    body = rest.lstrip() if first.startswith("# ") else markdown
    lines, in_code = [], False
    for line in body.split("\n"):
        if line.lstrip().startswith("```"):
            in_code = not in_code
        heading = _SECTION.match(line)
        lines.append(f"**{heading.group(1)}**" if heading and not in_code else line)
    return "\n".join(lines)


@lru_cache(maxsize=32)
def picture_html(image: str, alt: str) -> str:
    """A diagram from static/ as an <img> with its alt text, inlined as a data URI.

    viser's image widget takes pixel arrays; an HTML widget shows the SVG
    itself, sharp at any panel width.
    """
    path = STATIC_DIR / image
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    mime = IMAGE_TYPES[path.suffix.lower()]
    # Nearly the panel's full width (it keeps clear of the scroll bar): the
    # diagrams' smallest text stays about 12 px in the side panel. On a wide stage
    # the window's height is the bound: the whole diagram in view, its shape kept.
    return (
        '<div style="padding:2px 10px 10px 4px">'
        f'<img src="data:{mime};base64,{data}" alt="{html.escape(alt, quote=True)}" '
        'style="display:block;width:100%;height:auto;max-height:calc(100vh - 120px);'
        'object-fit:contain"></div>'
    )


class _HtmlView:
    """An HTML handle re-sent only when its content changes, hidden while empty."""

    def __init__(self, gui: viser.GuiApi) -> None:
        self._content = ""
        self.handle = gui.add_html("", visible=False)

    def show(self, content: str) -> None:
        if content != self._content:
            self._content = content
            self.handle.content = content
            self.handle.visible = bool(content)

    @property
    def content(self) -> str:
        return self._content


def _started_by(action: Spec) -> list[str]:
    """The catalog nodes a step button starts (the stage draws them at the click)."""
    if action.kind == "start":
        return [action["catalog_node"]]
    if action.kind == "start_group":
        try:
            return list(lookup_group(action["group"]).members)
        except UnknownNodeError:
            return []
    return []


def _stopped_by(action: Spec) -> list[str]:
    """The supervisor's names of what a step's Stop button stops ([]: not a Stop)."""
    if action.kind == "stop":
        return [action["catalog_node"]]
    if action.kind == "stop_group":
        try:
            return list(lookup_group(action["group"]).members)
        except UnknownNodeError:
            return []
    if action.kind == "stop_own":  # app.ros2cli.pkg's program key
        return [own_program_key(action["package"], action["executable"])]
    return []


COURSE_END = "End of the course"
# Every label Next takes but the course's end (browser tests and docs/screenshots.py find
# the button by it).
NEXT_LABEL = re.compile(r"^(Next|Next lesson: .+|Skip \(\d+ checks? not passed\))$")


def check_lines(results: list[CheckResult]) -> list[str]:
    """The step's check lines: what is left to do first, a line per check, except that
    checks waiting on the same thing (four frames, one missing /tf) share one line that
    says how many they are."""
    ordered = sorted(results, key=lambda result: result.state == PASS)
    counts = Counter((result.state, result.reason) for result in ordered)
    lines = []
    for state, reason in counts:  # in the order first seen
        many = f" ({counts[state, reason]} checks)" if counts[state, reason] > 1 else ""
        lines.append(f"- {_MARKS[state]} **{_WORDS[state]}**{many}: {reason}")
    return lines


def _next_label(not_passed: int, following: Lesson | None, last_step: bool) -> str:
    """Next's label: it moves on either way, but says when that skips checks; on a
    lesson's last step it names the lesson it opens, on the course's last it ends."""
    if last_step and following is None:
        return COURSE_END
    if not_passed:
        return f"Skip ({not_passed} check{'s' if not_passed > 1 else ''} not passed)"
    return f"Next lesson: {_label(following)}" if last_step and following else "Next"


def quiz_label(index: int, count: int) -> str:
    """'Question', or 'Question 2' when a step asks several."""
    return "Question" if count == 1 else f"Question {index + 1}"


def _label(lesson: Lesson) -> str:
    return f"{lesson.unit:02d} · {lesson.title}"


class LessonsPanel:
    calm = True  # once a second while idle (app.ui.Panel): checks; a step's button wakes the loop
    hidden_work = True  # the step card above the tools shows its checks whichever tool is open

    def __init__(
        self,
        gui: viser.GuiApi,
        ui: UiLoop,
        course: Course,
        live: LessonRuntime,
        progress: ProgressStore,
        side_window: viser.PanelHandle,
        exercise_marks: Callable[[str], str] = lambda _lesson_id: "",
        show_stage: Callable[[str, str], None] = lambda _stage, _picture: None,
        *,
        step_card: viser.GuiFolderHandle | None = None,
        open_tool: Callable[[str], None] = lambda _tool: None,
        start_requests: StartRequests | None = None,
        new_lesson: Callable[[frozenset[str]], None] = lambda _programs: None,
        position: MarkdownView | None = None,
        to_top: Callable[[], None] = lambda: None,
        atomic: Callable[[], AbstractContextManager[object]] = nullcontext,
    ) -> None:
        """``step_card``: a folder for the step's title, buttons, checks and Back/Next (the
        dashboard puts it above its tools, so they stay in view); made here when None.
        ``open_tool(name)`` brings a tool's tab into view (a step's `open_panel` button).
        ``new_lesson(programs)``: another lesson was opened, whose buttons start ``programs``
        (the dashboard clears what the last one left in the views). ``position``: where the
        "Lesson i of n · Step j of m" line goes (the dashboard puts it above the step card);
        made in the card when None.
        ``to_top()``: the column back to its top, where a new step's text begins.
        ``atomic()``: the server's ``atomic``, so a page draws a step's switch at once."""
        self._gui = gui
        self._ui = ui
        self._course = course
        self._live = live
        self._progress = progress
        self._exercise_marks = exercise_marks
        self._show_stage = show_stage  # the stage shows what each step names (and its picture)
        self._open_tool = open_tool
        self._to_top = to_top
        self._atomic = atomic
        self._requests = start_requests or StartRequests()  # the stage shows a Start at once
        self._new_lesson = new_lesson
        self._leftovers: list[str] = []  # nodes running when this lesson was opened
        self._stop_buttons: list[tuple[viser.GuiButtonHandle, list[str]]] = []  # (button, stops)
        self._dynamic: list[viser.GuiButtonHandle | viser.GuiMarkdownHandle] = []
        by_label = {_label(lesson): lesson for lesson in course.lessons}
        self._by_label = by_label
        if not course.lessons:
            gui.add_markdown("No lessons could be loaded.\n\n" + "\n".join(course.errors))
            return
        current = course.lesson(progress.current_lesson() or "") or course.lessons[0]
        # The Lessons tab: which lesson, its title and summary, its goals, the outline.
        self._selector = gui.add_dropdown("Lesson", list(by_label), initial_value=_label(current))
        self._header = MarkdownView(gui)
        with gui.add_folder("Goals of this lesson", expand_by_default=False):
            self._goals = MarkdownView(gui)
        with gui.add_folder("Course outline", expand_by_default=False):
            self._outline = MarkdownView(gui)
            self._reset = gui.add_button("Reset my progress", color="gray")
        # The step card reads top to bottom: the step's text (and picture, and the terminal
        # command), then what to do (buttons, questions), its checks, then Back and Next.
        self._card = step_card if step_card is not None else gui.add_folder("This step")
        with self._card:
            # Where am I: lesson i of n, step j of m.
            self._position = position if position is not None else MarkdownView(gui)
            self._stop_leftovers = gui.add_button(
                "", icon=viser.Icon.PLAYER_STOP, color="red", visible=False
            )
            self._text = MarkdownView(gui)
            self._picture = _HtmlView(gui)
            self._command = MarkdownView(gui)
            self._actions = gui.add_folder(None)  # the step's own buttons, rebuilt per step
            self._checks = MarkdownView(gui)
            self._message = MarkdownView(gui)
            # Back, Next and the Stops look different: gray goes back, blue goes on
            # (orange while it would skip checks), red stops.
            self._back = gui.add_button("Back", icon=viser.Icon.ARROW_LEFT, color="gray")
            self._next = gui.add_button("Next", icon=viser.Icon.ARROW_RIGHT, color="blue")
        # The code the lesson talks about sits beside the text, in the side
        # window docked on the left (the learner can minimise or move it).
        with side_window.add_tab("Code of this lesson", viser.Icon.CODE):
            self._code = _HtmlView(gui)
        self._lesson = current
        self._step = min(progress.lesson(current.id)["step"], len(current.steps) - 1)
        self._selector.on_update(ui.callback(self._on_lesson_picked))
        self._back.on_click(ui.callback(lambda: self._select(self._lesson, self._step - 1)))
        self._next.on_click(ui.callback(self._go_next))
        self._reset.on_click(ui.callback(self._do_reset))
        self._stop_leftovers.on_click(ui.callback(self._stop_left_over))
        self._select(current, self._step, reading=False)

    # -- navigation --------------------------------------------------------

    def _on_lesson_picked(self) -> None:
        lesson = self._by_label.get(self._selector.value)  # a forged value is ignored
        if lesson is not None and lesson is not self._lesson:
            self._select(lesson, 0)

    def open_lesson(self, lesson_id: str) -> bool:
        """Open lesson ``lesson_id`` at its first step (a link into the course, such as an
        LMS's launch); False for an id the course does not have."""
        lesson = next((known for known in self._course.lessons if known.id == lesson_id), None)
        if lesson is None:
            return False
        if lesson is not self._lesson:
            assign(self._selector, _label(lesson))
            self._select(lesson, 0)
        return True

    def _following(self, lesson: Lesson) -> Lesson | None:
        """The lesson after ``lesson`` in the course, None after the last."""
        index = self._course.lessons.index(lesson)
        return self._course.lessons[index + 1] if index + 1 < len(self._course.lessons) else None

    def _go_next(self) -> None:
        if self._step + 1 < len(self._lesson.steps):
            self._select(self._lesson, self._step + 1)
            return
        following = self._following(self._lesson)
        if following is not None:
            assign(self._selector, _label(following))
            self._select(following, 0)

    def _do_reset(self) -> None:
        self._progress.reset()
        self._message.show("Progress reset.")
        self._select(self._lesson, 0)

    def _select(self, lesson: Lesson, step: int, reading: bool = True) -> None:
        """Show ``step`` of ``lesson``; ``reading``: bring its text into view (a new step is
        read first; the tool the learner has open stays open under the card).

        In one atomic group: a page given the new title before the new buttons drew the
        card with none, Next moved up and back down, and a click on it was lost (ci127)."""
        with self._atomic():
            self._show_step(lesson, step, reading)

    def _show_step(self, lesson: Lesson, step: int, reading: bool) -> None:
        step = max(0, min(step, len(lesson.steps) - 1))
        opened = lesson is not self._lesson
        if opened:  # a lesson starts clean: nothing of the last one
            self._leftovers = sorted(
                name for name, status in self._statuses().items() if status.active
            )
        self._lesson, self._step = lesson, step
        self._progress.set_position(lesson.id, step)
        if opened:  # told after the position is saved: the Exercise tool reads it
            self._new_lesson(lesson.programs)
        current = lesson.steps[step]
        self._card.label = f"Step {step + 1} of {len(lesson.steps)}: {current.title}"
        number = self._course.lessons.index(lesson) + 1
        where = (
            f"**Lesson {number} of {len(self._course.lessons)} · Step {step + 1} of "
            f"{len(lesson.steps)}** · {lesson.title}"
        )
        self._position.show(f"{FIRST_SCREEN}\n\n{where}" if (number, step) == (1, 0) else where)
        self._header.show(f"### {lesson.title}\n{lesson.summary}")
        self._goals.show("\n".join(f"- {goal}" for goal in lesson.goals))
        self._text.show(_without_title(current.text))
        stage = current.stage or lesson.stage
        picture = picture_html(current.image, current.image_alt) if current.image else ""
        # A diagram on stage is not shown again, smaller, in the step's text.
        self._picture.show("" if stage == "picture" else picture)
        self._command.show(f"In a terminal: `{current.command}`" if current.command else "")
        self._code.show(step_code.listing(lesson, current))
        self._show_stage(stage, picture)
        self._message.show("")
        self._rebuild_step_widgets()
        self._back.disabled = step == 0
        if reading:
            self._to_top()

    def _rebuild_step_widgets(self) -> None:
        for handle in self._dynamic:
            handle.remove()
        self._dynamic = []
        self._stop_buttons = []
        step = self._lesson.steps[self._step]
        statuses = self._statuses()
        with self._actions:
            for action in step.actions:
                label = action_button_label(action)
                icon = _ACTION_ICONS.get(action.kind, viser.Icon.PLAYER_PLAY)
                stops = _stopped_by(action)
                button = self._gui.add_button(
                    label,
                    icon=icon,
                    color="red" if stops else None,
                    disabled=bool(stops) and not _any_active(statuses, stops),
                )
                button.on_click(self._ui.callback(self._perform, action))
                self._dynamic.append(button)
                if stops:
                    self._stop_buttons.append((button, stops))
            quizzes = [check for check in step.checks if check.kind == "quiz"]
            for index, check in enumerate(quizzes):
                # The question at full width (a field's label column is ~80 px: a question
                # there ran to 11 lines), then each answer as a button with its whole text
                # (in a dropdown the chosen answer was cut off, and its open list covered
                # the checks): one choice at a time, as radio buttons.
                label = quiz_label(index, len(quizzes))
                question = self._gui.add_markdown(f"**{label}:** {check['question']}")
                self._dynamic.append(question)
                chosen = self._live.quiz_answers.get(check.key)
                answers = []
                for option in answer_order(check):
                    answer = self._gui.add_button(
                        answer_button_label(option, option == chosen),
                        color=_CHOSEN_COLOUR if option == chosen else _ANSWER_COLOUR,
                    )
                    answers.append((option, answer))
                    self._dynamic.append(answer)
                for option, answer in answers:
                    answer.on_click(self._ui.callback(self._answer, check, option, answers))
            if not self._dynamic:
                self._dynamic.append(self._gui.add_markdown("_Nothing to click: read on._"))

    def _perform(self, action: Spec) -> None:
        if action.kind == "open_panel":  # at once, on this thread: the page opens the tab
            self._open_tool(action["panel"])
        starting = _started_by(action)
        for name in starting:
            self._requests.asked(name)

        def failed(text: str) -> None:
            for name in starting:
                self._requests.done(name)
            self._message.show(f"⚠ {text}")

        self._ui.run_job(
            lambda: self._live.perform(action), self._message.show, failed, lane="lessons"
        )

    def _statuses(self) -> dict[str, NodeStatus]:
        supervisor = getattr(self._live, "supervisor", None)  # (a runtime without processes)
        return supervisor.statuses() if supervisor is not None else {}

    def _stop_left_over(self) -> None:
        names = self._leftovers
        self._leftovers = []
        for name in names:
            self._live.supervisor.stop(name)  # returns at once; the process ends on its own
        self._message.show(f"Stopping {', '.join(_ros_names(self._live, names))}.")

    def _answer(
        self, check: Spec, chosen: str, answers: list[tuple[str, viser.GuiButtonHandle]]
    ) -> None:
        self._live.quiz_answers[check.key] = chosen
        for option, answer in answers:
            picked = option == chosen
            answer.label = answer_button_label(option, picked)
            answer.color = _CHOSEN_COLOUR if picked else _ANSWER_COLOUR

    # -- live part ---------------------------------------------------------

    def refresh(self, graph: GraphSnapshot) -> None:
        if not self._course.lessons:
            return
        lesson, index = self._lesson, self._step
        step = lesson.steps[index]
        results = [(check, self._live.evaluate(check)) for check in step.checks]
        if results and all(result.state == PASS for _, result in results):
            self._progress.mark_passed(lesson.id, index)
        lines = check_lines([result for _, result in results])
        passed = set(self._progress.lesson(lesson.id)["passed"])
        status = "✓ step done" if index in passed else ""
        not_passed = sum(result.state != PASS for _, result in results)
        last_step = index + 1 == len(lesson.steps)
        label = _next_label(not_passed, self._following(lesson), last_step)
        if self._next.label != label:
            self._next.label = label
            self._next.color = "orange" if not_passed and label != COURSE_END else "blue"
            self._next.disabled = label == COURSE_END
        self._show_stops()
        self._checks.show(("**Checks** " + status + "\n\n" + "\n".join(lines)) if lines else status)
        if step_code.workspace_sources(step):  # a button or the Console may have changed it
            self._code.show(step_code.listing(lesson, step))
        self._outline.show(self._outline_text(lesson))

    def _show_stops(self) -> None:
        """A Stop with nothing to stop is greyed; nodes an earlier lesson left are named."""
        statuses = self._statuses()
        for button, names in self._stop_buttons:
            idle = not _any_active(statuses, names)
            if button.disabled != idle:
                button.disabled = idle
        self._leftovers = [n for n in self._leftovers if _any_active(statuses, [n])]
        shown = bool(self._leftovers)
        if shown:
            names = _ros_names(self._live, self._leftovers)
            count = len(names)
            label = (
                f"Stop {count} node{'s' if count > 1 else ''} left from earlier lessons: "
                + ", ".join(names)
            )
            if self._stop_leftovers.label != label:
                self._stop_leftovers.label = label
        if self._stop_leftovers.visible != shown:
            self._stop_leftovers.visible = shown

    def _outline_text(self, current: Lesson) -> str:
        rows = []
        for lesson in self._course.lessons:
            passed = len(self._progress.lesson(lesson.id)["passed"])
            total = len(lesson.steps)
            mark = "✓" if passed >= total else f"{passed}/{total}"
            title = f"**{lesson.title}**" if lesson is current else lesson.title
            exercise = self._exercise_marks(lesson.id) or "–"
            rows.append(f"| {lesson.unit} | {title} | {mark} | {exercise} |")
        warning = f"⚠ {self._progress.warning}\n\n" if self._progress.warning else ""
        errors = "".join(f"\n\n⚠ {error}" for error in self._course.errors)
        return (
            warning
            + "| unit | lesson | done | exercise |\n|---|---|---|---|\n"
            + "\n".join(rows)
            + errors
        )

    def close(self) -> None:
        """The dashboard owns the lesson runtime and closes it; nothing else is held."""


def _any_active(statuses: dict[str, NodeStatus], names: list[str]) -> bool:
    return any(status.active for name in names if (status := statuses.get(name)) is not None)


def _ros_names(live: LessonRuntime, names: list[str]) -> list[str]:
    """The supervisor's names as the ROS graph calls those nodes (/talker, /num_publisher).

    A program of the learner's own workspace is named as it was started ("py_pubsub
    talker, your program"): its node's name is in the learner's code, not known here
    (its key's "/py_pubsub/talker" read as a node the graph did not show).
    """
    shown = []
    for name in names:
        if name.startswith(OWN_PROGRAM):
            shown.append(" ".join(name.removeprefix(OWN_PROGRAM).split("/")) + ", your program")
            continue
        program = live.supervisor.program(name)
        shown.append(program.node_name if program is not None else name)
    return shown

"""The few HTML pages LTI shows a person: a refusal, the activity picker, the gradebook.

Server-rendered and self-contained (no outside file; script only for the
picker's one line, the gradebook's local times and filter, and the attempt
history's Copy buttons), since they open inside an LMS frame or a new tab
before any of our other pages. Every value from a request or an LMS is escaped.
"""

from __future__ import annotations

import html
import shlex
from collections.abc import Sequence
from datetime import datetime, timezone
from urllib.parse import urlencode

from app.lti.deep_linking import Activity
from app.lti.gradebook import GradebookLine, counts
from app.lti.history import Attempt, AttemptSource

_STYLE = (
    "body{font-family:system-ui,sans-serif;margin:1.5em;max-width:52em;line-height:1.4}"
    "table{border-collapse:collapse}td,th{padding:.3em .6em;text-align:left;"
    "border-bottom:1px solid #ddd}.why{background:#fff4e5;border-left:4px solid #d97706;"
    "padding:.6em 1em}input[type=number]{width:5em}"
    ".hub{color:#666;font-size:.85em}.sent{color:#166534}.refused{color:#b91c1c}"
)


def _page(title: str, body: str) -> str:
    return (
        "<!DOCTYPE html>\n"
        '<html lang="en"><head><meta charset="utf-8">'
        '<meta name="viewport" content="width=device-width,initial-scale=1">'
        f"<title>{html.escape(title)}</title><style>{_STYLE}</style></head>\n"
        f"<body>\n{body}\n</body></html>\n"
    )


def refusal_page(sentence: str, *, what: str = "This launch from your course") -> str:
    """What a refused login or launch shows: the reason, and what to do next."""
    return _page(
        "Launch refused: ROS 2 Classroom",
        f"<h1>{html.escape(what)} was refused</h1>\n"
        f'<p class="why">{html.escape(sentence)}</p>\n'
        "<p>Open the activity again from your course page. If this page comes back, "
        "show it to your teacher: the reason above is also in the service's log.</p>",
    )


def picker_page(
    activities: Sequence[Activity],
    *,
    action: str,
    token: str,
    multiple: bool,
) -> str:
    """The deep-linking picker: lessons and exercises with their points, posted to ``action``."""
    kind = "checkbox" if multiple else "radio"
    rows = []
    for activity in activities:
        value = html.escape(f"{activity.kind}:{activity.slug}", quote=True)
        rows.append(
            "<tr>"
            f'<td><input type="{kind}" name="pick" value="{value}" id="pick-{value}"></td>'
            f'<td><label for="pick-{value}">{html.escape(activity.title)}</label></td>'
            f"<td>{html.escape(activity.kind)}</td>"
            f'<td><input type="number" name="points-{value}" min="0.5" max="1000" step="0.5" '
            f'value="{activity.score_maximum:g}" aria-label="points for '
            f'{html.escape(activity.title, quote=True)}"></td>'
            "</tr>"
        )
    how = "one or more" if multiple else "one"
    return _page(
        "Pick an activity: ROS 2 Classroom",
        "<h1>Add a ROS 2 Classroom activity</h1>\n"
        f"<p>Pick {how} of the lessons or exercises below and the points each is worth. "
        "A lesson counts as done when its last step's checks pass; an exercise when "
        "it passes grading. The grade goes to the LMS by itself.</p>\n"
        f'<form method="post" action="{html.escape(action, quote=True)}">\n'
        f'<input type="hidden" name="token" value="{html.escape(token, quote=True)}">\n'
        "<table><thead><tr><th></th><th>Activity</th><th>Kind</th><th>Points</th></tr>"
        f"</thead><tbody>\n{chr(10).join(rows)}\n</tbody></table>\n"
        '<p><button type="submit">Add to the course</button></p>\n</form>',
    )


_STATE_MARKS = {
    "sent": "✓ sent",
    "waiting": "… waiting",
    "refused": "✗ refused",
    "not done": "not done yet",
    "no grade column": "no grade column",
}


def _time(stamp: float | str | None) -> str:
    """A time the page's script shows in the teacher's own zone (UTC without script)."""
    if not stamp:
        return ""
    when = (
        datetime.fromtimestamp(stamp, timezone.utc)
        if isinstance(stamp, (int, float))
        else datetime.fromisoformat(stamp.replace("Z", "+00:00")).astimezone(timezone.utc)
    )
    iso = when.isoformat(timespec="seconds")
    return f'<time datetime="{iso}">{when:%Y-%m-%d %H:%M:%S} UTC</time>'


def duration(seconds: int | None) -> str:
    """Time spent as a teacher reads it: '–' (none reported), '< 1 min', '12 min', '2 h 05 min'."""
    if seconds is None:
        return "–"
    minutes = seconds // 60
    if minutes < 1:
        return "< 1 min"
    if minutes < 60:
        return f"{minutes} min"
    return f"{minutes // 60} h {minutes % 60:02d} min"


# The rule of app/teacher/time_spent.py (IDLE_AFTER_SEC), which this layer cannot import.
TIME_SPENT_HELP = (
    "Time spent: active time the learner's dashboard counted while this activity was "
    "the one it was on and the learner had done something there in the last 5 minutes"
)


def _wait(seconds: float) -> str:
    if seconds <= 1:
        return "now"
    if seconds < 120:
        return f"in {seconds:.0f} s"
    return f"in {seconds / 60:.0f} min"


def _gradebook_row(line: GradebookLine, now: float, seats: bool, whose: bool = True) -> str:
    """One line of the gradebook; ``whose``: with its learner and activity (the full table)."""
    cells = []
    if whose:
        who = html.escape(line.lms_name or "(no name from the LMS)")
        hub_name = f'<span class="hub nowrap">{html.escape(line.learner)}</span>'
        cells.append(f"<td><b>{who}</b><br>{hub_name}</td>")
        if seats:
            cells.append(f"<td>{html.escape(line.seat)}</td>")
        activity = line.activity or "(a grade column no launch names now)"
        cells.append(f"<td>{html.escape(activity)}</td>")
    column = html.escape(line.lineitem or "")
    cells += [
        f'<td>{html.escape(line.link)}<br><span class="hub url">{column}</span></td>',
        f'<td class="{line.state.replace(" ", "-")} nowrap">{_STATE_MARKS[line.state]}</td>',
        f"<td>{html.escape(line.score)}</td>",
    ]
    if whose:
        cells.append(f'<td class="time nowrap">{duration(line.time_spent)}</td>')
        graded = str(line.graded) if line.kind == "exercise" else "–"
        last = f"<br>last {_time(line.last_graded)}" if line.last_graded else ""
        cells.append(f'<td class="graded">{graded}{last}</td>')
    if line.state == "sent":
        answer = line.lms_answer or "accepted"
        cells += [f"<td>{_time(line.sent_at)}</td>", f"<td>{html.escape(answer)}</td>", "<td></td>"]
    elif line.state == "waiting":
        answer = line.lms_answer if line.attempts else "not tried yet"
        retry = _wait((line.next_try or now) - now)
        tries = f" (after {line.attempts} tr{'y' if line.attempts == 1 else 'ies'})"
        cells += [
            f"<td>earned {_time(line.queued_at)}</td>",
            f"<td>{html.escape(answer)}</td>",
            f"<td>{retry}{tries if line.attempts else ''}</td>",
        ]
    elif line.state == "refused":
        cells += [
            f"<td>earned {_time(line.queued_at)}</td>",
            f"<td>{html.escape(line.lms_answer)}</td>",
            "<td>not retried: press Retry once fixed in the LMS</td>",
        ]
    else:
        cells += [f"<td>launched {_time(line.launched_at)}</td>", "<td></td>", "<td></td>"]
    return f'<tr data-state="{html.escape(line.state)}">{"".join(cells)}</tr>'


# A learner and an activity with several links (two courses): the cell shows the best.
_STATE_ORDER = ("sent", "waiting", "refused", "not done", "no grade column")
_CELL_MARKS = {
    "sent": "✓",
    "waiting": "…",
    "refused": "✗",
    "not done": "○",
    "no grade column": "–",
}


HISTORY_PATH = "gradebook/attempts"  # beside the gradebook page, under the tool's address


def history_link(learner: str, kind: str, slug: str) -> str:
    """The address of one learner's history of one activity, relative to the gradebook page."""
    return f"{HISTORY_PATH}?{urlencode({'learner': learner, 'activity': f'{kind}:{slug}'})}"


def _graded_words(line: GradebookLine) -> str:
    """'3 graded attempts, the last 2026-11-29 10:15 UTC', for a cell's tooltip."""
    if line.kind != "exercise":
        return "a lesson: no graded attempts"
    if not line.graded:
        return "no graded attempt known"
    when = datetime.fromtimestamp(line.last_graded or 0, timezone.utc).strftime("%Y-%m-%d %H:%M")
    plural = "" if line.graded == 1 else "s"
    return f"{line.graded} graded attempt{plural}, the last {when} UTC"


def class_grid(lines: Sequence[GradebookLine]) -> str:
    """The class at a glance: a row per learner, a column per activity, a mark per cell.

    A teacher of 200 reads who is done and what waits without reading 200 lines;
    a click on a cell opens that learner's history of that activity (each graded
    attempt, its seed, and what the LMS has), a click on a name shows their
    lines in the table below (the filter).
    """
    if not lines:
        return ""
    activities = sorted({line.activity for line in lines if line.activity})
    learners: dict[str, str] = {}
    best: dict[tuple[str, str], GradebookLine] = {}
    for line in lines:
        learners.setdefault(line.learner, line.lms_name or line.learner)
        key = (line.learner, line.activity)
        held = best.get(key)
        if held is None or _STATE_ORDER.index(line.state) < _STATE_ORDER.index(held.state):
            best[key] = line
    head = "".join(f"<th>{html.escape(activity)}</th>" for activity in activities)
    rows = []
    for learner, shown in sorted(learners.items(), key=lambda item: item[1].lower()):
        cells = []
        for activity in activities:
            shown_line = best.get((learner, activity))
            if shown_line is None:
                cells.append("<td></td>")
                continue
            state, score = shown_line.state, shown_line.score
            spent = duration(shown_line.time_spent)
            title = f"{_STATE_MARKS[state]} {score}: {shown}, {activity}; time spent {spent}; "
            title += f"{_graded_words(shown_line)}; its attempts"
            link = history_link(learner, shown_line.kind, shown_line.slug)
            tip = html.escape(title, quote=True)
            cells.append(
                f'<td class="{state.replace(" ", "-")}">'
                f'<a href="{html.escape(link, quote=True)}" title="{tip}">'
                f"{_CELL_MARKS[state]} {html.escape(score)}</a></td>"
            )
        name = (
            f'<a href="#gradebook" data-show="{html.escape(learner, quote=True)}">'
            f"{html.escape(shown)}</a>"
        )
        rows.append(f"<tr><th>{name}</th>{''.join(cells)}</tr>")
    legend = " · ".join(f"{_CELL_MARKS[state]} {state}" for state in _STATE_ORDER)
    return (
        "<h2>The class at a glance</h2>\n"
        f"<p>{html.escape(legend)}. A click on a cell opens that learner's attempts at it "
        "(each grading, its seed, what went to the LMS); a click on a name shows their "
        "lines below. Hover a cell for the time spent on it.</p>\n"
        f'<table id="class-grid"><thead><tr><th>Learner</th>{head}</tr></thead>'
        f"<tbody>\n{chr(10).join(rows)}\n</tbody></table>\n"
    )


def gradebook_page(
    lines: Sequence[GradebookLine],
    *,
    now: float,
    retry_form: str,
    back: tuple[str, str] | None = None,
    notice: str = "",
) -> str:
    """The teacher's gradebook: per learner and LMS link, what was sent and what waits.

    ``retry_form`` is the form's opening tag and hidden fields (the web layer's
    XSRF field); ``back`` a link to the teacher's page, (address, text).
    """
    found = counts(lines)
    seats = any(line.seat for line in lines)
    summary = " · ".join(f"{n} {state}" for state, n in found.items() if n) or "no launches yet"
    retryable = found["waiting"] + found["refused"]
    head = ["Learner", *(["Dashboard"] if seats else []), "Activity", "LMS link and grade column"]
    head += [
        "Grade",
        "Score",
        f'<span title="{html.escape(TIME_SPENT_HELP, quote=True)}">Time spent</span>',
        "Graded attempts",
    ]
    head += ["When", "The LMS's answer", "Next try"]
    rows = "\n".join(_gradebook_row(line, now, seats) for line in lines)
    back_link = (
        f' · <a href="{html.escape(back[0], quote=True)}">{html.escape(back[1])}</a>'
        if back
        else ""
    )
    return _page(
        "Gradebook: ROS 2 Classroom",
        "<style>body{max-width:none}.url{display:inline-block;max-width:22em;"
        "word-break:break-all}.nowrap{white-space:nowrap}</style>"
        "<h1>Grades sent to the LMS</h1>\n"
        f'<p>{html.escape(summary)}{back_link} · <a href="gradebook">Reload</a> · '
        '<a href="gradebook.csv">Download as CSV</a></p>\n'
        + (f'<p class="why">{html.escape(notice)}</p>\n' if notice else "")
        + "<p>One line per LMS link a learner opened. A finished lesson or passed exercise "
        "becomes a score that waits in the outbox until the LMS takes it; an LMS that is "
        "down gets it later (after 5 s, 10 s, 20 s ... up to every ten minutes).</p>\n"
        f"{retry_form}"
        f'<button type="submit">Retry the outbox now ({retryable} waiting or refused)</button>'
        ' <label>Show only <input id="filter" placeholder="a name, an activity, a state"></label>'
        "</form>\n" + class_grid(lines) + "<h2>Every line</h2>\n"
        '<table id="gradebook"><thead><tr>'
        + "".join(f"<th>{h}</th>" for h in head)
        + f"</tr></thead><tbody>\n{rows}\n</tbody></table>\n"
        "<script>"
        'for(const t of document.querySelectorAll("time"))'
        "t.textContent=new Date(t.dateTime).toLocaleString();"
        'const f=document.getElementById("filter");f.oninput=()=>{const q=f.value.toLowerCase();'
        'for(const r of document.querySelectorAll("#gradebook tbody tr"))'
        "r.hidden=q&&!r.textContent.toLowerCase().includes(q);};"
        'for(const a of document.querySelectorAll("#class-grid a[data-show]"))'
        "a.onclick=()=>{f.value=a.dataset.show;f.oninput();};"
        "</script>",
    )


_VERDICTS = {"pass": "✓ passed", "fail": "✗ failed", "problem": "⚠ not graded"}


def replay_command(slug: str, seed: int, code_file: str = "") -> str:
    """The command that replays one grading: the learner's code as FILE, the same seed."""
    file = shlex.quote(code_file) if code_file else "FILE"
    return f"ros2-classroom exercise check {slug} {file} --seed {seed}"


def _attempt_row(attempt: Attempt, slug: str, code_file: str) -> str:
    verdict = _VERDICTS.get(attempt.verdict, attempt.verdict)
    checks = f"{attempt.passed} of {attempt.total}" if attempt.total else "–"
    if attempt.failed:
        why = "<ul>" + "".join(f"<li>{html.escape(f)}</li>" for f in attempt.failed) + "</ul>"
    elif attempt.verdict == "problem":
        why = html.escape(attempt.summary or "grading could not start")
    elif attempt.verdict == "fail" and not attempt.total:
        why = "(its result lines could not be read: the recording is damaged)"
    else:
        why = ""
    if attempt.seed and attempt.verdict != "problem":
        # The code this attempt graded, when its folder kept it: the verdict comes back.
        command = replay_command(slug, attempt.seed, attempt.graded_file or code_file)
        quoted = html.escape(command, quote=True)
        replay = (
            f"<code>{html.escape(command)}</code> "
            f'<button type="button" class="copy" data-copy="{quoted}">Copy</button>'
        )
        seed = str(attempt.seed)
    else:
        replay, seed = "nothing to replay" if attempt.verdict == "problem" else "no seed kept", "–"
    cells = [
        f'<td class="nowrap">{_time(attempt.at)}</td>',
        f'<td class="{attempt.verdict} nowrap">{html.escape(verdict)}</td>',
        f"<td>{checks}</td>",
        f"<td>{why}</td>",
        f'<td class="seed">{seed}</td>',
        f"<td>{replay}</td>",
    ]
    return f'<tr data-verdict="{html.escape(attempt.verdict)}">{"".join(cells)}</tr>'


def attempts_page(
    lines: Sequence[GradebookLine],
    *,
    learner: str,
    kind: str,
    slug: str,
    source: AttemptSource | None,
    now: float,
) -> str:
    """One learner's history of one activity: every graded attempt, and what the LMS has.

    ``lines`` are the learner's gradebook lines for it (a line per LMS link, so one
    per course that links it); ``source`` the attempts and where they come from
    (None for a lesson, which has no graded attempts).
    """
    first = lines[0] if lines else None
    shown = (first.lms_name if first else "") or learner
    activity = (first.activity if first else "") or f"{kind} {slug}"
    seat = f" · dashboard {html.escape(first.seat)}" if first and first.seat else ""
    spent = first.time_spent if first else None
    head = ["LMS link and grade column", "Grade", "Score", "When", "The LMS's answer", "Next try"]
    lms_rows = "\n".join(_gradebook_row(line, now, False, whose=False) for line in lines)
    told = [
        f"<li>{html.escape(line.link or 'LMS link')}: <q>{html.escape(line.comment)}</q></li>"
        for line in lines
        if line.comment
    ]
    parts = [
        "<style>body{max-width:none}.url{display:inline-block;max-width:22em;"
        "word-break:break-all}.nowrap{white-space:nowrap}.fail{color:#b91c1c}"
        ".pass{color:#166534}td ul{margin:0;padding-left:1.1em}</style>",
        f"<h1>{html.escape(shown)}: {html.escape(activity)}</h1>",
        f'<p><span class="hub">{html.escape(learner)}</span>{seat} · '
        '<a href="../gradebook">Back to the gradebook</a></p>',
        f'<p id="time-spent"><b>Time spent on it: {duration(spent)}</b> '
        f"({html.escape(TIME_SPENT_HELP[len('Time spent: ') :])}"
        + ("" if spent is not None else "; none reported yet")
        + ").</p>",
        "<h2>In the LMS</h2>",
        '<table id="lms"><thead><tr>'
        + "".join(f"<th>{h}</th>" for h in head)
        + f"</tr></thead><tbody>\n{lms_rows}\n</tbody></table>",
    ]
    if told:
        parts.append(f"<p>What the score told the LMS:</p><ul>{''.join(told)}</ul>")
    if source is None:
        parts += [
            "<h2>Attempts</h2>",
            "<p>A lesson has no graded attempts: it counts as done when the learner is on "
            "its last step and every check of that step passes on their live ROS 2 graph. "
            "The teacher's page shows the step they are on and its checks.</p>",
        ]
        return _page(f"{shown}: {activity}", "\n".join(parts))
    parts += [
        "<h2>Graded attempts, newest first</h2>",
        f"<p>{html.escape(source.where)}</p>",
    ]
    if source.attempts:
        passes = sum(a.verdict == "pass" for a in source.attempts)
        fails = sum(a.verdict == "fail" for a in source.attempts)
        parts.append(
            f"<p>{len(source.attempts)} shown: {passes} passed, {fails} failed, "
            f"{len(source.attempts) - passes - fails} not graded.</p>"
        )
        rows = "\n".join(_attempt_row(a, slug, source.code_file) for a in source.attempts)
        head = ["When", "Verdict", "Checks passed", "What failed, and why", "Seed", "Replay it"]
        parts.append(
            '<table id="attempts"><thead><tr>'
            + "".join(f"<th>{h}</th>" for h in head)
            + f"</tr></thead><tbody>\n{rows}\n</tbody></table>"
        )
    else:
        parts.append(f"<p><b>No graded attempt of {html.escape(slug)} is known here yet.</b></p>")
    parts.append(
        '<h2 id="replay">Replaying a grading</h2>'
        "<p>The command beside an attempt grades the learner's code again with the hidden "
        "inputs drawn from that attempt's seed, so the probes send the same values. "
        f"There is no replay button here: {html.escape(source.replay)}. Run it in a "
        "terminal on a machine with the classroom installed"
        + (
            f", where <code>{html.escape(source.code_file)}</code> is the learner's code"
            if source.code_file
            else ", with the learner's code saved as FILE (the teacher's page shows it "
            "under the learner)"
        )
        + ". An attempt that kept the code it graded names that copy (a path in the "
        "learner's bags folder, on the machine that graded it), and the command gives "
        "its verdict again; for an older attempt it grades the code as it is now, and "
        "if the learner changed it since, the result may differ.</p>"
    )
    if source.recordings:
        parts.append(f"<p>{html.escape(source.recordings)}</p>")
    parts.append(
        "<script>"
        'for(const t of document.querySelectorAll("time"))'
        "t.textContent=new Date(t.dateTime).toLocaleString();"
        'for(const b of document.querySelectorAll("button.copy")){'
        "if(!navigator.clipboard){b.hidden=true;continue;}"
        "b.onclick=()=>navigator.clipboard.writeText(b.dataset.copy)"
        '.then(()=>{b.textContent="Copied";});}'
        "</script>"
    )
    return _page(f"{shown}: {activity}", "\n".join(parts))


def not_found_page(sentence: str) -> str:
    """What a history address that names no learner or activity of the gradebook shows."""
    return _page(
        "Not in the gradebook: ROS 2 Classroom",
        "<h1>Not in the gradebook</h1>\n"
        f'<p class="why">{html.escape(sentence)}</p>\n'
        '<p><a href="../gradebook">Back to the gradebook</a>: its class grid links each '
        "learner's history of each activity.</p>",
    )

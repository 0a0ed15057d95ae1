"""The few HTML pages LTI shows a person: a refusal, and the teacher's activity picker.

Server-rendered and self-contained (no script but the picker's one line, no
outside file), since they open inside an LMS frame or a new tab before any
of our other pages. Every value from a request or an LMS is escaped.
"""

from __future__ import annotations

import html
from collections.abc import Sequence

from app.lti.deep_linking import Activity

_STYLE = (
    "body{font-family:system-ui,sans-serif;margin:1.5em;max-width:52em;line-height:1.4}"
    "table{border-collapse:collapse}td,th{padding:.3em .6em;text-align:left;"
    "border-bottom:1px solid #ddd}.why{background:#fff4e5;border-left:4px solid #d97706;"
    "padding:.6em 1em}input[type=number]{width:5em}"
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

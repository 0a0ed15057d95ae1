"""Python source as the learner reads it: highlighted, with line numbers to point at.

Lesson text can say "line 12 creates the publisher": the numbers beside the
code are the file's own line numbers. Pygments writes inline styles, so the
HTML needs no stylesheet in viser's page.
"""

from __future__ import annotations

import html

from pygments import highlight
from pygments.formatters import HtmlFormatter
from pygments.lexers import PythonLexer

_FORMATTER = HtmlFormatter(
    linenos="inline", noclasses=True, style="friendly", nobackground=True, wrapcode=True
)


def python_listing(title: str, source: str) -> str:
    """One file: its name, then its code highlighted with inline line numbers."""
    body = highlight(source, PythonLexer(), _FORMATTER)
    return (
        f'<div style="font-weight:600;margin:6px 0 2px">{html.escape(title)}</div>'
        '<div style="font-size:12px;line-height:1.45;overflow-x:auto;background:#f8f8f8;'
        f'border:1px solid #e5e7eb;border-radius:4px;padding:4px 6px">{body}</div>'
    )

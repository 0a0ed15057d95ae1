"""Source as the learner reads it: highlighted, with line numbers to point at.

Lesson text can say "line 12 creates the publisher": the numbers beside the
code are the file's own line numbers. Pygments writes inline styles, so the
HTML needs no stylesheet in viser's page.
"""

from __future__ import annotations

import html

from pygments import highlight
from pygments.formatters import HtmlFormatter
from pygments.lexers import PythonLexer, TextLexer, get_lexer_for_filename
from pygments.util import ClassNotFound

_FORMATTER = HtmlFormatter(
    linenos="inline",
    linespans="L",  # each line its own span, which we make a block (below)
    noclasses=True,
    style="friendly",
    nobackground=True,
    wrapcode=True,
)
_NUMBER_STYLE = (
    "color: #666666; background-color: transparent; padding-left: 5px; padding-right: 5px;"
)
# A long line wraps under its own code, never under the numbers, and nothing
# is cut off at the window's edge: a hanging indent as wide as the number column.
_LINE = '<span style="display:block;white-space:pre-wrap;padding-left:5ch;text-indent:-5ch" id="L-'
_NUMBER = (
    'style="color:#868e96;display:inline-block;width:3.5ch;margin-right:1.5ch;'
    'text-align:right;text-indent:0;user-select:none" class="lineno"'
)


def python_listing(title: str, source: str, filename: str = "") -> str:
    """One file: its name, then its code highlighted, numbered, wrapped at the edge.

    Python unless ``filename`` names another kind (package.xml, CMakeLists.txt, Num.msg).
    """
    lexer = PythonLexer()
    if filename and not filename.endswith(".py"):
        try:
            lexer = get_lexer_for_filename(filename, stripnl=False)
        except ClassNotFound:
            lexer = TextLexer(stripnl=False)
    body = highlight(source, lexer, _FORMATTER)
    body = body.replace('<span id="L-', _LINE).replace("\n</span>", "</span>")
    body = body.replace(f'style="{_NUMBER_STYLE}"', _NUMBER)
    return (
        f'<div style="font-weight:600;margin:6px 0 2px">{html.escape(title)}</div>'
        '<div style="font-size:12px;line-height:1.45;background:#f8f8f8;'
        f'border:1px solid #e5e7eb;border-radius:4px;padding:4px 6px">{body}</div>'
    )

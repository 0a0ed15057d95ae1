"""The lesson code window: highlighted Python whose line numbers are the file's own."""

from __future__ import annotations

import re

from app.ui.code_view import python_listing


def test_every_line_is_numbered_and_code_is_highlighted():
    source = "import rclpy\n\n\ndef main():\n    x = '<b>'  # not markup\n"
    listing = python_listing("nodes/<demo>.py", source)
    numbers = re.findall(r'class="lineno">\s*(\d+)</span>', listing)
    assert numbers[:5] == ["1", "2", "3", "4", "5"]
    assert "color:" in listing  # coloured tokens, inline: no stylesheet needed
    assert "&lt;b&gt;" in listing and "<b>" not in listing  # code is text, never markup
    assert "nodes/&lt;demo&gt;.py" in listing


def test_a_lesson_file_keeps_its_line_count():
    text = open("nodes/talker.py", encoding="utf-8").read()
    listing = python_listing("nodes/talker.py", text)
    numbers = [int(n) for n in re.findall(r'class="lineno">\s*(\d+)</span>', listing)]
    assert max(numbers) == len(text.splitlines())


def test_long_lines_wrap_under_their_code_instead_of_being_cut_off():
    listing = python_listing("long.py", "x = '" + "a" * 300 + "'\n")
    assert "overflow" not in listing  # no hidden part to scroll to
    line = re.search(r'<span style="([^"]*)" id="L-1">', listing)
    assert line and "white-space:pre-wrap" in line.group(1) and "text-indent:-5ch" in line.group(1)

"""A step's text as the card shows it: the title is the card's own, section headings are
no larger than it."""

from __future__ import annotations

from app.lessons.panel import _without_title


def test_a_steps_text_loses_its_title_and_its_section_headings_come_out_bold():
    text = "# The step\n\nRead this.\n\n## Try it\n\n```sh\n# a comment, not a heading\nls\n```\n"
    shown = _without_title(text)
    assert not shown.startswith("# The step") and shown.startswith("Read this.")
    assert "**Try it**" in shown and "## Try it" not in shown
    assert "# a comment, not a heading" in shown  # inside a code block: as written
    assert _without_title("No title here.\n") == "No title here.\n"

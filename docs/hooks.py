"""MkDocs hooks: the pages' generated parts, drawn from the code at every build.

A page asks for one with a marker on a line of its own:

- ``<!-- generated: architecture -->``: the packages of ``app`` and their
  imports (``tools/architecture.py``), and the circles among them;
- ``<!-- generated: contracts -->``: the import-linter contracts of
  ``pyproject.toml``, the rules ``make lint`` enforces;
- ``<!-- generated: course -->``: the lessons in course order, from their
  ``lesson.toml`` files (number, title, steps, exercises).

So the developers' pages cannot drift from the code they describe.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tools.architecture import architecture_svg, circles_markdown, read_house  # noqa: E402

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib


def _contracts() -> str:
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())
    rows = ["| rule | kind | modules |", "|---|---|---|"]
    for contract in config["tool"]["importlinter"]["contracts"]:
        if contract["type"] == "forbidden":
            modules = (
                ", ".join(f"`{m}`" for m in contract["source_modules"])
                + " must not import "
                + ", ".join(f"`{m}`" for m in contract["forbidden_modules"])
            )
        elif contract["type"] == "layers":
            modules = " above ".join(f"`{m}`" for m in contract["layers"])
        else:
            modules = ", ".join(f"`{m}`" for m in contract["modules"])
        rows.append(f"| {contract['name']} | {contract['type']} | {modules} |")
    return "\n".join(rows)


def _course() -> str:
    rows = ["| # | lesson | steps | exercises |", "|---|---|---|---|"]
    for folder in sorted(p for p in (ROOT / "lessons").iterdir() if (p / "lesson.toml").is_file()):
        lesson = tomllib.loads((folder / "lesson.toml").read_text(encoding="utf-8"))
        exercises = folder / "exercises"
        count = sum(1 for e in exercises.iterdir() if e.is_dir()) if exercises.is_dir() else 0
        rows.append(
            f"| {int(folder.name[:2])} | {lesson['title']} | {len(lesson['steps'])} | "
            f"{count or '–'} |"
        )
    return "\n".join(rows)


def on_page_markdown(markdown: str, **_: Any) -> str:
    if "<!-- generated: architecture -->" in markdown:
        house = read_house()
        picture = f'<div class="architecture">{architecture_svg(house)}</div>'
        markdown = markdown.replace(
            "<!-- generated: architecture -->", picture + "\n\n" + circles_markdown(house)
        )
    if "<!-- generated: contracts -->" in markdown:
        markdown = markdown.replace("<!-- generated: contracts -->", _contracts())
    if "<!-- generated: course -->" in markdown:
        markdown = markdown.replace("<!-- generated: course -->", _course())
    return markdown

"""The course's lessons and exercises as the deep-linking picker lists them.

The teacher service runs in the hub's image, which has no ROS and no viser
(tests/hub/test_deploy.py keeps it so), while the course loaders
(``app.lessons.schema.load_course``, ``app.exercises.model.load_exercises``)
check every lesson against the ROS layer and the UI's tabs. So this reads
only what a picker needs, the folder names and titles, from the same files
with the same naming rules; tests/lti/test_service.py checks that it lists
exactly what those loaders load.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

from app import PROJECT_ROOT
from app.lti.deep_linking import Activity

if sys.version_info >= (3, 11):
    import tomllib
else:  # Python 3.10
    import tomli as tomllib

LESSONS_DIR = PROJECT_ROOT / "lessons"
DEFAULT_POINTS = 10.0
_LESSON_DIR = re.compile(r"^(\d{2})_[a-z0-9_]+$")
_SLUG = re.compile(r"^[a-z][a-z0-9_]{2,48}$")


def _title(path: Path) -> str | None:
    try:
        title = tomllib.loads(path.read_text(encoding="utf-8")).get("title")
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
        return None
    return title.strip() if isinstance(title, str) and title.strip() else None


def course_activities(root: Path = LESSONS_DIR) -> list[Activity]:
    """Each lesson, then its exercises, in course order; a file that does not read is left out."""
    found: list[Activity] = []
    folders = sorted(p for p in root.iterdir() if p.is_dir()) if root.is_dir() else []
    for lesson in (p for p in folders if _LESSON_DIR.match(p.name)):
        title = _title(lesson / "lesson.toml")
        if title is None:
            continue
        unit = int(lesson.name[:2])
        found.append(Activity("lesson", lesson.name, f"Lesson {unit}: {title}", DEFAULT_POINTS))
        for exercise in sorted((lesson / "exercises").glob("*")):
            if not exercise.is_dir() or exercise.name.startswith((".", "_")):
                continue
            if not _SLUG.match(exercise.name):
                continue
            exercise_title = _title(exercise / "exercise.toml")
            if exercise_title is not None:
                found.append(
                    Activity(
                        "exercise",
                        exercise.name,
                        f"Exercise (lesson {unit}): {exercise_title}",
                        DEFAULT_POINTS,
                    )
                )
    return found

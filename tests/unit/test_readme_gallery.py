"""The README's gallery shows every lesson's first and last step, as `make screenshots`
took them (docs/screenshots.py, ``gallery``)."""

from __future__ import annotations

from app import PROJECT_ROOT
from tests.course_data import shared_course


def test_every_lesson_has_its_first_and_last_step_in_the_readme_gallery():
    readme = (PROJECT_ROOT / "README.md").read_text(encoding="utf-8")
    missing = []
    for lesson in shared_course().lessons:
        for which in ("first", "last"):
            picture = f"docs/images/lessons/{lesson.unit:02d}-{which}.jpg"
            if f"]({picture})" not in readme or not (PROJECT_ROOT / picture).is_file():
                missing.append(picture)
    assert not missing, f"run `make screenshots` (gallery) and update the README: {missing}"

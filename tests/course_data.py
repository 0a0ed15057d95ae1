"""The course and the exercises as this tree holds them, loaded once per test process.

Some thirty test modules build their cases from the lessons and the exercises when
pytest collects them, and every xdist worker collects every module: read afresh each
time, the course and the exercise book took 5 CPU-seconds of each worker's start.
Both are frozen dataclasses, so sharing one copy is safe. A test that loads lessons
it wrote itself (a folder of its own) calls ``load_course(root)`` as before.
"""

from __future__ import annotations

from functools import cache

from app.exercises.model import ExerciseBook, load_exercises
from app.lessons.schema import Course, load_course


@cache
def shared_course() -> Course:
    """``load_course()`` of the lessons in this tree, once."""
    return load_course()


@cache
def shared_exercises() -> ExerciseBook:
    """``load_exercises()`` of the exercises in this tree, once."""
    return load_exercises()

"""Which recorded mistake a failed grading matches, so a teacher can group a class's failures.

Each exercise lists plausible wrong solutions (``[[mistakes]]``: a file whose
name says the mistake, ``front_is_index_zero.py``, and words its failing
result must contain). The test suite proves each one fails with its words; the
same words, found in a learner's failed result, name what the learner most
likely did. Failures no recorded mistake explains keep the failed result's
name ("stop before the wall"), so they still group with their like.
"""

from __future__ import annotations

from app.exercises.model import Exercise, Mistake
from app.exercises.report import Report


def matched_mistake(exercise: Exercise, report: Report) -> str:
    """The first recorded mistake whose words a failed result's detail contains (the stem
    of its file, e.g. ``front_is_index_zero``); else the first failed result's name; ''
    when nothing failed."""
    if report.passed:
        return ""
    failures = report.failures()
    for mistake in exercise.mistakes:
        if any(mistake.reason in result.detail for result in failures):
            return mistake_name(exercise, mistake)
    return failures[0].name if failures else ""


def mistake_name(exercise: Exercise, mistake: Mistake) -> str:
    """``front_is_index_zero`` for ``mistakes/front_is_index_zero.py``; a package exercise's
    mistake is a package folder inside the folder that names it
    (``mistakes/wrong_module/py_adder``: ``wrong_module``)."""
    if exercise.is_package and mistake.path.name == exercise.package:
        return mistake.path.parent.name
    return mistake.path.stem

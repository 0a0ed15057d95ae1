"""Every exercise loads, and the course has one for each unit from 2 to 14."""

from __future__ import annotations

from app.exercises.lint import lint, refuses_to_run
from app.exercises.model import load_exercises

book = load_exercises()


def test_every_exercise_file_is_valid():
    assert book.errors == ()


def test_an_exercise_for_every_unit_from_2_to_14_and_15_in_all():
    units = {exercise.unit for exercise in book.exercises}
    missing = sorted(set(range(2, 15)) - units)
    assert not missing, f"units without an exercise: {missing}"
    assert len(book.exercises) >= 15


def test_each_exercise_has_a_plausible_mistake_and_runnable_code():
    for exercise in book.exercises:
        assert exercise.mistakes, f"{exercise.slug}: no [[mistakes]]"
        for name, code in (("starter", exercise.starter), ("reference", exercise.reference)):
            assert not refuses_to_run(lint(code)), f"{exercise.slug}: {name} does not compile"
        assert "TODO" in exercise.starter, f"{exercise.slug}: the starter marks no part to fill in"

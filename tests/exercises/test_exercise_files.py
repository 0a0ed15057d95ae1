"""Every exercise loads, and the course has one for each unit from 2 to 14."""

from __future__ import annotations

from app.exercises.lint import lint, refuses_to_run
from tests.course_data import shared_exercises

book = shared_exercises()


def test_every_exercise_file_is_valid():
    assert book.errors == ()


def test_an_exercise_for_every_lesson_from_first_node_to_tf2_and_15_in_all():
    # Lessons 4 (your first node) to 16 (tf2) each teach writing a node; 1-3 are about
    # the graph and the command line, 17 and 21 go on with what 16 and 20 practise.
    lessons = {exercise.unit for exercise in book.exercises}
    missing = sorted(set(range(4, 17)) - lessons)
    assert not missing, f"lessons without an exercise: {missing}"
    assert len(book.exercises) >= 15


def test_each_exercise_has_a_plausible_mistake_and_runnable_code():
    for exercise in book.exercises:
        assert exercise.mistakes, f"{exercise.slug}: no [[mistakes]]"
        for name, code in _python_sources(exercise):
            assert not refuses_to_run(lint(code)), f"{exercise.slug}: {name} does not compile"
        assert "TODO" in exercise.starter, f"{exercise.slug}: the starter marks no part to fill in"


def _python_sources(exercise):
    """The starter's and reference's Python: one file, or each .py file of a package."""
    if not exercise.is_package:
        return [("starter", exercise.starter), ("reference", exercise.reference)]
    folders = (("starter", exercise.starter_dir), ("reference", exercise.reference_dir))
    return [
        (f"{name} {path.name}", path.read_text(encoding="utf-8"))
        for name, folder in folders
        for path in sorted(folder.rglob("*.py"))
    ]


def _leaves(value):
    """The plain values inside an example (lists and tables opened)."""
    if isinstance(value, dict):
        return [leaf for inner in value.values() for leaf in _leaves(inner)]
    if isinstance(value, list):
        return [leaf for inner in value for leaf in _leaves(inner)]
    return [value]


def test_every_exercise_has_a_cheat_or_a_reasoned_exemption():
    """A solution replaying the statement's example is generated for every exercise (and
    test_grading runs it), unless the exercise is exempt, with a reason."""
    from tests.exercises.cheats import EXEMPT, cheat_code, input_probe

    for slug, reason in EXEMPT.items():
        assert book.get(slug) and len(reason.split()) >= 5, f"{slug}: exempt without a reason"
    for exercise in book.exercises:
        if exercise.slug in EXEMPT:
            continue
        assert input_probe(exercise), (
            f"{exercise.slug}: no probe with a cheat generator (tests/exercises/cheats.py) and "
            "no exemption: a solution replaying the statement's example is never tried"
        )
        assert "class Cheat" in cheat_code(exercise)


def test_every_exercise_shows_an_example_that_is_not_the_test():
    """The example (what the statement shows) is data, so a cheat replaying it can be made."""
    from app.exercises.explain import drawn_fields
    from app.exercises.probes import PROBES
    from tests.exercises.cheats import EXEMPT

    for exercise in book.exercises:
        if exercise.slug in EXEMPT:
            continue
        assert exercise.example, f"{exercise.slug}: no example table"
        for item in _leaves(exercise.example):
            shown = f"{item:.2f}" if isinstance(item, float) else str(item)
            assert shown in exercise.statement or str(item) in exercise.statement, (
                f"{exercise.slug}: example value {item!r} is not in the statement"
            )
        if any(PROBES[p.kind].feeds for p in exercise.probes):
            drawn = [name for p in exercise.probes for name in drawn_fields(p)]
            assert drawn, f"{exercise.slug}: its probes draw nothing at grading time"


def test_a_seed_replays_the_drawn_inputs_and_another_seed_changes_them():
    import random

    from app.exercises.probes.base import draw
    from app.exercises.probes.lifecycle_sequence import lifecycle_walk

    def inputs(seed):
        rng = random.Random(seed)
        return [draw(rng, [-1000, 1000]) for _ in range(8)], lifecycle_walk(rng, 8)

    assert inputs(12345) == inputs(12345)
    assert inputs(12345) != inputs(54321)
    steps = inputs(12345)[1]
    assert sum(not s.get("succeeds", True) for s in steps) >= 2
    assert steps[-1]["state"] == "active"


def test_a_teacher_can_read_how_each_exercise_is_graded_without_the_values():
    from app.exercises.explain import explain, panel_line

    running_sum = book.get("running_sum")
    text = "\n".join(explain(running_sum))
    assert "inputs random in [-1000, 1000]" in text and "count random in [6, 9]" in text
    assert "--seed" in text
    assert "random" in panel_line(book.get("lifecycle_beacon"))
    assert "random images" in "\n".join(explain(book.get("red_mask")))


def test_each_probe_kind_is_one_module_of_its_name_and_a_name_registers_once():
    """A new probe kind is a new module in app/exercises/probes and nothing else."""
    import pytest

    from app.exercises.probes import PROBES
    from app.exercises.probes.base import register_probe
    from app.lessons.kinds import CHECKS

    for name, kind in PROBES.items():
        assert kind.run.__module__ == f"app.exercises.probes.{name}", name
        assert kind.words, f"probe kind {name} has no words for the learner"
    assert not set(PROBES) & set(CHECKS), "a probe kind named like a check kind"
    with pytest.raises(RuntimeError, match="registered twice"):
        register_probe("topic_feed", required="", words="again")(PROBES["topic_feed"].run)
    with pytest.raises(RuntimeError, match="already a check kind"):
        register_probe("topic_rate", required="", words="a check's name")(lambda ctx, p: None)


def test_a_random_lifecycle_order_is_never_the_statements_example():
    """Unchecked, 18 % of the drawn orders accepted exactly the example's transitions (the
    invalid requests aside), and a node replaying the example passed those gradings."""
    import random

    from app.exercises.probes.lifecycle_sequence import lifecycle_walk

    beacon = book.get("lifecycle_beacon")
    example = beacon.example["transitions"]
    probe = next(p for p in beacon.probes if p.kind == "lifecycle_sequence")
    low, high = probe["walk"]
    for seed in range(3000):
        rng = random.Random(seed)
        steps = lifecycle_walk(rng, rng.randint(low, high), probe.get("end", "active"), example)
        accepted = [s["transition"] for s in steps if s.get("succeeds", True)]
        assert accepted != example, f"seed {seed} draws the example's order"

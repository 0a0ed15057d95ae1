"""Exercise files: ``lessons/NN_slug/exercises/<slug>/exercise.toml``, validated at load.

An exercise is data that lives with its lesson: the task (``statement.md``),
runnable starter code with the parts to fill in marked, the reference
solution, hints, the checks (the lessons' check kinds, run on the live graph)
and the probes (the grader drives the learner's node: calls, goals,
parameters, transitions, fed messages). ``[[mistakes]]`` lists plausible
wrong solutions with the words their failure must name; the test suite runs
each one. The grading logic lives in ``app.exercises.grader`` and
``app.exercises.probes``.
"""

from __future__ import annotations

import copy
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, TypeVar

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib

from app.catalog import ENTRIES
from app.exercises.probes import PROBE_KINDS, PROBES
from app.lessons.kinds import CHECK_KINDS
from app.lessons.schema import LESSONS_DIR, LessonError, Spec, inside, parse_spec

if TYPE_CHECKING:
    from collections.abc import Mapping

_SLUG = re.compile(r"^[a-z][a-z0-9_]{2,48}$")
_LESSON_DIR = re.compile(r"^(\d{2})_[a-z0-9_]+$")
_NODE = re.compile(r"^(/[A-Za-z_][A-Za-z0-9_]*)+$")
_CATALOG = frozenset(entry.name for entry in ENTRIES)
DEFAULT_REVEAL_AFTER = 3  # failed checks before the reference solution may be shown
T = TypeVar("T")


class ExerciseError(LessonError):
    """An exercise file that does not follow the schema; names the file and field."""


@dataclass(frozen=True)
class Mistake:
    """A plausible wrong solution and the words its failing result must contain."""

    path: Path
    reason: str


@dataclass(frozen=True)
class Exercise:
    slug: str
    unit: int
    lesson_id: str
    title: str
    node: str  # the ROS node the learner's program must create
    statement: str  # Markdown
    starter: str
    reference: str
    hints: tuple[str, ...]
    checks: tuple[Spec, ...]
    probes: tuple[Spec, ...]
    setup: tuple[str, ...] = ()  # catalog nodes started before grading
    reveal_after: int = DEFAULT_REVEAL_AFTER
    timed: bool = False  # has probes that wait on purpose (the bench leaves these out)
    mistakes: tuple[Mistake, ...] = ()
    path: Path = LESSONS_DIR
    # The statement's example as data (never the tested input): the test suite
    # generates a solution that replays it, and that solution must fail.
    example: dict[str, object] = field(default_factory=dict)
    # A package exercise: the learner's ROS package of this name is graded; the
    # grader builds it with colcon, then `ros2 run package run` or `ros2 launch
    # package launch` (app.exercises.package_grading). Starter, reference and
    # mistakes are then package folders; ``starter``/``reference`` hold their text.
    package: str = ""
    run: str = ""
    launch: str = ""
    starter_dir: Path | None = None
    reference_dir: Path | None = None
    main_file: str = ""  # the node's module inside the package, e.g. py_doubler/doubler.py

    @property
    def is_package(self) -> bool:
        return bool(self.package)

    @property
    def program_name(self) -> str:
        """The supervisor's key for the learner's process."""
        return f"exercise:{self.slug}"


def _field(
    data: Mapping[str, object], key: str, kind: type[T], where: str, default: T | None = None
) -> T:
    if key not in data:
        if default is None:
            raise ExerciseError(f"{where}: missing field '{key}'")
        return default
    value = data[key]
    if not isinstance(value, kind) or (isinstance(value, bool) and kind is not bool):
        raise ExerciseError(f"{where}: field '{key}' must be {kind.__name__}")
    return value


def _probe(raw: object, where: str) -> Spec:
    if not isinstance(raw, dict) or not isinstance(raw.get("kind"), str):
        raise ExerciseError(f"{where}: a probe is a table with a 'kind'")
    kind = raw["kind"]
    if kind not in PROBE_KINDS:
        raise ExerciseError(f"{where}: unknown probe kind '{kind}' (known: {sorted(PROBE_KINDS)})")
    fields = {k: v for k, v in raw.items() if k != "kind"}
    required, optional = PROBE_KINDS[kind].required, PROBE_KINDS[kind].optional
    missing = required - fields.keys()
    if missing:
        raise ExerciseError(f"{where}: probe '{kind}' needs field '{sorted(missing)[0]}'")
    unknown = fields.keys() - required - optional
    if unknown:
        raise ExerciseError(f"{where}: probe '{kind}' has unknown field '{sorted(unknown)[0]}'")
    # The kind's defaults (its ranges among them) fill in what the file leaves out.
    return Spec(kind, {**copy.deepcopy(PROBES[kind].defaults), **fields})


def load_exercise(directory: Path) -> Exercise:
    lesson_dir = directory.parent.parent
    match = _LESSON_DIR.match(lesson_dir.name)
    where = f"{lesson_dir.name}/exercises/{directory.name}/exercise.toml"
    if not match or not _SLUG.match(directory.name):
        raise ExerciseError(f"{where}: exercise folders are lowercase words joined by '_'")
    try:
        data = tomllib.loads((directory / "exercise.toml").read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ExerciseError(f"{where}: file missing") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ExerciseError(f"{where}: not valid TOML ({exc})") from None
    node = _field(data, "node", str, where)
    if not _NODE.match(node):
        raise ExerciseError(f"{where}: 'node' must be a ROS node name such as /counter")
    setup = tuple(_field(data, "setup", list, where, []))
    for name in setup:
        if name not in _CATALOG:
            raise ExerciseError(f"{where}: setup names no catalog node '{name}'")
    hints = tuple(_field(data, "hints", list, where))
    if not hints or not all(isinstance(h, str) for h in hints):
        raise ExerciseError(f"{where}: 'hints' must list at least one string")
    checks = tuple(
        parse_spec(raw, CHECK_KINDS, f"{where}: checks[{i}]", learner_node=node)
        for i, raw in enumerate(_field(data, "checks", list, where, []))
    )
    probes = tuple(
        _probe(raw, f"{where}: probes[{i}]")
        for i, raw in enumerate(_field(data, "probes", list, where, []))
    )
    if not checks and not probes:
        raise ExerciseError(f"{where}: an exercise needs at least one check or probe")
    package = _field(data, "package", str, where, "")
    find = _package_folder if package else inside
    mistakes = []
    for i, raw in enumerate(_field(data, "mistakes", list, where, [])):
        mistake_where = f"{where}: mistakes[{i}]"
        if not isinstance(raw, dict):
            raise ExerciseError(f"{mistake_where}: must be a table")
        path = find(directory, _field(raw, "file", str, mistake_where), mistake_where)
        mistakes.append(Mistake(path, _field(raw, "reason", str, mistake_where)))
    folders: dict[str, Path] = {}

    def text(key: str) -> str:
        name = _field(data, key, str, where)
        if package and key in ("starter", "reference"):
            folders[key] = _package_folder(directory, name, f"{where}: {key}")
            return package_text(folders[key])
        return inside(directory, name, f"{where}: {key}").read_text(encoding="utf-8")

    run, launch, main_file = (
        _field(data, k, str, where, "") for k in ("run", "launch", "main_file")
    )
    if package and (not _PACKAGE.match(package) or bool(run) == bool(launch) or not main_file):
        raise ExerciseError(
            f"{where}: a package exercise names a valid package, exactly one of 'run' "
            "(an executable) or 'launch' (a launch file), and its 'main_file'"
        )
    if not package and (run or launch or main_file):
        raise ExerciseError(f"{where}: 'run', 'launch' and 'main_file' need 'package'")

    return Exercise(
        slug=directory.name,
        unit=int(match.group(1)),
        lesson_id=lesson_dir.name,
        title=_field(data, "title", str, where),
        node=node,
        statement=text("statement"),
        starter=text("starter"),
        reference=text("reference"),
        hints=hints,
        checks=checks,
        probes=probes,
        setup=setup,
        reveal_after=_field(data, "reveal_after", int, where, DEFAULT_REVEAL_AFTER),
        timed=_field(data, "timed", bool, where, False),
        mistakes=tuple(mistakes),
        path=directory,
        example=dict(_field(data, "example", dict, where, {})),
        package=package,
        run=run,
        launch=launch,
        starter_dir=folders.get("starter"),
        reference_dir=folders.get("reference"),
        main_file=main_file,
    )


_PACKAGE = re.compile(r"^[a-z][a-z0-9_]*$")
_SKIPPED = {"build", "install", "log", "__pycache__"}


def _package_folder(base: Path, relative: str, where: str) -> Path:
    """A package folder of the exercise (it holds package.xml), inside the exercise."""
    candidate = (base / relative).resolve()
    if not candidate.is_relative_to(base.resolve()):
        raise ExerciseError(f"{where}: path '{relative}' leaves {base.name}/")
    if not (candidate / "package.xml").is_file():
        raise ExerciseError(f"{where}: '{relative}' is not a package folder (no package.xml)")
    return candidate


def package_files(folder: Path) -> list[Path]:
    """The package's text files, sorted, without build products."""
    return sorted(
        p for p in folder.rglob("*")
        if p.is_file() and not _SKIPPED & set(p.relative_to(folder).parts)
    )  # fmt: skip


def package_text(folder: Path) -> str:
    """A package folder as one text: each file under a line naming it."""
    parts = []
    for path in package_files(folder):
        body = path.read_text(encoding="utf-8", errors="replace")
        parts.append(f"# ==== {folder.name}/{path.relative_to(folder)} ====\n{body}")
    return "\n".join(parts)


@dataclass(frozen=True)
class ExerciseBook:
    """Every valid exercise, in course order; errors for the broken ones."""

    exercises: tuple[Exercise, ...]
    errors: tuple[str, ...] = ()

    def get(self, slug: str) -> Exercise:
        for exercise in self.exercises:
            if exercise.slug == slug:
                return exercise
        known = ", ".join(e.slug for e in self.exercises)
        raise ExerciseError(f"no exercise '{slug}' (known: {known})")

    def for_lesson(self, lesson_id: str) -> list[Exercise]:
        return [e for e in self.exercises if e.lesson_id == lesson_id]


def load_exercises(root: Path = LESSONS_DIR) -> ExerciseBook:
    exercises: list[Exercise] = []
    errors: list[str] = []
    for directory in sorted(root.glob("[0-9][0-9]_*/exercises/*")):
        if not directory.is_dir() or directory.name.startswith((".", "_")):
            continue
        try:
            exercises.append(load_exercise(directory))
        except LessonError as exc:
            errors.append(str(exc))
    slugs = [e.slug for e in exercises]
    duplicates = {s for s in slugs if slugs.count(s) > 1}
    if duplicates:
        errors.append(f"exercise names used twice: {', '.join(sorted(duplicates))}")
    return ExerciseBook(tuple(exercises), tuple(errors))

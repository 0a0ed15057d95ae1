"""Lesson files: ``lessons/NN_slug/lesson.toml`` plus Markdown, validated at load.

A broken lesson gives a ``LessonError`` naming the file and the field; the
loader keeps the rest of the course. Lessons are data only: the action and
check kinds they may name are registered in ``app.lessons.kinds`` and
implemented in ``app.lessons.runtime``; the catalog nodes, ROS node names and
tabs they name are checked against the product at load.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar, overload

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib

from app import PROJECT_ROOT
from app.catalog import ENTRIES, GROUPS
from app.lessons.kinds import ACTION_KINDS, CHECK_KINDS, Kind
from app.ros.runtime import DASHBOARD_NODE_NAME
from app.stage import DEFAULT_STAGE, STAGES
from app.ui import TAB_NAMES

LESSONS_DIR = PROJECT_ROOT / "lessons"
# The course's diagrams (drawn by tools/make_diagrams.py); a step names one by file name.
STATIC_DIR = PROJECT_ROOT / "static"
IMAGE_TYPES = {".svg": "image/svg+xml", ".png": "image/png"}
_DIR_PATTERN = re.compile(r"^(\d{2})_[a-z0-9_]+$")


# In an exercise's checks, the catalog name of the learner's own program.
LEARNER_PROGRAM = "learner"


class LessonError(ValueError):
    """A lesson file that does not follow the schema; the message names file and field."""


@dataclass(frozen=True)
class Spec:
    """An action or a check: its kind and its validated fields."""

    kind: str
    fields: dict[str, Any]  # TOML values, checked by kind: each kind reads its own fields

    def __getitem__(self, key: str) -> Any:
        return self.fields[key]

    def get(self, key: str, default: object = None) -> Any:
        return self.fields.get(key, default)

    @property
    def key(self) -> str:
        """Stable identity, used to remember answers and results."""
        return self.kind + ":" + ",".join(f"{k}={self.fields[k]}" for k in sorted(self.fields))


@dataclass(frozen=True)
class Step:
    title: str
    text: str  # Markdown
    command: str = ""  # the `ros2 ...` command for the same step
    actions: tuple[Spec, ...] = ()
    checks: tuple[Spec, ...] = ()
    image: str = ""  # a file in static/, shown under the text
    image_alt: str = ""  # what the picture shows, for a screen reader (required with image)
    stage: str = ""  # what the centre of the screen shows; "" = the unit's stage
    code: tuple[str, ...] = ()  # project files this step is about; () = the lesson's code


@dataclass(frozen=True)
class Lesson:
    id: str  # directory name, e.g. "04_first_node"
    unit: int  # its number in course order (1..N): the folder's prefix
    title: str
    summary: str
    goals: tuple[str, ...]
    steps: tuple[Step, ...]
    code: tuple[str, ...] = ()  # project-relative source files shown beside the text
    stage: str = DEFAULT_STAGE  # what the centre of the screen shows (app.stage.STAGES)
    path: Path = field(default=LESSONS_DIR, compare=False)

    @property
    def programs(self) -> frozenset[str]:
        """The catalog programs this lesson's buttons start or stop (by catalog name)."""
        return frozenset(
            str(action.fields["catalog_node"])
            for step in self.steps
            for action in step.actions
            if "catalog_node" in action.fields
        )


@dataclass(frozen=True)
class Course:
    lessons: tuple[Lesson, ...]
    errors: tuple[str, ...] = ()

    def lesson(self, lesson_id: str) -> Lesson | None:
        return next((lesson for lesson in self.lessons if lesson.id == lesson_id), None)


T = TypeVar("T")


@overload
def _require(table: Mapping[str, object], key: str, kind: type[T], where: str) -> T: ...


@overload
def _require(
    table: Mapping[str, object], key: str, kind: tuple[type, ...], where: str
) -> object: ...


def _require(
    table: Mapping[str, object], key: str, kind: type | tuple[type, ...], where: str
) -> object:
    if key not in table:
        raise LessonError(f"{where}: missing field '{key}'")
    value = table[key]
    if not isinstance(value, kind) or isinstance(value, bool) and kind is not bool:
        names = kind.__name__ if isinstance(kind, type) else " or ".join(k.__name__ for k in kind)
        raise LessonError(f"{where}: field '{key}' must be {names}, got {type(value).__name__}")
    return value


_CATALOG_NAMES = frozenset(entry.name for entry in ENTRIES)
_GROUP_NAMES = frozenset(group.name for group in GROUPS)
# Every ROS node name a lesson can expect on the graph: what catalog entries create.
_ROS_NODE_NAMES = frozenset({entry.node_name for entry in ENTRIES} | {f"/{DASHBOARD_NODE_NAME}"})


def _check_names(
    kind: str, fields: Mapping[str, object], where: str, learner_node: str | None
) -> None:
    """Names a lesson uses must exist in the product it runs in.

    In an exercise, ``learner_node`` is the ROS node the learner's program
    creates, and ``catalog_node = "learner"`` names that program.
    """
    if learner_node is not None:
        if fields.get("catalog_node") == LEARNER_PROGRAM or fields.get("node") == learner_node:
            return
    if "catalog_node" in fields and fields["catalog_node"] not in _CATALOG_NAMES:
        raise LessonError(
            f"{where}: no catalog node '{fields['catalog_node']}' (see the Nodes tab)"
        )
    if "group" in fields and fields["group"] not in _GROUP_NAMES:
        raise LessonError(f"{where}: no launch group '{fields['group']}'")
    if "node" in fields and fields["node"] not in _ROS_NODE_NAMES:
        raise LessonError(
            f"{where}: no catalog entry creates the ROS node '{fields['node']}' "
            "(a ROS node name starts with '/'; catalog names go in 'catalog_node')"
        )
    if kind == "console" and not (
        isinstance(fields["command"], str)
        and fields["command"].startswith("ros2 ")
        and "\n" not in fields["command"]
    ):
        raise LessonError(f"{where}: a console command is one line that starts with 'ros2 '")
    if kind == "open_panel" and fields["panel"] not in TAB_NAMES:
        raise LessonError(
            f"{where}: there is no tab '{fields['panel']}' (tabs: {', '.join(TAB_NAMES)})"
        )


def parse_spec(
    raw: object, table: dict[str, Kind], where: str, learner_node: str | None = None
) -> Spec:
    """One action or check table, validated against the registry and the product."""
    if not isinstance(raw, dict):
        raise LessonError(f"{where}: must be a table, got {type(raw).__name__}")
    kind = _require(raw, "kind", str, where)
    if kind not in table:
        raise LessonError(f"{where}: unknown kind '{kind}' (known: {', '.join(sorted(table))})")
    required, optional = table[kind].required, table[kind].optional
    fields = {k: v for k, v in raw.items() if k != "kind"}
    missing = required - fields.keys()
    if missing:
        raise LessonError(f"{where}: kind '{kind}' needs field '{sorted(missing)[0]}'")
    unknown = fields.keys() - required - optional
    if unknown:
        raise LessonError(f"{where}: kind '{kind}' has unknown field '{sorted(unknown)[0]}'")
    _check_names(kind, fields, where, learner_node)
    if kind == "quiz" and fields["answer"] not in fields["options"]:
        raise LessonError(f"{where}: quiz answer must be one of its options")
    return Spec(kind, fields)


def inside(base: Path, relative: str, where: str) -> Path:
    """Resolve a path from a lesson file, refusing any that leaves ``base``."""
    candidate = (base / relative).resolve()
    if not candidate.is_relative_to(base.resolve()):
        raise LessonError(f"{where}: path '{relative}' leaves {base.name}/")
    if not candidate.is_file():
        raise LessonError(f"{where}: file '{relative}' does not exist")
    return candidate


def _step_image(raw: Mapping[str, object], where: str) -> tuple[str, str]:
    """A step's optional picture: a file in static/ and the alt text it needs."""
    if "image" not in raw:
        if "image_alt" in raw:
            raise LessonError(f"{where}: field 'image_alt' given without 'image'")
        return "", ""
    image = _require(raw, "image", str, where)
    if Path(image).suffix.lower() not in IMAGE_TYPES:
        raise LessonError(
            f"{where}: field 'image' must name a {' or '.join(IMAGE_TYPES)} file, got '{image}'"
        )
    inside(STATIC_DIR, image, f"{where}.image")
    alt = _require(raw, "image_alt", str, where) if "image_alt" in raw else ""
    if not alt.strip():
        raise LessonError(f"{where}: field 'image_alt' must describe the picture '{image}'")
    return image, alt.strip()


def _stage(table: Mapping[str, object], where: str, default: str) -> str:
    """The optional ``stage`` field: one of the names the stage knows."""
    if "stage" not in table:
        return default
    stage = _require(table, "stage", str, where)
    if stage not in STAGES:
        raise LessonError(f"{where}: unknown stage '{stage}' (stages: {', '.join(STAGES)})")
    return str(stage)


def load_lesson(directory: Path) -> Lesson:
    toml_path = directory / "lesson.toml"
    where = f"{directory.name}/lesson.toml"
    try:
        data = tomllib.loads(toml_path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise LessonError(f"{where}: file missing") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise LessonError(f"{where}: not valid TOML ({exc})") from None
    if "unit" in data:
        raise LessonError(f"{where}: 'unit' is gone: a lesson's number is its folder's prefix")
    match = _DIR_PATTERN.match(directory.name)
    unit = int(match.group(1)) if match else 0
    title = _require(data, "title", str, where)
    summary = _require(data, "summary", str, where)
    goals = _require(data, "goals", list, where)
    if not all(isinstance(goal, str) for goal in goals):
        raise LessonError(f"{where}: field 'goals' must be a list of strings")
    code = _code_list(data, where)
    stage = _stage(data, where, DEFAULT_STAGE)
    raw_steps = _require(data, "steps", list, where)
    if not raw_steps:
        raise LessonError(f"{where}: field 'steps' must list at least one step")
    steps = []
    for i, raw in enumerate(raw_steps):
        step_where = f"{where}: steps[{i}]"
        if not isinstance(raw, dict):
            raise LessonError(f"{step_where}: must be a table")
        text_file = _require(raw, "text", str, step_where)
        text = inside(directory, text_file, f"{step_where}.text").read_text(encoding="utf-8")
        actions = [
            parse_spec(a, ACTION_KINDS, f"{step_where}.actions[{j}]")
            for j, a in enumerate(_require(raw, "actions", list, step_where))
        ] if "actions" in raw else []  # fmt: skip
        checks = [
            parse_spec(c, CHECK_KINDS, f"{step_where}.checks[{j}]")
            for j, c in enumerate(_require(raw, "checks", list, step_where))
        ] if "checks" in raw else []  # fmt: skip
        command = _require(raw, "command", str, step_where) if "command" in raw else ""
        image, image_alt = _step_image(raw, step_where)
        step_stage = _stage(raw, step_where, "")
        if (step_stage or stage) == "picture" and not image:
            raise LessonError(f"{step_where}: its stage is the step's diagram, but it has no image")
        steps.append(
            Step(
                title=_require(raw, "title", str, step_where),
                text=text,
                command=command,
                actions=tuple(actions),
                checks=tuple(checks),
                image=image,
                image_alt=image_alt,
                stage=step_stage,
                code=_code_list(raw, step_where),
            )
        )
    return Lesson(
        id=directory.name,
        unit=unit,
        title=title,
        summary=summary,
        goals=tuple(goals),
        steps=tuple(steps),
        code=tuple(code),
        stage=stage,
        path=directory,
    )


# A ``code`` entry ``launch/<group>.launch.py`` is a catalog launch group's launch file,
# which the classroom writes for ``ros2 launch`` (app/launch.py), not a project file.
LAUNCH_CODE = re.compile(r"launch/(?P<group>[A-Za-z0-9_]+)\.launch\.py")


def _code_list(raw: Mapping[str, object], where: str) -> tuple[str, ...]:
    """A lesson's or a step's ``code``: project files, each checked to exist inside it, or a
    launch group's launch file (``launch/<group>.launch.py``)."""
    code = _require(raw, "code", list, where) if "code" in raw else []
    for i, source in enumerate(code):
        if not isinstance(source, str):
            raise LessonError(f"{where}: code[{i}] must be a string")
        launch = LAUNCH_CODE.fullmatch(source)
        if launch is None:
            inside(PROJECT_ROOT, source, f"{where}: code[{i}]")
        elif launch["group"] not in _GROUP_NAMES:
            raise LessonError(f"{where}: code[{i}]: no launch group '{launch['group']}'")
    return tuple(code)


def load_course(root: Path = LESSONS_DIR) -> Course:
    """Every valid lesson under ``root``, sorted by directory; errors for the rest."""
    lessons: list[Lesson] = []
    errors: list[str] = []
    folders = sorted(p for p in root.iterdir() if p.is_dir()) if root.is_dir() else []
    folders = [p for p in folders if _DIR_PATTERN.match(p.name)]
    for directory in folders:
        try:
            lessons.append(load_lesson(directory))
        except LessonError as exc:
            errors.append(str(exc))
    numbers = [int(p.name[:2]) for p in folders]
    if numbers != list(range(1, len(numbers) + 1)):
        # The picker, the position line and the teacher's view all show this number.
        errors.append(f"lesson folders must be numbered 01..{len(numbers):02d} in course order")
    return Course(tuple(lessons), tuple(errors))

"""How a graded attempt's folder is named and what its metadata says, without ROS.

A grading leaves ``<attempts>/<exercise>/<UTC time>[-n][-seed<N>]-<verdict>``
(``-n``: a second grading within the same second; the folder ends in
``.recording`` until the grading is over), with the grader's verdict and
result lines in the bag's ``metadata.yaml`` (rosbag2's ``custom_data``) and
the code that was graded beside it. The dashboard writes these folders
(app/exercises/attempts.py, which needs rclpy to record); the teacher's side
and the hub read them (app/teacher/attempt_files.py) where no ROS is
installed. Both use this module, so the two can never disagree on a name.

It imports nothing of ROS, and nothing of app.exercises but itself.
"""

from __future__ import annotations

import calendar
import json
import re
import shlex
import time
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import yaml

ATTEMPTS_FOLDER = "attempts"  # in the learner's bags folder
UNFINISHED = ".recording"  # a folder's suffix until its grading ended
CUSTOM_PREFIX = "classroom."  # of our keys in the bag's custom_data
STAMP_FORMAT = "%Y%m%d-%H%M%S"  # UTC
VERDICTS = ("pass", "fail", "problem")
# The code that was graded, kept in the attempt's folder: GRADED_FILE for a
# one-file exercise, GRADED_PACKAGE/<package>/ for a package exercise.
GRADED_FILE = "graded.py"
GRADED_PACKAGE = "graded"

_NAME = re.compile(r"(\d{8}-\d{6})(?:-\d+)?(?:-seed(\d+))?-(pass|fail|problem)")
_STAMP = re.compile(r"\d{8}-\d{6}")


def verdict_of(passed: bool, problem: str) -> str:
    """The verdict word a folder ends in."""
    return "problem" if problem else ("pass" if passed else "fail")


def unfinished_names(when: float | None = None) -> Iterable[str]:
    """Names for a grading starting at ``when`` (now), in the order to try: the plain
    stamp first, then ``-2``, ``-3`` ... for gradings within the same second."""
    stamp = time.strftime(STAMP_FORMAT, time.gmtime(when))
    yield f"{stamp}{UNFINISHED}"
    for n in range(2, 100):
        yield f"{stamp}-{n}{UNFINISHED}"


def finished_name(unfinished: str, seed: int | None, verdict: str) -> str:
    """The final name of a folder once its grading gave ``verdict``."""
    name = unfinished.removesuffix(UNFINISHED)
    return f"{name}{'' if seed is None else f'-seed{seed}'}-{verdict}"


_ORDER = re.compile(r"(\d{8}-\d{6})(?:-(\d+))?")


def age_order(name: str) -> tuple[str, int, str]:
    """Sorts attempt folders oldest first: a second grading within the same second
    (``-2``) after the first, which a plain sort of the names does not do
    ("-2-seed..." sorts before "-seed...")."""
    found = _ORDER.match(name)
    if found is None:
        return (name, 0, name)
    return (found.group(1), int(found.group(2) or 1), name)


@dataclass(frozen=True)
class FolderName:
    """What a finished attempt's folder name tells."""

    at: float  # when the grading started, UTC seconds
    seed: int | None  # None: no seed kept
    verdict: str  # "pass", "fail" or "problem"


def parse_name(name: str) -> FolderName | None:
    """A finished attempt's name read back; None for anything else."""
    found = _NAME.fullmatch(name)
    if found is None:
        return None
    stamp, seed, verdict = found.groups()
    at = float(calendar.timegm(time.strptime(stamp, STAMP_FORMAT)))
    return FolderName(at, None if seed is None else int(seed), verdict)


@dataclass(frozen=True)
class ResultLine:
    """One check or probe as the bag's metadata keeps it."""

    name: str
    passed: bool
    detail: str


@dataclass(frozen=True)
class KeptVerdict:
    """The grader's last line and its result lines, as the bag's metadata keeps them."""

    summary: str
    results: tuple[ResultLine, ...]


def custom_data(
    exercise: str, seed: int | None, verdict: str, summary: str, results: Iterable[ResultLine]
) -> dict[str, str]:
    """What a grading writes into its bag's ``custom_data`` (keys without CUSTOM_PREFIX).

    ``verdict`` is the folder's word; the metadata says "not graded" for a problem,
    which reads better in ``ros2 bag info``.
    """
    return {
        "exercise": exercise,
        "seed": "" if seed is None else str(seed),
        "verdict": "not graded" if verdict == "problem" else verdict,
        "summary": summary,
        "results": json.dumps(
            [{"name": r.name, "passed": r.passed, "detail": r.detail} for r in results]
        ),
    }


def read_verdict(folder: Path) -> KeptVerdict | None:
    """The verdict kept in ``folder``'s metadata.yaml; None when it cannot be read
    (a damaged bag, a recording that never ended, not an attempt)."""
    try:
        meta = yaml.safe_load((folder / "metadata.yaml").read_text(encoding="utf-8"))
        custom = meta["rosbag2_bagfile_information"].get("custom_data") or {}
        results = tuple(
            ResultLine(str(r.get("name", "")), bool(r.get("passed")), str(r.get("detail", "")))
            for r in json.loads(custom.get(CUSTOM_PREFIX + "results", "[]"))
        )
        summary = str(custom.get(CUSTOM_PREFIX + "summary", ""))
    except (OSError, ValueError, KeyError, TypeError, AttributeError, yaml.YAMLError):
        return None
    return KeptVerdict(summary, results)


def graded_code(folder: Path) -> Path | None:
    """The code an attempt graded, as kept in its folder: the file, or the package
    folder (what ``exercise check`` takes); None when none was kept."""
    single = folder / GRADED_FILE
    if single.is_file():
        return single
    try:
        packages = sorted(p for p in (folder / GRADED_PACKAGE).iterdir() if p.is_dir())
    except OSError:
        return None
    return packages[0] if len(packages) == 1 else None


def attempt_label(path: Path) -> str:
    """How a kept attempt is listed: "2026-11-29 10:15:00 UTC · fail · seed 4242", or damaged."""
    name = path.name
    stamp = name[:15]
    when = (
        time.strftime("%Y-%m-%d %H:%M:%S UTC", time.strptime(stamp, STAMP_FORMAT))
        if _STAMP.fullmatch(stamp)
        else name
    )
    if name.endswith(UNFINISHED):
        return f"{when} · damaged: its recording never ended (ros2 bag reindex repairs it)"
    parsed = parse_name(name)
    if parsed is None:
        return f"{when} · ?"
    return f"{when} · {parsed.verdict}" + ("" if parsed.seed is None else f" · seed {parsed.seed}")


def attempt_heading(path: Path) -> str:
    """What a replay of a kept attempt says first: its verdict and result lines, as kept in
    the bag's metadata ('' when they cannot be read: the bag is damaged)."""
    kept = read_verdict(path)
    if kept is None:
        return ""
    lines = "\n".join(
        f"- {'✓' if r.passed else '✗'} **{r.name}**: {r.detail}" for r in kept.results
    )
    return "\n\n".join(part for part in (f"**{kept.summary}**", lines) if part.strip("*"))


def replay_command(slug: str, code: Path | str, seed: int) -> str:
    """The command that grades ``code`` again with the hidden inputs of ``seed``
    (app/lti/pages.py writes the same for the gradebook, which cannot import this)."""
    return f"ros2-classroom exercise check {slug} {shlex.quote(str(code))} --seed {seed}"


def replay_of(folder: Path) -> str:
    """The replay command of a kept attempt, on the code it kept ('' : no seed or no code)."""
    parsed, code = parse_name(folder.name), graded_code(folder)
    if parsed is None or parsed.seed is None or parsed.verdict == "problem" or code is None:
        return ""
    return replay_command(folder.parent.name, code, parsed.seed)

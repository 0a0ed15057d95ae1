"""Every graded attempt kept as a bag: what the grader fed the learner's node and what came back.

A line such as "came within 0.21 m of the wall" is about a run the learner
never saw (the grader resets the world, runs it fast, with hidden inputs). So
each grading is recorded, as ``ros2 bag record -a`` would, into an MCAP bag
in the learner's bags folder (``attempts/<exercise>/<time>-seed<seed>-<verdict>``,
so the Console's ``ros2 bag info`` and ``ros2 bag play`` take it, and contained
learner code cannot reach it): the probes' requests and the node's answers,
``/rosout``, ``/tf``, and in the simulated world the ground truth. Its
``metadata.yaml`` carries the exercise, the seed, the verdict and each result
line (rosbag2's ``custom_data``), so ``ros2 bag info`` and any MCAP tool
(Foxglove opens the file as it is) show what was judged.

The code that was graded is kept beside the bag (``graded.py``, or the
package in ``graded/<package>/``), so ``exercise check`` can grade exactly
that again with the same seed and get the same verdict. The folder's naming
and reading live in app/exercises/attempt_folders.py (no ROS there).

Bounded: the newest ``keep`` attempts of each exercise stay, and the oldest
of all go first while the folder is over its size. Camera images and point
clouds are left out (megabytes a second; the grader judges them by what it
computes from them). A folder that cannot be written never stops a grading:
the attempt is then "not kept", with the reason.
"""

from __future__ import annotations

import json
import logging
import shutil
import threading
from dataclasses import dataclass
from pathlib import Path

from rclpy.node import Node

from app.bags.errors import BagError
from app.bags.folder import bags_dir
from app.bags.recorder import Recorder
from app.exercises import plots
from app.exercises.attempt_folders import (
    ATTEMPTS_FOLDER,
    CUSTOM_PREFIX,
    GRADED_FILE,
    GRADED_PACKAGE,
    ResultLine,
    age_order,
    custom_data,
    finished_name,
    unfinished_names,
    verdict_of,
)
from app.exercises.model import package_files
from app.exercises.report import Report
from app.ros.names import ATTEMPT_RECORDER_NODE

log = logging.getLogger(__name__)

KEEP_PER_EXERCISE = 10
CAP_BYTES = 200 * 1024 * 1024  # all attempts of one learner together
POLL_SEC = 0.25  # how soon a topic that appears during the grading is recorded
LEFT_OUT_TYPES = frozenset(
    {
        "sensor_msgs/msg/Image",
        "sensor_msgs/msg/CompressedImage",
        "sensor_msgs/msg/PointCloud2",
    }
)
MAX_CODE_BYTES = 1024 * 1024  # of the code kept with an attempt (an exercise's is a few kB)
MAX_CODE_FILES = 200
TRACES_FILE = "traces.json"  # what the probes judged over time (app/exercises/trace.py)


def attempts_root() -> Path:
    """The dashboard's attempts: a folder in the learner's bags folder."""
    return bags_dir() / ATTEMPTS_FOLDER


@dataclass(frozen=True)
class KeptAttempt:
    """Where an attempt was kept (``path``), or why it was not (``note``)."""

    path: Path | None
    note: str = ""
    plots: tuple[Path, ...] = ()  # the PNG plots of the results' traces, in the folder


class AttemptStore:
    """The attempts folder of one learner: ``<root>/<exercise>/<time>-seed<seed>-<verdict>``."""

    def __init__(
        self, root: Path, keep: int = KEEP_PER_EXERCISE, cap_bytes: int = CAP_BYTES
    ) -> None:
        self.root = root
        self.keep = max(1, keep)
        self.cap_bytes = cap_bytes

    def start(self, node: Node, slug: str) -> AttemptRecording:
        """Begin recording one grading of ``slug`` (never raises: see ``AttemptRecording``)."""
        return AttemptRecording(self, node, next_attempt_path(self.root / slug))

    def attempts(self, slug: str) -> list[Path]:
        """The kept attempts of ``slug``, oldest first (unfinished ones included)."""
        folder = self.root / slug
        if not folder.is_dir():
            return []
        return sorted((p for p in folder.iterdir() if p.is_dir()), key=lambda p: age_order(p.name))

    def prune(self, slug: str, keeping: Path) -> None:
        """Drop the oldest attempts beyond ``keep`` for ``slug``, then beyond the size cap.

        ``keeping`` (the attempt just made) goes last, and only if it alone is over the cap.
        """
        for old in self.attempts(slug)[: -self.keep]:
            _remove(old)
        every = sorted(
            (p for folder in _dirs(self.root) for p in _dirs(folder)),
            key=lambda p: (p == keeping, age_order(p.name)),
        )
        sizes = {p: _size(p) for p in every}  # each folder walked once
        total = sum(sizes.values())
        for old in every:
            if total <= self.cap_bytes:
                break
            total -= sizes[old]
            _remove(old)


class AttemptRecording:
    """One grading being recorded; ``finish(report)`` closes the bag and names it."""

    def __init__(self, store: AttemptStore, node: Node, path: Path) -> None:
        self._store = store
        self._path = path
        self._recorder: Recorder | None = None
        self._failure = ""
        self._stop = threading.Event()
        self._poller: threading.Thread | None = None
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            self._recorder = Recorder(
                node,
                path,
                all_topics=True,
                skip_types=LEFT_OUT_TYPES,
                reader_name=ATTEMPT_RECORDER_NODE,
            )
        except (OSError, BagError) as exc:
            self._failure = f"cannot record into {path.parent}: {exc}"
            return
        except Exception as exc:  # never a reason for the grading itself to fail
            log.exception("attempt recording could not start")
            self._failure = f"the recording could not start: {exc}"
            return
        self._poll_once()  # the topics already there, before the first probe sends anything
        self._poller = threading.Thread(target=self._poll_loop, name="attempt-poll", daemon=True)
        self._poller.start()

    def _poll_once(self) -> None:
        try:
            if self._recorder is not None:
                self._recorder.poll()
        except Exception:  # the graph changed under us: the next round sees it again
            log.debug("attempt recording: poll failed", exc_info=True)

    def _poll_loop(self) -> None:
        while not self._stop.wait(POLL_SEC):
            self._poll_once()

    def finish(
        self, report: Report, code: Path | None = None, package: bool = False
    ) -> KeptAttempt:
        """Write the verdict into the bag's metadata, close it and give it its final name;
        keep ``code`` (the graded file, or a file of the graded package) beside it."""
        self._stop.set()
        if self._poller is not None:
            self._poller.join(timeout=2.0)
        recorder = self._recorder
        if recorder is None:
            return KeptAttempt(None, f"attempt not kept: {self._failure}")
        for key, value in _custom_data(report).items():
            recorder.set_custom_data(CUSTOM_PREFIX + key, value)
        status = recorder.stop()
        failed = recorder.failed
        if failed:
            return KeptAttempt(None, f"attempt not kept: {failed}")
        verdict = verdict_of(report.passed, report.problem)
        final = self._path.with_name(finished_name(self._path.name, report.seed, verdict))
        try:
            self._path.rename(final)
        except OSError as exc:
            return KeptAttempt(None, f"attempt not kept: cannot name {self._path}: {exc}")
        lost_code = keep_graded_code(code, final, package=package) if code is not None else ""
        drawn = _keep_traces(report, final)
        try:
            self._store.prune(final.parent.name, final)
        except OSError as exc:
            log.warning("could not drop old attempts in %s: %s", final.parent, exc)
        if not final.exists():
            return KeptAttempt(None, f"attempt not kept: larger than {self._store.cap_bytes} bytes")
        log.info("attempt kept in %s (%d messages)", final, status.count)
        note = f"attempt kept in {final}, but not the code it graded: {lost_code}"
        return KeptAttempt(final, note if lost_code else "", plots=drawn)


def keep_graded_code(code: Path, folder: Path, *, package: bool = False) -> str:
    """Copy what was graded into the attempt's ``folder``, so the attempt can be graded
    again on exactly that code; '' once kept, else why not (never raises: a grading
    must not fail for it).

    One file goes to ``graded.py``. For a package exercise ``code`` is a file inside
    the package (the grader's own copy, the one it built): the whole package goes to
    ``graded/<package>/``, which ``exercise check`` takes as it takes the learner's.
    """
    try:
        if not package:
            if code.stat().st_size > MAX_CODE_BYTES:
                return f"{code.name} is larger than {MAX_CODE_BYTES // 1024} kB"
            shutil.copyfile(code, folder / GRADED_FILE)
            return ""
        root = next((p for p in code.parents if (p / "package.xml").is_file()), None)
        if root is None:
            return f"no package.xml above {code}"
        files = package_files(root)
        if len(files) > MAX_CODE_FILES or sum(f.stat().st_size for f in files) > MAX_CODE_BYTES:
            return (
                f"the package {root.name} has more than {MAX_CODE_FILES} files or "
                f"{MAX_CODE_BYTES // 1024} kB"
            )
        target = folder / GRADED_PACKAGE / root.name
        for path in files:
            destination = target / path.relative_to(root)
            destination.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(path, destination)
        return ""
    except Exception as exc:  # an unwritable folder, a file gone: the grading stands
        log.warning("could not keep the graded code in %s: %s", folder, exc)
        return str(exc) or type(exc).__name__


def _keep_traces(report: Report, folder: Path) -> tuple[Path, ...]:
    """The results' traces as JSON and as PNG plots beside the bag (nothing if none)."""
    traces = report.traces()
    if not traces:
        return ()
    try:
        text = json.dumps([trace.to_json() for trace in traces])
        (folder / TRACES_FILE).write_text(text, encoding="utf-8")
        return tuple(plots.save(traces, folder))
    except OSError as exc:
        log.warning("could not keep the plots of %s: %s", folder, exc)
        return ()


def _custom_data(report: Report) -> dict[str, str]:
    lines = (ResultLine(r.name, r.passed, r.detail) for r in report.results)
    verdict = verdict_of(report.passed, report.problem)
    return custom_data(report.slug, report.seed, verdict, report.summary(), lines)


def next_attempt_path(folder: Path, when: float | None = None) -> Path:
    """Where a grading starting at ``when`` (now) records: a stamp no attempt has yet.

    A stamp is taken by a recording or a finished attempt of that second alike
    (the finished name would collide): two gradings within one second get -2, -3 ...
    """
    taken = {age_order(p.name)[:2] for p in _dirs(folder)}
    names = list(unfinished_names(when))
    return folder / next((n for n in names if age_order(n)[:2] not in taken), names[-1])


def _dirs(folder: Path) -> list[Path]:
    try:
        return [p for p in folder.iterdir() if p.is_dir()]
    except OSError:
        return []


def _size(path: Path) -> int:
    try:
        return sum(f.stat().st_size for f in path.rglob("*") if f.is_file())
    except OSError:
        return 0


def _remove(path: Path) -> None:
    shutil.rmtree(path, ignore_errors=True)

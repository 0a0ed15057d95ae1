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
import time
from dataclasses import dataclass
from pathlib import Path

import yaml
from rclpy.node import Node

from app.bags.errors import BagError
from app.bags.folder import bags_dir
from app.bags.recorder import Recorder
from app.exercises import plots
from app.exercises.report import Report

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
ATTEMPTS_FOLDER = "attempts"
UNFINISHED = ".recording"  # a folder's suffix until its grading ended
CUSTOM_PREFIX = "classroom."
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
        stamp = time.strftime("%Y%m%d-%H%M%S", time.gmtime())
        folder = self.root / slug
        path = folder / f"{stamp}{UNFINISHED}"
        for n in range(2, 100):  # two gradings within one second
            if not path.exists():
                break
            path = folder / f"{stamp}-{n}{UNFINISHED}"
        return AttemptRecording(self, node, path)

    def attempts(self, slug: str) -> list[Path]:
        """The kept attempts of ``slug``, oldest first (unfinished ones included)."""
        folder = self.root / slug
        if not folder.is_dir():
            return []
        return sorted((p for p in folder.iterdir() if p.is_dir()), key=lambda p: p.name)

    def prune(self, slug: str, keeping: Path) -> None:
        """Drop the oldest attempts beyond ``keep`` for ``slug``, then beyond the size cap.

        ``keeping`` (the attempt just made) goes last, and only if it alone is over the cap.
        """
        for old in self.attempts(slug)[: -self.keep]:
            _remove(old)
        every = sorted(
            (p for folder in _dirs(self.root) for p in _dirs(folder)),
            key=lambda p: (p == keeping, p.name),
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
            self._recorder = Recorder(node, path, all_topics=True, skip_types=LEFT_OUT_TYPES)
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

    def finish(self, report: Report) -> KeptAttempt:
        """Write the verdict into the bag's metadata, close it and give it its final name."""
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
        verdict = "problem" if report.problem else ("pass" if report.passed else "fail")
        seed = f"-seed{report.seed}" if report.seed is not None else ""
        name = self._path.name.removesuffix(UNFINISHED)
        final = self._path.with_name(f"{name}{seed}-{verdict}")
        try:
            self._path.rename(final)
        except OSError as exc:
            return KeptAttempt(None, f"attempt not kept: cannot name {self._path}: {exc}")
        drawn = _keep_traces(report, final)
        try:
            self._store.prune(final.parent.name, final)
        except OSError as exc:
            log.warning("could not drop old attempts in %s: %s", final.parent, exc)
        if not final.exists():
            return KeptAttempt(None, f"attempt not kept: larger than {self._store.cap_bytes} bytes")
        log.info("attempt kept in %s (%d messages)", final, status.count)
        return KeptAttempt(final, plots=drawn)


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


def attempt_label(path: Path) -> str:
    """How a kept attempt is listed: "2026-11-29 10:15 UTC · fail · seed 4242", or damaged."""
    name = path.name
    stamp = name[:15]
    try:
        when = time.strftime("%Y-%m-%d %H:%M:%S UTC", time.strptime(stamp, "%Y%m%d-%H%M%S"))
    except ValueError:
        when = name
    if name.endswith(UNFINISHED):
        return f"{when} · damaged: its recording never ended (ros2 bag reindex repairs it)"
    parts = name[15:].split("-")
    verdict = parts[-1] if parts and parts[-1] in ("pass", "fail", "problem") else "?"
    seed = next((part[4:] for part in parts if part.startswith("seed")), "")
    return f"{when} · {verdict}" + (f" · seed {seed}" if seed else "")


def attempt_heading(path: Path) -> str:
    """What a replay of a kept attempt says first: its verdict and result lines, as kept in
    the bag's metadata ('' when they cannot be read: the bag is damaged)."""
    try:
        meta = yaml.safe_load((path / "metadata.yaml").read_text(encoding="utf-8"))
        custom = meta["rosbag2_bagfile_information"].get("custom_data") or {}
        lines = [
            f"- {'✓' if r.get('passed') else '✗'} **{r.get('name', '')}**: {r.get('detail', '')}"
            for r in json.loads(custom.get(CUSTOM_PREFIX + "results", "[]"))
        ]
    except (OSError, ValueError, KeyError, TypeError, AttributeError, yaml.YAMLError):
        return ""
    summary = custom.get(CUSTOM_PREFIX + "summary", "")
    return "\n\n".join(part for part in (f"**{summary}**", "\n".join(lines)) if part.strip("*"))


def _custom_data(report: Report) -> dict[str, str]:
    return {
        "exercise": report.slug,
        "seed": "" if report.seed is None else str(report.seed),
        "verdict": "not graded" if report.problem else ("pass" if report.passed else "fail"),
        "summary": report.summary(),
        "results": json.dumps(
            [{"name": r.name, "passed": r.passed, "detail": r.detail} for r in report.results]
        ),
    }


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

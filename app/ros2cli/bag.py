"""`ros2 bag record/info/play/reindex` (the bag work itself: app.bags).

record and play run until they end by themselves (play: the bag's end) or
are stopped: Ctrl+C on the command line, the Stop button in the Console.
They do not obey the console's few-seconds limit for streams (a recording is
meant to last), but in the browser they stop after ``CONSOLE_CAP_SEC`` at
the latest, so a forgotten recording cannot fill the disk; ``--max-duration``
(ours, not rosbag2's) stops a recording after a set time of recording: counted
from its first subscription, since discovery may take a second or more on a
busy machine and what comes before is not recorded (with nothing to subscribe
to, from the start).
"""

from __future__ import annotations

import argparse
import functools
import threading
import time
from collections.abc import Callable
from typing import ParamSpec

from app.bags.errors import BagError
from app.bags.folder import existing_path, output_path
from app.bags.info import human_size, info_lines, read_info
from app.bags.player import Player, PlayOptions, parse_remap
from app.bags.recorder import COMPRESSION_MODES, STORAGES, SUBSCRIBED, Recorder
from app.bags.repair import reindex
from app.ros.context import CallContext
from app.ros.errors import Cancelled
from app.ros2cli.common import Commands, Verb

P = ParamSpec("P")

CONSOLE_CAP_SEC = 600.0  # the browser's longest recording or playback
PROGRESS_EVERY_SEC = 5.0


def _disk_errors_as_one_line(verb: Callable[P, int]) -> Callable[P, int]:
    """A folder we may not write or a file we may not read: one line, not a traceback."""

    @functools.wraps(verb)
    def wrapped(*args: P.args, **kwargs: P.kwargs) -> int:
        try:
            return verb(*args, **kwargs)
        except OSError as exc:
            where = f" ({exc.filename})" if exc.filename else ""
            raise BagError(f"{exc.strerror or exc}{where}") from None

    return wrapped


def _log(ctx: CallContext, who: str, text: str) -> None:
    """rosbag2's log line shape: [INFO] [stamp] [rosbag2_recorder]: text."""
    ctx.write(f"[INFO] [{time.time():.9f}] [{who}]: {text}")


def _cap(ctx: CallContext, wanted: float | None) -> float | None:
    """The time limit: the one asked for, else the browser's cap (none on the CLI)."""
    if wanted is not None:
        if wanted <= 0:
            raise BagError(f"--max-duration must be positive, got {wanted:g}")
        return wanted
    return CONSOLE_CAP_SEC if ctx.limits.max_seconds is not None else None


@_disk_errors_as_one_line
def record(
    ctx: CallContext,
    topics: list[str],
    *,
    all_topics: bool = False,
    output: str | None = None,
    storage: str = "mcap",
    compression_mode: str = "none",
    compression_format: str = "zstd",
    max_duration: float | None = None,
) -> int:
    if topics and all_topics:
        raise BagError("give topics or -a, not both")
    limit = _cap(ctx, max_duration)
    path = output_path(output)
    path.parent.mkdir(parents=True, exist_ok=True)
    recorder = Recorder(
        ctx.node,
        path,
        topics,
        all_topics=all_topics,
        storage=storage,
        compression_mode=compression_mode,
        compression_format=compression_format,
    )
    who = "rosbag2_recorder"
    _log(ctx, who, f"Opened bag '{path}' ({storage}) for writing.")
    _log(ctx, who, "Listening for topics...")
    if limit is not None and max_duration is None:
        _log(ctx, who, f"Press Stop to end the recording (it ends by itself after {limit:g} s).")
    started = time.monotonic()
    next_progress = started + PROGRESS_EVERY_SEC
    announced = False
    recording_since: float | None = None  # the first subscription: --max-duration counts from it
    try:
        while limit is None or time.monotonic() - (recording_since or started) < limit:
            for line in recorder.poll():
                if (
                    recording_since is None
                    and max_duration is not None
                    and line.startswith(SUBSCRIBED)
                ):
                    recording_since = time.monotonic()
                if line.startswith("[WARN]"):
                    ctx.write(line)
                else:
                    _log(ctx, who, line)
            if recorder.failed:
                break
            if not announced and topics and not recorder.missing_topics():
                _log(ctx, who, "All requested topics are subscribed. Recording...")
                announced = True
            if time.monotonic() >= next_progress:
                status = recorder.status()
                _log(
                    ctx,
                    who,
                    f"{status.count} messages recorded ({human_size(status.size)}) "
                    f"in {status.duration:.0f} s",
                )
                next_progress += PROGRESS_EVERY_SEC
            ctx.sleep(0.25)
    except Cancelled:
        pass  # Stop / Ctrl+C is how a recording normally ends
    finally:
        status = recorder.stop()
    for topic in recorder.missing_topics():
        ctx.write(f"[WARN] nothing was published on {topic}: it is not in the bag")
    if status.failure:
        ctx.write(f"error: {status.failure}")
        return 1
    per_topic = ", ".join(f"{t.topic}: {t.count}" for t in status.topics) or "no topics"
    _log(ctx, who, "Recording stopped")
    ctx.write(
        f"Recorded {status.count} messages in {status.duration:.1f} s into {path} "
        f"({human_size(status.size)}; {per_topic})"
    )
    return 0


@_disk_errors_as_one_line
def info(ctx: CallContext, path: str) -> int:
    for line in info_lines(read_info(existing_path(path))):
        ctx.write(line)
    return 0


@_disk_errors_as_one_line
def play(
    ctx: CallContext,
    path: str,
    *,
    rate: float = 1.0,
    loop: bool = False,
    start_offset: float = 0.0,
    topics: list[str] | None = None,
    remap: list[str] | None = None,
    delay: float = 0.0,
) -> int:
    options = PlayOptions(
        rate=rate,
        loop=loop,
        start_offset=start_offset,
        topics=tuple(topics or ()),
        remap=parse_remap(remap or []),
        delay=delay,
    )
    player = Player(ctx.node, existing_path(path), options)
    who = "rosbag2_player"
    limit = _cap(ctx, None)
    timer: threading.Timer | None = None
    try:
        _log(ctx, who, f"Set rate to {rate:g}")
        _log(ctx, who, f"Playing {', '.join(player.topics) or 'nothing'}")
        if limit is not None:
            # The browser's cap: end a forgotten loop as the Stop button would.
            timer = threading.Timer(limit, ctx.cancel.set)
            timer.daemon = True
            timer.start()

        def on_loop(loops: int) -> None:
            if loop:
                _log(ctx, who, f"Reached the end of the bag (pass {loops}); playing it again")

        try:
            done = player.run(ctx.cancel, on_loop)
        except Cancelled:
            done = player.progress()
            _log(ctx, who, "Playback stopped")
        ctx.write(
            f"Published {done.published} messages "
            f"({done.position:.1f} s of {done.duration:.1f} s of the bag)"
        )
    finally:
        if timer is not None:
            timer.cancel()
        player.close()
    return 0


@_disk_errors_as_one_line
def reindex_verb(ctx: CallContext, path: str) -> int:
    ctx.write(reindex(existing_path(path)))
    return 0


def add_verbs(verbs: Commands, verb: Verb) -> None:
    """The `ros2 bag ...` verbs, registered on the parser's `bag` group."""
    p = verb(
        verbs,
        "record",
        "record topics into a bag",
        lambda c, a: record(
            c,
            a.topics,
            all_topics=a.all,
            output=a.output,
            storage=a.storage,
            compression_mode=a.compression_mode,
            compression_format=a.compression_format,
            max_duration=a.max_duration,
        ),
    )
    p.add_argument("topics", nargs="*", help="topics to record")
    p.add_argument("-a", "--all", action="store_true", help="record every topic")
    p.add_argument("-o", "--output", help="bag folder name (default rosbag2_<date>-<time>)")
    p.add_argument("-s", "--storage", choices=sorted(STORAGES), default="mcap")
    p.add_argument("--compression-mode", choices=sorted(COMPRESSION_MODES), default="none")
    p.add_argument("--compression-format", choices=["zstd"], default="zstd")
    p.add_argument(
        "--max-duration",
        type=float,
        default=None,
        help="stop after recording this many seconds (from the first subscription; ours)",
    )
    p = verb(verbs, "info", "what a bag holds", lambda c, a: info(c, a.bag_path))
    p.add_argument("bag_path")
    p = verb(
        verbs,
        "play",
        "publish a bag's messages again",
        lambda c, a: play(
            c,
            a.bag_path,
            rate=a.rate,
            loop=a.loop,
            start_offset=a.start_offset,
            topics=a.topics,
            remap=a.remap,
            delay=a.delay,
        ),
    )
    p.add_argument("bag_path")
    p.add_argument("-r", "--rate", type=float, default=1.0, help="speed factor (default 1)")
    p.add_argument("-l", "--loop", action="store_true", help="play again and again")
    p.add_argument("--start-offset", type=float, default=0.0, help="skip the first S seconds")
    p.add_argument("--topics", nargs="+", default=None, help="play only these topics")
    p.add_argument("--remap", "-m", nargs="+", default=None, help="/from:=/to")
    p.add_argument("-d", "--delay", type=float, default=0.0, help="wait S seconds first")
    p = verb(verbs, "reindex", "repair a bag whose recording was killed", _reindex_handler)
    p.add_argument("bag_path")


def _reindex_handler(ctx: CallContext, args: argparse.Namespace) -> int:
    return reindex_verb(ctx, args.bag_path)


NO_DDS_VERBS = ("info", "reindex")  # read files only: the CLI makes no ROS participant

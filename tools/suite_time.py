"""Where a test run's time went: per worker, per folder and per module, wall and CPU.

Each worker of ``tests/run.py`` writes a timeline (``test-artifacts/gwN/timeline.txt``,
tests/conftest.py): when each test started and ended, and the CPU seconds its process
tree took. This reads them and answers the two questions that decide what to make
faster. Is the run bound by the cores (the tests' CPU over what the cores could give in
the run's span, near 100 %) or by waiting (far below)? And which tests cost the most
CPU, or hold a worker longest?

``python tools/suite_time.py [ARTIFACTS] [--top N]`` (ARTIFACTS: test-artifacts by
default). A timeline grows with every run in the same checkout: read a fresh clone's,
or remove test-artifacts before the run.
"""

from __future__ import annotations

import argparse
import os
import re
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path

LINE = re.compile(r"^(\d\d):(\d\d):(\d\d) (start|end  |waited) (.*)$")
END = re.compile(r"^(\S+)(?: cpu ([\d.]+))?")
WAIT = re.compile(r"^(\d+) s for a core's slot")


@dataclass
class Test:
    worker: str
    nodeid: str
    start: int  # seconds of the day
    end: int
    cpu: float  # the test's process tree, seconds (0 where the timeline has no figure)

    @property
    def wall(self) -> int:
        return self.end - self.start


@dataclass
class Worker:
    name: str
    tests: list[Test]
    slot_wait: int  # seconds spent waiting for a heavy test's slot (tests/heavy_slots.py)


def read_worker(path: Path) -> Worker:
    """One worker's timeline. A day boundary in the run is taken as one (times go back)."""
    tests, started, slot_wait, day = [], {}, 0, 0
    last = -1
    for raw in path.read_text(encoding="utf-8", errors="replace").splitlines():
        match = LINE.match(raw)
        if not match:
            continue  # a hang watchdog's stack dump, or a line cut by a crash
        hours, minutes, seconds, kind, rest = match.groups()
        at = int(hours) * 3600 + int(minutes) * 60 + int(seconds) + day
        if at < last:
            day += 86400
            at += 86400
        last = at
        if kind == "start":
            started[rest.rsplit(" load ", 1)[0]] = at
        elif kind == "waited":
            wait = WAIT.match(rest)
            slot_wait += int(wait.group(1)) if wait else 0
        else:
            end = END.match(rest)
            if end and end.group(1) in started:
                cpu = float(end.group(2)) if end.group(2) else 0.0
                tests.append(
                    Test(path.parent.name, end.group(1), started.pop(end.group(1)), at, cpu)
                )
    return Worker(path.parent.name, tests, slot_wait)


def report(workers: list[Worker], cores: int, top: int) -> str:
    tests = [t for w in workers for t in w.tests]
    if not tests:
        return "no finished test in these timelines"
    first, last = min(t.start for t in tests), max(t.end for t in tests)
    span = max(last - first, 1)
    cpu = sum(t.cpu for t in tests)
    lines = [
        f"{len(tests)} tests over {span / 60:.1f} min on {len(workers)} workers; "
        f"their CPU {cpu:.0f} s = {100 * cpu / (span * cores):.0f} % of {cores} cores "
        "in that span (near 100 %: the run is bound by the cores, so only less CPU "
        "makes it shorter)",
        "",
        "worker  busy s  cpu s  tests  slot waits s  first-last min",
    ]
    for w in sorted(workers, key=lambda w: w.name):
        if w.tests:
            lines.append(
                f"{w.name:6} {sum(t.wall for t in w.tests):7d} {sum(t.cpu for t in w.tests):6.0f}"
                f" {len(w.tests):6d} {w.slot_wait:13d}  "
                f"{(min(t.start for t in w.tests) - first) / 60:.1f}-"
                f"{(max(t.end for t in w.tests) - first) / 60:.1f}"
            )
    for title, key in (("folder", _folder), ("module", _module)):
        groups: dict[str, list[Test]] = defaultdict(list)
        for t in tests:
            groups[key(t.nodeid)].append(t)
        lines += ["", f"by {title}, most CPU first: cpu s  wall s  tests  {title}"]
        ranked = sorted(groups.items(), key=lambda kv: -sum(t.cpu for t in kv[1]))
        for name, members in ranked[:top]:
            lines.append(
                f"{sum(t.cpu for t in members):7.0f} {sum(t.wall for t in members):7d}"
                f" {len(members):6d}  {name}"
            )
    lines += ["", "longest tests: wall s  cpu s  worker  test"]
    for t in sorted(tests, key=lambda t: -t.wall)[:top]:
        lines.append(f"{t.wall:6d} {t.cpu:6.0f}  {t.worker}  {t.nodeid}")
    return "\n".join(lines)


def _module(nodeid: str) -> str:
    return nodeid.split("::", 1)[0]


def _folder(nodeid: str) -> str:
    return _module(nodeid).rsplit("/", 1)[0]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python tools/suite_time.py")
    parser.add_argument("artifacts", nargs="?", default="test-artifacts", type=Path)
    parser.add_argument("--top", type=int, default=20, help="rows per table")
    parser.add_argument("--cores", type=int, default=os.cpu_count() or 1)
    args = parser.parse_args(argv)
    paths = sorted(args.artifacts.glob("gw*/timeline.txt"))
    if not paths:
        print(f"no worker timelines under {args.artifacts} (run `make test` first)")
        return 1
    print(report([read_worker(p) for p in paths], args.cores, args.top))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Where a test run's CPU went, by the kind of process that spent it.

``tools/suite_time.py`` says which tests cost most, each test's figure being its
whole process tree. This says which *processes* spent it: Chromium's pages, the
dashboards, the catalog nodes, the learners' programs, pytest's workers. The
kernel writes a record for every process that ends (BSD process accounting,
acct(2): its CPU seconds, start time and pid), while a thread notes each live
process's command line once a second; the two are matched on pid and start time.

    python tools/suite_cpu_by_process.py record OUT -- bash .ci/run
    python tools/suite_cpu_by_process.py report OUT [--kinds]

``record`` needs root (acct(2) wants CAP_SYS_PACCT) and counts every process of the
machine that starts while it runs, so run nothing else meanwhile. A process that ends
within a second of its start can be missed by the sampler; it is then named by the
kernel's short command name ("short-lived: NAME").
"""

from __future__ import annotations

import argparse
import ctypes
import os
import re
import struct
import subprocess
import sys
import threading
import time
from collections import Counter, defaultdict
from dataclasses import dataclass
from pathlib import Path

import psutil

# struct acct_v3 (linux/acct.h): flag, version, tty, exit code, uid, gid, pid, ppid,
# start (epoch s), elapsed (float), then eight comp_t (utime, stime, ...) and the name.
RECORD = struct.Struct("<BBHIIIIIIf8H16s")
AHZ = 100  # the ticks of comp_t times in version 3 records
ACCT_FILE, PROCESSES_FILE, START_FILE = "pacct", "processes.tsv", "started"

# Kinds into the groups the report prints, first match wins.
GROUPS = (
    ("Chromium and Playwright (browser tests' pages)", r"^(chromium|playwright)"),
    ("pytest workers (test code, in-process probes and graders)", r"^pytest"),
    ("dashboards (python -m app serve)", r"^dashboard"),
    (
        "simulated world, Nav2 and mapping nodes",
        r"nodes\.(sim_world|amcl|controller_server|bt_navigator|planner_server|map_server"
        r"|lifecycle_manager|model_state_publisher|waypoint_follower|grid_mapper|slam_node)",
    ),
    ("other catalog nodes (talker, turtlesim, tf2 demos...)", r"^python -m nodes\."),
    ("learner programs and tests' helper scripts", r"^(learner program|python \S+\.py)$"),
    ("builds (colcon, cmake, compilers, pip)", r"^build|-m pip$"),
    ("JupyterHub", r"jupyter"),
)
OTHER = "other (ros2 verbs, short-lived Python, shells...)"


@dataclass
class Ended:
    """One accounting record: a process that ended."""

    pid: int
    start: float  # epoch seconds
    cpu: float  # user + system seconds
    name: str  # the kernel's short command name


def decode_comp(value: int) -> int:
    """comp_t: a 13-bit mantissa times 8 to the power of a 3-bit exponent."""
    return (value & 0x1FFF) << (3 * (value >> 13))


def read_records(data: bytes) -> list[Ended]:
    ended = []
    for offset in range(0, len(data) - RECORD.size + 1, RECORD.size):
        fields = RECORD.unpack_from(data, offset)
        if fields[1] != 3:  # not a version 3 record: this reader does not know it
            continue
        utime, stime, name = fields[10], fields[11], fields[-1]
        cpu = (decode_comp(utime) + decode_comp(stime)) / AHZ
        text = name.split(b"\0")[0].decode(errors="replace")
        ended.append(Ended(pid=fields[6], start=float(fields[8]), cpu=cpu, name=text))
    return ended


def kind_of(command: str | None, name: str) -> str:
    """A short kind for a command line; ``name`` when the sampler never saw it."""
    if command is None:
        return f"short-lived: {name}"
    if "/chromium" in command:
        found = re.search(r"--type=([a-z-]+)", command)
        return "chromium " + (found.group(1) if found else "browser")
    if "playwright/driver" in command:
        return "playwright driver"
    if re.search(r"exec\(eval\(sys\.stdin|tests/run\.py|-m pytest", command):
        return "pytest worker or runner"
    if re.search(r"popen-gw\d+/code\d+/|/scratch/|ros2_ws/install", command):
        return "learner program"
    # Compilers, and the Python that colcon and pip start (setup.py's questions, the
    # build's file-size cap of app/learner_ws/build.py, pip's runner).
    if re.search(
        r"\b(cc1|cc1plus|g\+\+|gcc|ld|collect2|cmake|ninja|colcon)\b"
        r"|from setuptools|setup\.py|RLIMIT_FSIZE|__pip-runner__",
        command,
    ):
        return "build"
    if re.search(r"-c while True: pass$", command):
        return "busy cores (tests that load the machine on purpose)"
    words = command.split()
    if words[0].rsplit("/", 1)[-1].startswith("python"):
        return _python_kind(words[1:])
    return words[0].rsplit("/", 1)[-1]


def _python_kind(words: list[str]) -> str:
    """``python -m MODULE``, ``python SCRIPT.py`` or ``python -c``, past the options."""
    index = 0
    while index < len(words):
        word = words[index]
        if word == "-c":
            return "python -c"
        if word == "-m":
            module, rest = (words[index + 1 : index + 2] or [""])[0], words[index + 2 :]
            if module == "app":
                return "dashboard" if rest[:1] == ["serve"] else "python -m app"
            return f"python -m {module}"
        if not word.startswith("-"):
            return f"python {word.rsplit('/', 1)[-1]}"
        index += 2 if word in ("-X", "-W") else 1  # these two take a value
    return "python"


def group_of(kind: str) -> str:
    for group, pattern in GROUPS:
        if re.search(pattern, kind):
            return group
    return OTHER


def read_processes(path: Path) -> dict[int, list[tuple[float, str]]]:
    """pid -> [(start, command line)] as the sampler wrote them."""
    seen: dict[int, list[tuple[float, str]]] = defaultdict(list)
    for line in path.read_text(errors="replace").splitlines():
        parts = line.split("\t", 2)
        if len(parts) == 3:
            seen[int(parts[0])].append((float(parts[1]), parts[2]))
    return seen


def command_of(ended: Ended, seen: dict[int, list[tuple[float, str]]]) -> str | None:
    """The sampled command line of the same pid started within 2 s of the record's start
    (a record's start is whole seconds; pids are reused within a long run)."""
    for start, command in seen.get(ended.pid, []):
        if abs(start - ended.start) <= 2:
            return command
    return None


def report(out: Path, kinds: bool = False) -> str:
    started = float((out / START_FILE).read_text())
    seen = read_processes(out / PROCESSES_FILE)
    by_kind: Counter[str] = Counter()
    count: Counter[str] = Counter()
    for ended in read_records((out / ACCT_FILE).read_bytes()):
        if ended.start + 1 < started:  # began before the recording: not the run's
            continue
        kind = kind_of(command_of(ended, seen), ended.name)
        by_kind[kind] += ended.cpu
        count[kind] += 1
    total = sum(by_kind.values())
    if total <= 0:
        return "no process of the run ended with CPU time on record"
    group = {kind: group_of(kind) for kind in by_kind}
    by_group: Counter[str] = Counter()
    for kind, cpu in by_kind.items():
        by_group[group[kind]] += cpu
    lines = [f"{total:,.0f} CPU-s in {sum(count.values()):,} processes", "", "CPU s     %  group"]
    for name, cpu in by_group.most_common():
        lines.append(f"{cpu:6,.0f} {100 * cpu / total:5.1f}  {name}")
        if kinds:
            for kind, kind_cpu in by_kind.most_common():
                if group[kind] == name and kind_cpu >= 0.005 * total:
                    lines.append(f"{'':13}{kind_cpu:6,.0f}  {kind} ({count[kind]} processes)")
    return "\n".join(lines)


def _sample(path: Path, stop: threading.Event) -> None:
    """Each second, the command line of every process not noted yet (by pid and start)."""
    noted: dict[int, float] = {}
    with open(path, "a", encoding="utf-8") as out:
        while not stop.wait(1.0):
            for proc in psutil.process_iter(["cmdline", "create_time"]):
                started, words = proc.info["create_time"], proc.info["cmdline"]
                # (kernel threads, zombies and processes gone meanwhile have no words)
                if not words or started is None or noted.get(proc.pid) == started:
                    continue
                noted[proc.pid] = started
                command = re.sub(r"\s+", " ", " ".join(words))[:400].strip()
                out.write(f"{proc.pid}\t{started:.2f}\t{command}\n")
            out.flush()


def record(out: Path, command: list[str]) -> int:
    out.mkdir(parents=True, exist_ok=True)
    accounting = out / ACCT_FILE
    accounting.write_bytes(b"")
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.acct(str(accounting).encode()) != 0:
        error = os.strerror(ctypes.get_errno())
        print(f"acct(2) refused ({error}): run this as root", file=sys.stderr)
        return 2
    (out / START_FILE).write_text(f"{time.time():.2f}")
    stop = threading.Event()
    sampler = threading.Thread(target=_sample, args=(out / PROCESSES_FILE, stop), daemon=True)
    sampler.start()
    try:
        return subprocess.call(command)
    finally:
        libc.acct(None)
        stop.set()
        sampler.join(5)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    verbs = parser.add_subparsers(dest="verb", required=True)
    rec = verbs.add_parser("record", help="run COMMAND with every process accounted")
    rec.add_argument("out", type=Path)
    rec.add_argument("command", nargs=argparse.REMAINDER)
    rep = verbs.add_parser("report", help="the CPU of a recorded run by process kind")
    rep.add_argument("out", type=Path)
    rep.add_argument("--kinds", action="store_true", help="each group's kinds too")
    args = parser.parse_args(argv)
    if args.verb == "record":
        command = args.command[1:] if args.command[:1] == ["--"] else args.command
        if not command:
            parser.error("record OUT -- COMMAND...")
        return record(args.out, command)
    print(report(args.out, args.kinds))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Run the test suite inside a private network namespace that has only loopback.

DDS multicasts on every network card by default; on these machines no packet
may leave 127.0.0.0/8. ``unshare --net --map-root-user`` needs no root and
gives this process tree its own network stack with only ``lo``, which we
bring up. If that is impossible the run fails: it never falls back to the
real network.

The process that made the namespace stays as its keeper: it runs pytest (or
the benchmark, or the script) as a child, passes on SIGINT, SIGTERM and
SIGHUP, and when the child has ended, whatever way, kills every process still
in the namespace and fails the run naming them. So nothing of a run outlives
it, even when the run itself is killed (pytest dies on SIGTERM without its
teardown; a dashboard or node it started is in its own session).

pytest runs its tests in several workers at once (pytest-xdist): most of a
test's time is spent waiting (discovery, rates measured over seconds, a
grading's time limits), not computing. Each worker is started through this
file (``--worker``) in a private namespace of its own, nested in the run's:
workers cannot hear each other's DDS traffic or take each other's ports, so
domain ids and ports need no coordination between them. A worker notes its
namespace in a file the keeper reads, so the keeper ends what is left in
every namespace of the run.

Tests marked ``loaded`` take both cores on purpose, and tests marked
``alone`` need the machine's real time to themselves; they run after the
rest, one at a time, in a second pytest session (``pytest_phases``).

Usage: ``python tests/run.py [--workers N] [pytest args]`` (``make test`` does
this; ``--workers 1`` runs pytest in one process, as before); ``--bench
[names]`` runs the benchmarks, ``--script FILE [args]`` one program.
"""

from __future__ import annotations

import contextlib
import fcntl
import glob
import os
import shutil
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))  # run as a script from anywhere
from bench._reaper import end_found  # the run's reaper; it needs only the stdlib
from tests import hang_watchdog  # stdlib only, too
from tests.worker_plan import GENERAL_WORKERS, WAITING_WORKERS  # stdlib only, too

_SIOCGIFFLAGS = 0x8913
_SIOCSIFFLAGS = 0x8914
_IFF_UP = 0x1
MARKER = "CLASSROOM_PRIVATE_NETNS"
KEEPER = "CLASSROOM_NETNS_KEEPER"  # set only for the process that unshare starts
WORKER = "CLASSROOM_WORKER_NETNS"  # set only for the worker that unshare starts
NAMESPACES = "CLASSROOM_RUN_NAMESPACES"  # the file where workers note their namespaces
SLOT_SUFFIX = ".heavy"  # the heavy-test slots' files beside it: <file>.heavy0, .heavy1, ...
# How many cores the run's heavy tests may count on (tests/heavy_slots.py): the machine's,
# less those that something outside the run kept busy as it began (measured by the keeper).
FREE_CORES = "CLASSROOM_FREE_CORES"
BUSY_SAMPLE_SEC = 2.0
# Three workers on two cores, measured: the whole suite in 16-17 min instead of
# 47, a core still idle a third of the time. Four took 15 min but saturated the
# cores: eight tests that wait on real time failed (a MuJoCo run, turtlesim). So
# three take any test, and four more only tests that wait (tests/worker_plan.py).
DEFAULT_WORKERS = GENERAL_WORKERS + WAITING_WORKERS
FORWARDED = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
LOADED = "loaded"  # the mark of tests that take the cores on purpose (tests/conftest.py)
ALONE = "alone"  # ...and of tests that need the machine's real time to themselves
SECOND_PHASE = f"{LOADED} or {ALONE}"
NO_TESTS = 5  # pytest's exit code when it selected no test
GO_ON = (0, 1, NO_TESTS)  # a phase that ended so (passed, tests failed, none) lets the next run


def interfaces() -> list[str]:
    return [name for _, name in socket.if_nameindex()]


def bring_loopback_up() -> None:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        request = struct.pack("16sH", b"lo", 0)
        flags = struct.unpack("16sH", fcntl.ioctl(sock, _SIOCGIFFLAGS, request)[:18])[1]
        fcntl.ioctl(sock, _SIOCSIFFLAGS, struct.pack("16sH", b"lo", flags | _IFF_UP))


def _net_namespace(pid: int | str) -> str | None:
    try:
        return os.readlink(f"/proc/{pid}/ns/net")
    except OSError:
        return None


def _run_namespaces() -> set[str]:
    """This namespace and those its workers made (they note them in the NAMESPACES file)."""
    noted = Path(os.environ.get(NAMESPACES, "/nonexistent"))
    found = set(noted.read_text().split()) if noted.is_file() else set()
    return found | {_net_namespace("self") or "?"}


def _left_in_namespace() -> list[tuple[int, str]]:
    """(pid, command line) of every live process in the run's namespaces but this one."""
    ours, me, found = _run_namespaces(), os.getpid(), []
    for entry in Path("/proc").iterdir():
        if (
            not entry.name.isdigit()
            or int(entry.name) == me
            or _net_namespace(entry.name) not in ours
            or _another_run(entry)
        ):
            continue
        try:
            if (entry / "stat").read_text().rsplit(")", 1)[1].split()[0] == "Z":
                continue  # dead already; its parent is gone or about to reap it
            cmd = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
        except (OSError, IndexError):
            continue
        found.append((int(entry.name), cmd.strip()[:160]))
    return found


def _another_run(proc: Path) -> bool:
    """A process of another run whose namespace got a number this run's had: the kernel
    reuses a namespace's number once it is gone (seen: a run's keeper ended the workers
    of a run started beside it, and another run's keeper). A run's processes inherit
    its NAMESPACES file's name; its keeper, which names that file only after it started,
    is known by KEEPER in the environment it started with (this run's own keeper is
    this process, and it took KEEPER out before starting anything)."""
    try:
        environ = (proc / "environ").read_bytes().split(b"\0")
    except OSError:
        return False
    if f"{KEEPER}=1".encode() in environ:
        return True
    prefix = f"{NAMESPACES}=".encode()
    theirs = next((v[len(prefix) :] for v in environ if v.startswith(prefix)), None)
    return theirs is not None and theirs.decode(errors="replace") != os.environ.get(NAMESPACES)


def _cpu_ticks() -> tuple[int, int]:
    """(busy, total) ticks of every core since boot, from /proc/stat's first line."""
    with open("/proc/stat", encoding="ascii") as stat:
        fields = [int(x) for x in stat.readline().split()[1:]]
    idle = fields[3] + (fields[4] if len(fields) > 4 else 0)  # idle + iowait
    total = sum(fields[:8])  # guest time is already counted in user time
    return total - idle, total


def cores_free_of_others(sample_sec: float = BUSY_SAMPLE_SEC) -> tuple[int, float]:
    """(cores free, cores busy) as the run begins, before it has started anything: the
    busy ones are another program's (a build, a second run, a busy loop beside it). The
    heavy tests then share the free ones: ci128, one core kept busy by a loop while the
    plan counted two, ran two heavy tests beside the loop at a load of 15-22, and a fuzz
    of 22 nodes took longer than its 150 s while a talker took over 30 s to show."""
    cores = os.cpu_count() or 1
    busy0, total0 = _cpu_ticks()
    time.sleep(sample_sec)
    busy1, total1 = _cpu_ticks()
    busy = cores * (busy1 - busy0) / max(total1 - total0, 1)
    # A core counts as taken from three quarters busy: a busy loop is one, noise is none.
    return max(1, cores - int(busy + 0.25)), busy


def keep(command: list[str], quiet: bool = False) -> int:
    """Run ``command`` in this namespace, then end everything it left; its exit code."""
    out = subprocess.DEVNULL if quiet else None
    child = subprocess.Popen(command, stdout=out, stderr=out)

    def forward(signum: int, _frame: object) -> None:
        if child.poll() is None:
            child.send_signal(signum)

    for sig in FORWARDED:
        signal.signal(sig, forward)
    code = child.wait()
    killed = end_found(_left_in_namespace)
    if killed:
        print("\ntests/run.py: FAILED: processes of this run were still running (killed now):")
        print("\n".join(f"  {line}" for line in killed), flush=True)
        code = code or 1
    return code if code >= 0 else 128 - code  # a child ended by a signal, as a shell says it


def _unshare(argv: list[str]) -> None:
    """Run ``argv`` again in a new network namespace (does not return)."""
    unshare = shutil.which("unshare")
    if unshare is None:
        print("tests/run.py: error: `unshare` (util-linux) is needed", file=sys.stderr)
        raise SystemExit(1)
    # Real root keeps its own uids: the sandbox tests switch to unprivileged
    # ones, which a user namespace that maps only uid 0 cannot do. Inside the
    # run's namespace we are root already (a worker's unshare needs no mapping).
    as_user = [] if os.geteuid() == 0 else ["--map-root-user"]
    os.execv(unshare, [unshare, "--net", *as_user, *argv])


def _isolated() -> bool:
    """Bring up loopback; True when it is this namespace's only interface."""
    try:
        bring_loopback_up()
    except OSError as exc:
        print(f"tests/run.py: error: cannot bring up loopback: {exc}", file=sys.stderr)
        return False
    if interfaces() != ["lo"]:
        print(f"tests/run.py: error: not isolated, interfaces: {interfaces()}", file=sys.stderr)
        return False
    return True


def worker(python_args: list[str]) -> int:
    """An xdist worker: ``python PYTHON_ARGS`` in a namespace of its own, noted for the keeper."""
    if os.environ.pop(WORKER, None) != "1":
        os.environ[WORKER] = "1"
        _unshare([sys.executable, __file__, "--worker", *python_args])
    if not _isolated():
        return 1
    noted = os.environ.get(NAMESPACES)
    if noted:  # a run's keeper will look here; a worker started by hand has none
        with open(noted, "a", encoding="ascii") as out:
            out.write(f"{_net_namespace('self')}\n")
    os.execv(sys.executable, [sys.executable, *python_args])
    return 1  # not reached


def _take_workers(args: list[str]) -> tuple[int, list[str]]:
    """``--workers N`` out of pytest's arguments: (N, or DEFAULT_WORKERS; the rest)."""
    if "--workers" in args[:-1]:
        at = args.index("--workers")
        return int(args[at + 1]), [*args[:at], *args[at + 2 :]]
    return DEFAULT_WORKERS, list(args)


def pytest_command(args: list[str]) -> list[str]:
    """pytest with ``--workers N`` (default DEFAULT_WORKERS) turned into xdist's workers."""
    workers, args = _take_workers(args)
    command = [sys.executable, "-m", "pytest", *args]
    if workers <= 1:
        return command
    spawn = f"{workers}*popen//python={sys.executable} {Path(__file__).resolve()} --worker"
    # A worker that dies (SIGKILL) fails the run at once: a replacement worker never came up
    # (rehearsal ci79 then waited for it until killed), and xdist replaced crash after crash.
    restart = "--max-worker-restart=0"
    return [*command, "--tx", spawn, "--dist", "loadscope", restart]  # tests/worker_plan.py


def collect_ahead(args: list[str], keeper: bool) -> None:
    """Collect the tests once, in one process, before the workers start.

    Every xdist worker collects the whole suite, and on a fresh clone each
    rewrote the asserts of every test module (10 CPU-s a worker, seven workers
    on two cores at once). One collection first leaves the rewritten modules in
    __pycache__ (tests/conftest.py), and the workers read them. Whatever it
    finds wrong, the run itself reports.
    """
    workers, rest = _take_workers(args)
    if workers > 1:
        command = [sys.executable, "-m", "pytest", *rest, "--collect-only", "-q"]
        if keeper:
            keep(command, quiet=True)
        else:
            subprocess.call(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def pytest_phases(args: list[str]) -> list[list[str]]:
    """The tests in the workers, then the ``loaded`` ones alone, one at a time.

    A loaded test takes both cores on purpose (to prove a check holds on a slow
    computer); beside other workers it starved their tests of real time. A
    run that picks its own marks (``-m``) is one phase.
    """
    if any(arg == "-m" or arg.startswith("-m") and not arg.startswith("--") for arg in args):
        return [pytest_command(args)]
    _, alone = _take_workers(args)
    return [
        pytest_command([*args, "-m", f"not ({SECOND_PHASE})"]),
        pytest_command([*alone, "--workers", "1", "-m", SECOND_PHASE]),
    ]


def run_phases(commands: list[list[str]], keeper: bool) -> int:
    """Each phase in turn (after failed tests too); the first failure's code.

    pytest says 5 when a phase selected no test (a run of only loaded tests, or
    none): that is a failure only when no phase ran any.
    """
    if not keeper and len(commands) == 1:
        os.execv(sys.executable, commands[0])
    codes: list[int] = []
    timelines = _timeline_sizes()
    with tempfile.TemporaryDirectory(prefix="classroom-run-") as reports:
        for number, command in enumerate(commands):
            if codes and codes[-1] not in GO_ON:
                break  # interrupted (Ctrl+C), or pytest could not run: stop here
            if number:
                print(f"\ntests/run.py: the tests marked {SECOND_PHASE}: one at a time", flush=True)
            command = [*command, f"--junitxml={reports}/phase{number}.xml"]
            codes.append(keep(command) if keeper else subprocess.call(command))
        print_failures(sorted(Path(reports).glob("phase*.xml")))
    print_hangs(timelines)
    failed = [code for code in codes if code not in (0, NO_TESTS)]
    if failed:
        return failed[0]
    return NO_TESTS if all(code == NO_TESTS for code in codes) else 0


ARTIFACTS = Path(__file__).resolve().parent.parent / "test-artifacts"


def _timeline_sizes() -> dict[Path, int]:
    """Each worker's timeline and its size now: what a run appends is that run's."""
    return {path: path.stat().st_size for path in ARTIFACTS.glob("**/timeline.txt")}


def print_hangs(before: dict[Path, int]) -> None:
    """The stacks tests/hang_watchdog.py wrote for a test stuck in native code."""
    for path in sorted(ARTIFACTS.glob("**/timeline.txt")):
        for dump in hang_watchdog.hangs_in(hang_watchdog.new_text(path, before.get(path, 0))):
            print(f"\ntests/run.py: a test hung ({path.parent.name}):\n{dump}", flush=True)


DIGEST_CHARS = 1200  # of each failure's message: the reason, not the whole traceback


def print_failures(reports: list[Path]) -> None:
    """Every phase's failures once more, at the very end, each with its reason: a CI log
    shown by its head and tail still says what failed and why."""
    import xml.etree.ElementTree as ET

    lines: list[str] = []
    for report in reports:
        try:
            cases = ET.parse(report).getroot().iter("testcase")
        except (OSError, ET.ParseError):
            continue
        for case in cases:
            for bad in [*case.findall("failure"), *case.findall("error")]:
                name = f"{case.get('classname', '')}::{case.get('name', '')}"
                reason = (bad.get("message") or "").strip() or (bad.text or "").strip()
                lines.append(f"{bad.tag.upper()} {name}\n    {reason[:DIGEST_CHARS]}")
    if lines:
        print("\ntests/run.py: what failed, and why", *lines, sep="\n", flush=True)


def main() -> int:
    args = sys.argv[1:]
    if args[:1] == ["--worker"]:
        return worker(args[1:])
    if os.environ.get(MARKER) != "1":
        os.environ[MARKER] = os.environ[KEEPER] = "1"
        _unshare([sys.executable, *sys.argv])
    keeper = os.environ.pop(KEEPER, None) == "1"  # a run inside a run keeps nothing
    if not _isolated():
        return 1
    if args[:1] == ["--script"]:  # e.g. docs/screenshots.py: a program that needs DDS
        command = [sys.executable, *args[1:]]
    elif args[:1] == ["--bench"]:
        command = [sys.executable, "-m", "bench", *args[1:]]
    else:
        phases = pytest_phases(args)
        if not keeper:
            collect_ahead(args, keeper=False)
            return run_phases(phases, keeper=False)
        with tempfile.NamedTemporaryFile("w", prefix="classroom-run-", suffix=".netns") as noted:
            # First this run's own file: a run inside a run must not end the outer one's
            # workers when its collection ends (it inherited the outer run's file).
            os.environ[NAMESPACES] = noted.name
            if FREE_CORES not in os.environ:  # (set by hand: that figure)
                free, busy = cores_free_of_others()
                os.environ[FREE_CORES] = str(free)
                print(
                    f"tests/run.py: {busy:.1f} of {os.cpu_count()} cores busy before the run: "
                    f"heavy tests share {free}",
                    flush=True,
                )
            try:
                collect_ahead(args, keeper=True)
                return run_phases(phases, keeper=True)
            finally:
                _remove_slot_files(noted.name)
    if not keeper:
        os.execv(sys.executable, command)
    with tempfile.NamedTemporaryFile("w", prefix="classroom-run-", suffix=".netns") as noted:
        os.environ[NAMESPACES] = noted.name
        return keep(command)


def _remove_slot_files(run_file: str) -> None:
    """The heavy-test slots (tests/heavy_slots.py) are files beside the run's own: they go
    with it, or every run leaves a few in /tmp."""
    for path in glob.glob(f"{glob.escape(run_file)}{SLOT_SUFFIX}*"):
        with contextlib.suppress(OSError):
            os.unlink(path)


if __name__ == "__main__":
    raise SystemExit(main())

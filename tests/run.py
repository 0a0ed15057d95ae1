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

Usage: ``python tests/run.py [pytest args]`` (``make test`` does this);
``--bench [names]`` runs the benchmarks, ``--script FILE [args]`` one program.
"""

from __future__ import annotations

import fcntl
import os
import shutil
import signal
import socket
import struct
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))  # run as a script from anywhere
from bench._reaper import end_found  # the run's reaper; it needs only the stdlib

_SIOCGIFFLAGS = 0x8913
_SIOCSIFFLAGS = 0x8914
_IFF_UP = 0x1
MARKER = "CLASSROOM_PRIVATE_NETNS"
KEEPER = "CLASSROOM_NETNS_KEEPER"  # set only for the process that unshare starts
FORWARDED = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


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


def _left_in_namespace() -> list[tuple[int, str]]:
    """(pid, command line) of every live process in this namespace but this one."""
    ours, me, found = _net_namespace("self"), os.getpid(), []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit() or int(entry.name) == me or _net_namespace(entry.name) != ours:
            continue
        try:
            if (entry / "stat").read_text().rsplit(")", 1)[1].split()[0] == "Z":
                continue  # dead already; its parent is gone or about to reap it
            cmd = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
        except (OSError, IndexError):
            continue
        found.append((int(entry.name), cmd.strip()[:160]))
    return found


def keep(command: list[str]) -> int:
    """Run ``command`` in this namespace, then end everything it left; its exit code."""
    child = subprocess.Popen(command)

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


def main() -> int:
    args = sys.argv[1:]
    if os.environ.get(MARKER) != "1":
        unshare = shutil.which("unshare")
        if unshare is None:
            print("tests/run.py: error: `unshare` (util-linux) is needed", file=sys.stderr)
            return 1
        os.environ[MARKER] = os.environ[KEEPER] = "1"
        # Real root keeps its own uids: the sandbox tests switch to unprivileged
        # ones, which a user namespace that maps only uid 0 cannot do.
        as_user = [] if os.geteuid() == 0 else ["--map-root-user"]
        os.execv(unshare, [unshare, "--net", *as_user, sys.executable, *sys.argv])
    keeper = os.environ.pop(KEEPER, None) == "1"  # a run inside a run keeps nothing
    try:
        bring_loopback_up()
    except OSError as exc:
        print(f"tests/run.py: error: cannot bring up loopback: {exc}", file=sys.stderr)
        return 1
    if interfaces() != ["lo"]:
        print(f"tests/run.py: error: not isolated, interfaces: {interfaces()}", file=sys.stderr)
        return 1
    if args[:1] == ["--script"]:  # e.g. docs/screenshots.py: a program that needs DDS
        command = [sys.executable, *args[1:]]
    elif args[:1] == ["--bench"]:
        command = [sys.executable, "-m", "bench", *args[1:]]
    else:
        command = [sys.executable, "-m", "pytest", *args]
    if not keeper:
        os.execv(sys.executable, command)
    return keep(command)


if __name__ == "__main__":
    raise SystemExit(main())

"""Run the test suite inside a private network namespace that has only loopback.

DDS multicasts on every network card by default; on these machines no packet
may leave 127.0.0.0/8. ``unshare --net --map-root-user`` needs no root and
gives this process tree its own network stack with only ``lo``, which we
bring up. If that is impossible the run fails: it never falls back to the
real network.

Usage: ``python tests/run.py [pytest args]`` (``make test`` does this);
``--bench [names]`` runs the benchmarks, ``--script FILE [args]`` one program.
"""

from __future__ import annotations

import fcntl
import os
import shutil
import socket
import struct
import sys

_SIOCGIFFLAGS = 0x8913
_SIOCSIFFLAGS = 0x8914
_IFF_UP = 0x1
MARKER = "CLASSROOM_PRIVATE_NETNS"


def interfaces() -> list[str]:
    return [name for _, name in socket.if_nameindex()]


def bring_loopback_up() -> None:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        request = struct.pack("16sH", b"lo", 0)
        flags = struct.unpack("16sH", fcntl.ioctl(sock, _SIOCGIFFLAGS, request)[:18])[1]
        fcntl.ioctl(sock, _SIOCSIFFLAGS, struct.pack("16sH", b"lo", flags | _IFF_UP))


def main() -> int:
    args = sys.argv[1:]
    if os.environ.get(MARKER) != "1":
        unshare = shutil.which("unshare")
        if unshare is None:
            print("tests/run.py: error: `unshare` (util-linux) is needed", file=sys.stderr)
            return 1
        os.environ[MARKER] = "1"
        # Real root keeps its own uids: the sandbox tests switch to unprivileged
        # ones, which a user namespace that maps only uid 0 cannot do.
        as_user = [] if os.geteuid() == 0 else ["--map-root-user"]
        os.execv(unshare, [unshare, "--net", *as_user, sys.executable, *sys.argv])
    try:
        bring_loopback_up()
    except OSError as exc:
        print(f"tests/run.py: error: cannot bring up loopback: {exc}", file=sys.stderr)
        return 1
    if interfaces() != ["lo"]:
        print(f"tests/run.py: error: not isolated, interfaces: {interfaces()}", file=sys.stderr)
        return 1
    if args[:1] == ["--script"]:  # e.g. docs/screenshots.py: a program that needs DDS
        os.execv(sys.executable, [sys.executable, *args[1:]])
    if args[:1] == ["--bench"]:
        os.execv(sys.executable, [sys.executable, "-m", "bench", *args[1:]])
    os.execv(sys.executable, [sys.executable, "-m", "pytest", *args])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

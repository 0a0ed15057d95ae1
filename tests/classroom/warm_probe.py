"""A program the warm-start tests run as a fork of the warm parent (``python -m`` this).

``show`` prints, as one JSON line, what the process is: pid, parent, session,
threads, working folder, its token, its argv, command line and open files. ``write WORD``
writes WORD into memory the warm parent made (a module's dictionary, a list,
and the bytes of a string in place), says ``written``, then waits to be
ended. ``read`` prints what those places hold. ``sleep`` waits to be ended.
"""

from __future__ import annotations

import ctypes
import json
import os
import sys
import time

import app.dds  # imported by the warm parent: its objects live in the shared pages


def _doc_bytes() -> int:
    """The address of the first character of app.dds's docstring (a compact ASCII str)."""
    doc = app.dds.__doc__ or ""
    return id(doc) + sys.getsizeof(doc) - (len(doc) + 1)


def _files() -> list[str]:
    """What this process's descriptors are (a pipe, /dev/null, a socket...)."""
    found = []
    for fd in os.listdir("/proc/self/fd"):
        try:
            found.append(os.readlink(f"/proc/self/fd/{fd}"))
        except OSError:  # the one listdir used
            continue
    return found


def places() -> dict[str, object]:
    doc = app.dds.__doc__ or ""
    return {
        "module_attribute": getattr(app.dds, "warm_probe", None),
        "path_entry": [p for p in sys.path if p.startswith("warm-probe:")],
        "string_start": doc[:12],
    }


def main(argv: list[str]) -> int:
    verb = argv[0] if argv else "show"
    if verb == "show":
        with open("/proc/self/cmdline", "rb") as f:
            cmdline = f.read().split(b"\0")[0].decode()
        print(
            json.dumps(
                {
                    "pid": os.getpid(),
                    "ppid": os.getppid(),
                    "sid": os.getsid(0),
                    "threads": len(os.listdir("/proc/self/task")),
                    "cwd": os.getcwd(),
                    "token": os.environ.get("CLASSROOM_TOKEN"),
                    "argv": sys.argv[1:],
                    "cmdline": cmdline,
                    "files": sorted(_files()),
                }
            ),
            flush=True,
        )
        return 0
    if verb == "write":
        word = argv[1]
        app.dds.warm_probe = word  # type: ignore[attr-defined]
        sys.path.append(f"warm-probe:{word}")
        ctypes.memmove(_doc_bytes(), word.encode()[:12].ljust(12, b"!"), 12)
        print("written", json.dumps(places()), flush=True)
        while True:
            time.sleep(1)
    if verb == "read":
        print(json.dumps(places()), flush=True)
        return 0
    while True:  # sleep
        time.sleep(1)


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))

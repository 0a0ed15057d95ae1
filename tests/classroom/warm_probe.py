"""A program the warm-start tests run as a fork of the warm parent (``python -m`` this).

``show`` prints, as one JSON line, what the process is: pid, parent, session,
threads, working folder, its token, its argv, command line and open files. ``write WORD``
writes WORD into memory the warm parent made (a module's dictionary, a list,
and the bytes of a string in place), says ``written``, then waits to be
ended. ``read`` prints what those places hold. ``sleep`` waits to be ended.
``kept`` (run cold) imports what the warm parent imports and prints, as JSON,
every place in a module's globals (three levels into containers and objects)
that holds the value of an environment variable whose value has ``-sentinel``.
"""

from __future__ import annotations

import ctypes
import json
import os
import sys
import time
import types

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


def _death_signal() -> int:
    """This process's parent-death signal (prctl PR_GET_PDEATHSIG)."""
    found = ctypes.c_int(0)
    ctypes.CDLL(None).prctl(2, ctypes.byref(found), 0, 0, 0)
    return found.value


def _proc_environ() -> dict[str, str]:
    """What /proc/self/environ (ps e, psutil) says this process's environment is."""
    with open("/proc/self/environ", "rb") as f:
        entries = f.read().split(b"\0")
    return dict(e.decode(errors="replace").split("=", 1) for e in entries if b"=" in e)


def places() -> dict[str, object]:
    doc = app.dds.__doc__ or ""
    return {
        "module_attribute": getattr(app.dds, "warm_probe", None),
        "path_entry": [p for p in sys.path if p.startswith("warm-probe:")],
        "string_start": doc[:12],
    }


def kept() -> list[str]:
    """Where the warm imports keep a sentinel variable's value: 'NAME module.attr[...]'."""
    import importlib

    from app.warm_start import WARM_IMPORTS

    for module in WARM_IMPORTS:
        importlib.import_module(module)
    sentinels = {k: v for k, v in os.environ.items() if "-sentinel" in v}
    seen: set[int] = set()
    hits: list[str] = []
    # The environment itself: a fork's is the learner's (app/warm_start._Learner.run).
    import posix

    environs = (os.environ, os.environ._data, posix.environ)  # type: ignore[attr-defined]

    def look(value: object, where: str, depth: int) -> None:
        if id(value) in seen or depth > 3 or any(value is e for e in environs):
            return
        if isinstance(value, types.ModuleType):  # looked at under its own name
            return
        seen.add(id(value))
        if isinstance(value, (str, bytes, os.PathLike)):
            text = os.fsdecode(value)
            hits.extend(f"{k} {where}" for k, v in sentinels.items() if v in text)
        elif isinstance(value, (list, tuple, set, frozenset)):
            for i, item in enumerate(list(value)[:500]):
                look(item, f"{where}[{i}]", depth + 1)
        elif isinstance(value, dict):
            for key, item in list(value.items())[:1000]:
                look(item, f"{where}[{key!r}]", depth + 1)
        elif not isinstance(value, type) and isinstance(getattr(value, "__dict__", None), dict):
            look(vars(value), f"{where}.__dict__", depth + 1)

    for name, module in list(sys.modules.items()):
        if name == "__main__" or module is None:
            continue
        for attr, value in list(vars(module).items()):
            if not attr.startswith("__"):
                look(value, f"{name}.{attr}", 0)
    return hits


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
                    "proc_token": _proc_environ().get("CLASSROOM_TOKEN"),
                    "uid": os.getuid(),
                    "euid": os.geteuid(),
                    "gid": os.getgid(),
                    "groups": sorted(os.getgroups()),
                    "pdeathsig": _death_signal(),
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
    if verb == "kept":
        print(json.dumps(kept()), flush=True)
        return 0
    if verb == "read":
        print(json.dumps(places()), flush=True)
        return 0
    while True:  # sleep
        time.sleep(1)


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))

"""Warm start: learners' dashboards fork from one process that has paid the imports.

A cold ``python -m app serve`` spends most of its start importing (rclpy,
viser, numpy and about 2,000 modules of ours and theirs); a class started
together pays that once per learner, on the same cores. The *warm parent*
(``python -m app.warm_start``, run by ``app.classroom``) imports it all once
and starts nothing: no rclpy context, no DDS participant, no socket but the
one to the classroom, no thread. Each learner's dashboard is a fork of it
that then runs what a cold ``python -m app serve ...`` runs, from
``app/__main__.py`` on, with its own argv, environment, working folder,
session, output pipe and parent-death signal: rclpy.init, DDS, the domain
id, viser's server all happen in the learner's process, as cold.

Threads that imports start, and what is done about them (the warm parent
reports its threads and open files; tests/classroom/test_warm_start.py):

- OpenBLAS (numpy's, scipy's and OpenCV's copies) starts a worker per extra
  core when it loads. The warm parent ends them (``blas_thread_shutdown_``,
  which OpenBLAS exports for this); in a learner OpenBLAS starts them again
  on its first large product, as it does after any fork.
- LTTng-UST (ROS 2 tracing, loaded with rclpy's C extension) starts two
  listener threads in its library constructor and has no switch to not do
  so. So the importing process forks once more, under LTTng's own fork
  protocol (``ust_before_fork``), and that thread-free copy is the warm
  parent; each learner runs ``ust_after_fork_child``, which gives it
  listeners of its own, as a cold process has.

A learner must be the classroom's own child, as when started cold (the
classroom waits for it, signals it, reads its exit code; its parent-death
signal is the classroom's death), and must outlive a warm parent that dies.
So the warm parent forks twice and the middle process ends at once: the
learner is adopted by the classroom, which is a child subreaper
(``PR_SET_CHILD_SUBREAPER``) only for those milliseconds. The learner then
waits for the classroom's go (a pipe), so a learner the classroom never
heard of (its warm parent died mid-request) ends instead of serving.

Secrets: a learner's environment (its access token) reaches the warm parent
as raw bytes in one buffer that only the learner's fork decodes; the warm
parent zeroes the buffer after each fork, so no later learner's process
carries an earlier learner's token.

What differs from a cold start, knowingly: the secret of ``str`` hash
randomization is the warm parent's (every fork shares it; numpy's global
generator is seeded again, ``random`` is by Python itself);
``/proc/PID/environ`` shows the learner's environment written over room the
warm parent was started with (``_set_environ``: a learner's bigger than
ENVIRON_ROOM leaves the warm parent's there, while ``os.environ`` and
``getenv`` see the learner's own either way); what the imports made is
frozen for the garbage collector (``gc.freeze``), so the learners'
collections leave the shared pages shared. A learner's startup
variables (``STARTUP_VARS``) must equal the warm parent's, else it starts cold.

Protocol, over a ``SOCK_SEQPACKET`` socket pair the classroom makes (nothing
else can connect), one JSON object a message unless said otherwise:

1. warm parent -> classroom: ``{"imported": ...}`` (or ``{"error": ...}``)
2. classroom -> warm parent: ``{"adopt": true}``, while it is a subreaper
3. warm parent (the thread-free copy) -> classroom: ``{"ready": ..., "pid": ...}``
4. per learner, classroom -> warm parent: a 4-byte header length, the header
   ``{"id", "argv", "cwd", "user"}`` (user: null, or the uid, gid and groups
   the fork becomes), the environment as ``KEY=VALUE\\0`` bytes, and
   two descriptors (the learner's output pipe, its go pipe); answered with
   ``{"id", "pid"}`` or ``{"id", "error"}``.
"""

from __future__ import annotations

import array
import ctypes
import gc
import importlib
import json
import os
import re
import select
import signal
import socket
import struct
import subprocess
import sys
import threading
import time
import warnings
from collections import deque
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager, suppress
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

from app import PROJECT_ROOT
from app.stop_signals import die_with

if TYPE_CHECKING:
    from typing import TypedDict

    class _Account(TypedDict):
        """A request's ``user``: the account its fork becomes."""

        uid: int
        gid: int
        groups: list[int]

    class _Said(TypedDict, total=False):
        """What the warm parent says to the classroom (protocol steps 1 and 3)."""

        imported: bool
        seconds: float
        missing: list[str]  # the optional modules that failed to import
        error: str
        ready: bool
        pid: int
        threads: int
        open_files: list[str]
        python_threads: list[str]

    class _Answer(TypedDict, total=False):
        """The warm parent's answer to one request (protocol step 4)."""

        id: int | None
        pid: int
        error: str


PARENT_MODULE = "app.warm_start"
COLD_START_VAR = "CLASSROOM_COLD_START"  # "1": every dashboard starts cold (a cold process each)

# What a learner's dashboard imports by the time it is ready (measured on a cold
# `serve`): the command, what `cmd_serve` imports when it runs, what the page's
# build imports, and the message type support its first subscriptions load. And the
# tools a page opens later (app/dashboard.py builds them then): paid once here, a
# learner's first click on one imports nothing.
TOOL_MODULES = (
    "actions",
    "bags",
    "echo",
    "graph",
    "lifecycle",
    "logs",
    "nodes",
    "parameters",
    "services",
    "tf",
    "topics",
    "turtlesim",
)
REQUIRED_IMPORTS = ("numpy", "rclpy", "rclpy.node", "viser", "app.cli", "app.dashboard")
WARM_IMPORTS = REQUIRED_IMPORTS + (
    "app.access",
    "app.bags.folder",
    "app.exercises.editor_server",
    "app.exercises.panel",
    "app.exercises.workspace",
    "app.lessons.progress",
    "app.lessons.schema",
    *(f"app.panels.{name}_panel" for name in TOOL_MODULES),
    "app.ros2cli.console_panel",
    "app.ros.liveness",
    "app.ros.runtime",
    "app.supervisor",
    "app.ui.base_path",
    "app.ui.page_links",
    "app.ros2cli.pkg",
    "app.teacher.hub_link",
    "app.teacher.beacon",
    "app.containment.contain",
    "app.containment.sandbox",
    "app.containment.policy",
    "app.ament_prefix",
    "app.launch_prefix",
    "app.ros2cli.tutorial_prefix",
    "em",
    "fractions",
    "lark",
    "rich.console",
    "rich.panel",
    "rich.table",
    "rich._log_render",
    "rosidl_generator_py",
    "type_description_interfaces.msg",
    "builtin_interfaces.builtin_interfaces_s__rosidl_typesupport_c",
    "geometry_msgs.geometry_msgs_s__rosidl_typesupport_c",
    "rcl_interfaces.rcl_interfaces_s__rosidl_typesupport_c",
    "sensor_msgs.sensor_msgs_s__rosidl_typesupport_c",
    "service_msgs.service_msgs_s__rosidl_typesupport_c",
    "std_msgs.std_msgs_s__rosidl_typesupport_c",
    "tf2_msgs.tf2_msgs_s__rosidl_typesupport_c",
    "type_description_interfaces.type_description_interfaces_s__rosidl_typesupport_c",
    "visualization_msgs.visualization_msgs_s__rosidl_typesupport_c",
)

# Read when a process starts or a library loads, so a learner's must equal the warm
# parent's (else that learner starts cold): the interpreter's, the loader's, the
# locale, and what the libraries loaded at import read. Not HOME: each hub learner
# has their own, and nothing the warm parent imports keeps it (only site's unused
# USER_SITE; tests/classroom/test_warm_start.py looks through every module).
STARTUP_VARS = re.compile(
    r"^(PYTHON|LD_|LC_|LANG|TZ$|GLIBC_TUNABLES$|MALLOC_|OPENBLAS_|OMP_|LTTNG_)"
)

IMPORT_TIMEOUT_SEC = 120.0  # a warm parent's imports on a busy 2-core machine
REPLY_TIMEOUT_SEC = 15.0  # two forks of a ~200 MB process, under load
ADOPT_TIMEOUT_SEC = 5.0  # the middle process ends at once; this is for a stalled machine
LAST_WORDS_WAIT_SEC = 2.0  # for the lines a warm parent printed as it ended to be read
ANNOUNCE_TIMEOUT_SEC = 5.0  # after a failed start: time to hear from a learner forked anyway
MAX_RESTARTS = 3  # within RESTART_WINDOW_SEC, then warm start is off for this classroom
RESTART_WINDOW_SEC = 600.0
MAX_REQUEST = 256 * 1024  # one learner's argv, folder and environment
TITLE_ROOM = 1536  # bytes of command line a fork can show in `ps` (see _set_title)
# Bytes of environment a fork can show in /proc/PID/environ (see _set_environ): a
# hub learner's is ~4 KB (its hub's URLs and tokens).
ENVIRON_ROOM = 64 * 1024
ENVIRON_ROOM_VAR = "CLASSROOM_ENVIRON_ROOM"

_PR_SET_PDEATHSIG = 1
_PR_SET_DUMPABLE = 4
_PR_SET_CHILD_SUBREAPER = 36
_PR_GET_CHILD_SUBREAPER = 37
_libc = ctypes.CDLL(None, use_errno=True)
_ANNOUNCE = re.compile(rb"warm start: this dashboard \(pid (\d+)\)")


class WarmStartError(RuntimeError):
    """The warm parent could not start a learner (or could not start itself): start cold."""


@dataclass(frozen=True)
class Credentials:
    """The account a fork becomes before it runs the learner's command (a hub run as root)."""

    uid: int
    gid: int
    groups: tuple[int, ...]


def _become(user: _Account, classroom: int) -> None:
    """Switch to the learner's account for good; any step that fails ends the process.

    Changing credentials clears the parent-death signal and makes the process
    non-dumpable (its /proc files the old owner's), which an exec would undo:
    both are set back, and the parent checked again.
    """
    try:
        os.setgroups([int(g) for g in user["groups"]])
        os.setgid(int(user["gid"]))
        os.setuid(int(user["uid"]))
        if os.getuid() != int(user["uid"]) or os.geteuid() != int(user["uid"]):
            raise PermissionError("the uid did not change")
    except (OSError, KeyError, TypeError, ValueError) as exc:
        os.write(2, f"warm start: could not become uid {user.get('uid')}: {exc}\n".encode())
        os._exit(72)  # never run a learner's server as the warm parent's account
    _libc.prctl(_PR_SET_DUMPABLE, 1, 0, 0, 0)
    _libc.prctl(_PR_SET_PDEATHSIG, signal.SIGTERM, 0, 0, 0)
    if os.getppid() != classroom:
        os._exit(0)  # the classroom died meanwhile: nobody waits for us


# --------------------------------------------------------------------- the warm parent


def _send(sock: socket.socket, message: Mapping[str, object]) -> None:
    sock.sendall(json.dumps(message).encode())


def _threads() -> int:
    return len(os.listdir("/proc/self/task"))


def _open_files(keep: set[int]) -> list[str]:
    """This process's descriptors beyond ``keep``, with what each is (a socket, a file...)."""
    found = []
    for name in os.listdir("/proc/self/fd"):
        fd = int(name)
        if fd in keep:
            continue
        try:
            found.append(f"{fd}: {os.readlink(f'/proc/self/fd/{fd}')}")
        except OSError:  # the descriptor listdir itself used
            continue
    return found


def _loaded_libraries(pattern: str) -> list[str]:
    """Paths of the shared libraries loaded here whose file name matches ``pattern``."""
    found = set()
    with open("/proc/self/maps") as maps:
        for line in maps:
            path = line.split(maxsplit=5)[-1].strip() if line.count(" ") >= 5 else ""
            if path.startswith("/") and re.search(pattern, path.rsplit("/", 1)[-1]):
                found.add(path)
    return sorted(found)


def _end_openblas_threads() -> None:
    """OpenBLAS's workers end; OpenBLAS starts them again where a product needs them."""
    for path in _loaded_libraries(r"openblas.*\.so"):
        try:
            ctypes.CDLL(path, mode=os.RTLD_NOLOAD).blas_thread_shutdown_()
        except (OSError, AttributeError):
            continue  # not loaded after all, or a build without a thread pool


class _LttngUst:
    """LTTng-UST's fork protocol (what its liblttng-ust-fork.so wraps ``fork`` with)."""

    def __init__(self, libraries: list[ctypes.CDLL]) -> None:
        self._libraries = libraries
        self._sigsets = [ctypes.create_string_buffer(128) for _ in libraries]  # sigset_t

    @classmethod
    def find(cls) -> _LttngUst:
        """The loaded copies of LTTng-UST (none: nothing to do); raises if one has no hooks."""
        libraries = []
        for path in _loaded_libraries(r"^liblttng-ust-[0-9a-f]+\.so|^liblttng-ust\.so"):
            library = ctypes.CDLL(path, mode=os.RTLD_NOLOAD)
            hooks = ("ust_before_fork", "lttng_ust_before_fork")  # LTTng-UST 2.12, 2.13
            if not any(hasattr(library, name) for name in hooks):
                raise WarmStartError(f"{path} has no fork hooks: forking it would be unsafe")
            libraries.append(library)
        return cls(libraries)

    def _call(self, suffix: str) -> None:
        for library, sigset in zip(self._libraries, self._sigsets, strict=True):
            name = f"ust_{suffix}" if hasattr(library, f"ust_{suffix}") else f"lttng_ust_{suffix}"
            getattr(library, name)(sigset)

    def before_fork(self) -> None:
        """Takes LTTng's locks and blocks every signal (the mask comes back after the fork)."""
        self._call("before_fork")

    def after_fork_child(self) -> None:
        """In a learner: LTTng's locks released, listeners of its own, the signal mask back."""
        self._call("after_fork_child")


def _own_area(which: str) -> tuple[int, int]:
    """Where this process's argv (``"arg"``) or environment (``"env"``) strings lie in its
    memory, as /proc/self/stat says (arg_start..env_end, proc(5)); (0, 0) if it cannot."""
    first = {"arg": 45, "env": 47}[which]  # counted after the command name's ")"
    try:
        fields = Path("/proc/self/stat").read_text().rsplit(")", 1)[1].split()
        return int(fields[first]), int(fields[first + 1])
    except (OSError, IndexError, ValueError):
        return 0, 0


def _set_title(argv: list[str]) -> None:
    """Show ``argv`` as this process's command line (ps, top, /proc/PID/cmdline).

    A fork keeps its parent's command line: every learner would read
    ``python -m app.warm_start``. The warm parent is started with room in its
    argv (TITLE_ROOM bytes); the learner writes its own command there, as the
    setproctitle package does: one string, the area's last byte not NUL.
    """
    start, end = _own_area("arg")
    room = end - start
    if room < 2:
        return
    title = " ".join(argv).encode(errors="replace")[: room - 2] + b"\0"
    ctypes.memmove(start, title.ljust(room, b" "), room)


def _set_environ(environ: bytes) -> bool:
    """Show ``environ`` (``KEY=VALUE\\0``...) as this process's /proc/PID/environ.

    A fork keeps its parent's: tools and tests that read a learner's environment
    there (``ps e``, psutil) would see the warm parent's. The warm parent is
    started with ENVIRON_ROOM spare bytes in its environment; once the learner's
    own environment is in place (``os.environ`` no longer points into that
    area), it is written over it, NUL-padded. False (left as it is) when it
    does not fit.
    """
    start, end = _own_area("env")
    room = end - start
    if room <= 0 or len(environ) > room:
        return False
    ctypes.memmove(start, environ.ljust(room, b"\0"), room)
    return True


def _wait_adopted(before: int, classroom: int) -> bool:
    """Once the middle process has ended, die with the classroom; False if it is not our parent.

    The parent-death signal counts only from when it is set, so it is set after the
    adoption and the parent checked again after it.
    """
    deadline = time.monotonic() + ADOPT_TIMEOUT_SEC
    while os.getppid() == before:
        if time.monotonic() > deadline:
            return False
        time.sleep(0.001)
    _libc.prctl(_PR_SET_PDEATHSIG, signal.SIGTERM, 0, 0, 0)
    return os.getppid() == classroom


@dataclass
class _Learner:
    """A learner's process, just forked: becomes what the request's argv asks for."""

    header: dict[str, Any]
    environ: bytes
    out_fd: int
    go_fd: int
    middle: int
    classroom: int
    warm_parent: int
    ust: _LttngUst
    sock: socket.socket

    def run(self) -> int:
        self.ust.after_fork_child()
        os.close(self.sock.detach())
        if not _wait_adopted(self.middle, self.classroom):  # said in the warm parent's log
            os.write(2, f"warm start: pid {os.getpid()} was not adopted; it ends\n".encode())
            os._exit(71)  # the classroom is gone (or is no subreaper): nobody waits for us
        os.setsid()  # own session and group, as a cold start's start_new_session
        os.dup2(self.out_fd, 1)
        os.dup2(self.out_fd, 2)
        os.close(self.out_fd)
        os.write(
            1,
            f"warm start: this dashboard (pid {os.getpid()}) is a fork of the warm parent "
            f"(pid {self.warm_parent})\n".encode(),
        )
        go = os.read(self.go_fd, 1)
        os.close(self.go_fd)
        if go != b"g":  # the classroom did not take us (its request failed): end unseen
            os._exit(0)
        argv: list[str] = self.header["argv"]
        if self.header.get("user") is not None:
            _become(self.header["user"], self.classroom)
        os.chdir(self.header["cwd"])
        os.environ.clear()
        for entry in self.environ.split(b"\0"):
            key, sep, value = entry.partition(b"=")
            if sep:
                os.environb[key] = value
        _set_title(argv)
        _set_environ(self.environ)
        if "numpy.random" in sys.modules:  # its global generator was seeded in the warm parent
            sys.modules["numpy.random"].seed()
        if sys.path and sys.path[0] == str(PROJECT_ROOT):  # `-m` puts the working folder first
            sys.path[0] = self.header["cwd"]
        sys.orig_argv = list(argv)
        sys.argv = ["-m", *argv[3:]]
        import runpy

        runpy.run_module(argv[2], run_name="__main__", alter_sys=True)
        return 0


class WarmParent:
    """The thread-free warm parent: forks a learner per request, answers with its pid."""

    def __init__(self, sock: socket.socket, ust: _LttngUst, classroom: int) -> None:
        self.sock = sock
        self.ust = ust
        self.classroom = classroom
        self.pid = os.getpid()
        self._buffer = bytearray(MAX_REQUEST)
        self._ancillary = socket.CMSG_SPACE(4 * array.array("i").itemsize)

    def serve(self) -> _Learner | None:
        """Requests until the classroom closes the socket (None); returns only in a learner."""
        while True:
            size, ancdata, flags, _ = self.sock.recvmsg_into([self._buffer], self._ancillary)
            if size == 0:
                return None
            fds: list[int] = []
            for level, kind, data in ancdata:
                if level == socket.SOL_SOCKET and kind == socket.SCM_RIGHTS:
                    usable = len(data) - len(data) % array.array("i").itemsize
                    fds += array.array("i", data[:usable]).tolist()
            learner = self._start(size, fds, flags)
            if learner is not None:
                return learner

    def _start(self, size: int, fds: list[int], flags: int) -> _Learner | None:
        request: object = None
        try:
            if flags & (socket.MSG_TRUNC | socket.MSG_CTRUNC) or len(fds) != 2:
                raise ValueError("a request too large, or without its two descriptors")
            (length,) = struct.unpack_from("!I", self._buffer)
            header = json.loads(bytes(self._buffer[4 : 4 + length]))
            request = header.get("id")
            argv = header["argv"]
            if len(argv) < 3 or argv[1] != "-m" or argv[0] != sys.executable:
                raise ValueError(f"not `{sys.executable} -m MODULE ...`: {argv[:3]}")
            learner = self._fork(header, 4 + length, size, fds)
            if learner is not None:
                return learner
        except (OSError, ValueError, KeyError, TypeError, struct.error) as exc:
            self._reply({"id": request, "error": f"{type(exc).__name__}: {exc}"})
        finally:
            if os.getpid() == self.pid:
                for fd in fds:
                    os.close(fd)
                self._buffer[:size] = bytes(size)  # no later fork carries this learner's secrets
        return None

    def _fork(
        self, header: dict[str, Any], env_at: int, size: int, fds: list[int]
    ) -> _Learner | None:
        status_r, status_w = os.pipe()
        sys.stdout.flush()
        sys.stderr.flush()
        try:
            middle = os.fork()
        except OSError:
            os.close(status_r)
            os.close(status_w)
            raise
        if middle == 0:  # the middle process: fork the learner, say its pid, end
            me = os.getpid()  # the learner must not ask getppid(): we may be gone by then
            pid = -1
            try:  # whatever happens here ends here: never back in the warm parent's loop
                os.close(status_r)
                pid = os.fork()
                if pid:
                    os.write(status_w, str(pid).encode())
            except BaseException as exc:
                with suppress(OSError):
                    os.write(status_w, f"error {exc}".encode())
            finally:
                if pid != 0:
                    os._exit(0)
            try:  # the learner
                os.close(status_w)
                env = bytes(self._buffer[env_at:size])
                return _Learner(
                    header, env, fds[0], fds[1], me, self.classroom, self.pid, self.ust, self.sock
                )
            except BaseException:
                os._exit(70)
        os.close(status_w)
        said = b""
        while chunk := os.read(status_r, 256):
            said += chunk
        os.close(status_r)
        os.waitpid(middle, 0)  # once it has ended, the learner is the classroom's
        if not said.isdigit():
            raise OSError(f"fork failed: {said.decode(errors='replace') or 'no answer'}")
        self._reply({"id": header.get("id"), "pid": int(said)})
        return None

    def _reply(self, message: Mapping[str, object]) -> None:
        _send(self.sock, message)


def _import_all() -> list[str]:
    """Import what a dashboard needs; the optional modules that failed (the required raise)."""
    missing = []
    for name in WARM_IMPORTS:
        try:
            importlib.import_module(name)
        except ImportError as exc:
            if name in REQUIRED_IMPORTS:
                raise
            missing.append(f"{name} ({exc})")
    return missing


def main(argv: list[str] | None = None) -> int:
    """The warm parent: imports, then forks into its thread-free copy, which serves."""
    import argparse

    parser = argparse.ArgumentParser(prog="python -m app.warm_start")
    parser.add_argument("--fd", type=int, required=True, help="the classroom's socket")
    parser.add_argument("--room", default="", help="room for a learner's command line")
    args = parser.parse_args(argv)
    sock = socket.socket(fileno=args.fd)
    started = time.monotonic()
    try:
        missing = _import_all()
        _end_openblas_threads()
        ust = _LttngUst.find()
    except Exception as exc:  # said to the classroom, which starts everyone cold
        _send(sock, {"error": f"{type(exc).__name__}: {exc}"})
        raise
    gc.collect()
    gc.freeze()  # learners' collections then leave the shared pages alone
    _send(sock, {"imported": True, "seconds": time.monotonic() - started, "missing": missing})
    answer = json.loads(sock.recv(4096) or b"{}")
    if not answer.get("adopt"):
        return 1
    classroom, importer = os.getppid(), os.getpid()
    sys.stdout.flush()
    sys.stderr.flush()
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, [])
    ust.before_fork()
    with warnings.catch_warnings():  # 3.12 warns of forking with threads: LTTng's, handled
        warnings.simplefilter("ignore", DeprecationWarning)
        pid = os.fork()
    if pid:
        os._exit(0)  # the importer's threads end with it; the classroom adopts the copy
    # The copy keeps LTTng's locks taken (it never traces) and gets its signals back.
    signal.pthread_sigmask(signal.SIG_SETMASK, mask)
    try:
        if not _wait_adopted(importer, classroom):
            _send(sock, {"error": "the classroom did not adopt the warm parent"})
            os._exit(1)
        _set_title([sys.executable, "-m", PARENT_MODULE])
        keep = {0, 1, 2, sock.fileno()}
        _send(
            sock,
            {
                "ready": True,
                "pid": os.getpid(),
                "threads": _threads(),
                "open_files": _open_files(keep),
                "python_threads": [t.name for t in threading.enumerate()],
            },
        )
        learner = WarmParent(sock, ust, classroom).serve()
    except BaseException:  # the warm parent never runs Python's exit (LTTng's locks are held)
        import traceback

        traceback.print_exc()
        sys.stderr.flush()
        os._exit(1)
    if learner is None:  # the classroom closed the socket
        sys.stdout.flush()
        os._exit(0)
    return learner.run()


# --------------------------------------------------------------------- the classroom's side


_adopting_lock = threading.Lock()
_adopting_depth = 0
_was_subreaper = False


@contextmanager
def _adopting() -> Iterator[None]:
    """While inside, orphans of this process's descendants become its children, not init's.

    Only for the moments a warm parent's middle process ends: a subreaper must
    reap whatever it adopts, and this process does not expect others.
    """
    global _adopting_depth, _was_subreaper
    with _adopting_lock:
        if _adopting_depth == 0:
            state = ctypes.c_int(0)
            _libc.prctl(_PR_GET_CHILD_SUBREAPER, ctypes.byref(state), 0, 0, 0)
            _was_subreaper = bool(state.value)
            if not _was_subreaper and _libc.prctl(_PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0) != 0:
                raise WarmStartError(f"PR_SET_CHILD_SUBREAPER: {os.strerror(ctypes.get_errno())}")
        _adopting_depth += 1
    try:
        yield
    finally:
        with _adopting_lock:
            _adopting_depth -= 1
            if _adopting_depth == 0 and not _was_subreaper:
                _libc.prctl(_PR_SET_CHILD_SUBREAPER, 0, 0, 0, 0)


def _parent_of(pid: int) -> int | None:
    try:
        return int(Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[1])
    except (OSError, IndexError, ValueError):
        return None


class WarmChild:
    """A process the classroom adopted from the warm parent, handled like ``subprocess.Popen``."""

    def __init__(self, pid: int, args: list[str], stdout: IO[bytes] | None = None) -> None:
        self.pid = pid
        self.args = args
        self.stdout = stdout
        self.returncode: int | None = None
        self._lock = threading.Lock()

    def _poll_locked(self) -> int | None:
        if self.returncode is None:
            try:
                pid, status = os.waitpid(self.pid, os.WNOHANG)
            except ChildProcessError:  # not ours after all: nothing to wait for
                self.returncode = 255
            else:
                if pid:
                    self.returncode = os.waitstatus_to_exitcode(status)
        return self.returncode

    def poll(self) -> int | None:
        with self._lock:
            return self._poll_locked()

    def wait(self, timeout: float | None = None) -> int:
        deadline = None if timeout is None else time.monotonic() + timeout
        while (code := self.poll()) is None:
            if deadline is not None and time.monotonic() > deadline:
                raise subprocess.TimeoutExpired(self.args, timeout or 0.0)
            time.sleep(0.02)
        return code

    def __enter__(self) -> WarmChild:
        return self

    def __exit__(self, *_exc: object) -> None:
        """As Popen's: its output closed, it is reaped (JupyterHub's poll does ``with proc``)."""
        if self.stdout is not None:
            self.stdout.close()
        self.wait()

    def send_signal(self, sig: int) -> None:
        with self._lock:  # never a signal to a pid reaped (and maybe reused) meanwhile
            if self._poll_locked() is None:
                os.kill(self.pid, sig)

    def terminate(self) -> None:
        self.send_signal(signal.SIGTERM)

    def kill(self) -> None:
        self.send_signal(signal.SIGKILL)


def describe_exit(code: int | None) -> str:
    if code is None:
        return "still running"
    if code < 0:
        try:
            return f"killed by {signal.Signals(-code).name}"
        except ValueError:
            return f"killed by signal {-code}"
    return f"exit code {code}"


@dataclass
class _Generation:
    """One warm parent: its socket, its process, what it said at start."""

    sock: socket.socket
    process: WarmChild
    import_sec: float
    ready: _Said
    tail: deque[str] = field(default_factory=lambda: deque(maxlen=20))


class WarmStarter:
    """The classroom's handle on its warm parent: start it, spawn learners, restart, close.

    Thread-safe; one request at a time (a learner who asks while the warm parent
    restarts waits for it). Every failure is a ``WarmStartError``: the caller
    starts that learner cold.
    """

    def __init__(
        self,
        env: Mapping[str, str],
        say: Callable[[str], None] = print,
        log_path: Path | None = None,
        module: str | None = None,
    ) -> None:
        self.env = {k: v for k, v in env.items() if k != "CLASSROOM_TOKEN"}
        self.env["PYTHONUNBUFFERED"] = "1"
        self.say = say
        self.log_path = log_path
        self.module = module  # None: PARENT_MODULE, when it starts
        self.enabled = True
        self._lock = threading.RLock()
        self._current: _Generation | None = None
        self._deaths: list[float] = []
        self._next_id = 0
        self._restarting: threading.Thread | None = None

    # ---- the warm parent's life

    @property
    def pid(self) -> int | None:
        return self._current.process.pid if self._current is not None else None

    @property
    def ready(self) -> dict[str, object]:
        """What the running warm parent said when ready (threads, open files)."""
        return dict(self._current.ready) if self._current is not None else {}

    @property
    def import_sec(self) -> float:
        return self._current.import_sec if self._current is not None else float("nan")

    def start(self) -> None:
        """Start the warm parent and wait until it is ready; raises WarmStartError."""
        with self._lock:
            if self._current is not None:
                return
            if not self.enabled:
                raise WarmStartError("warm start is off for this classroom")
            self._current = self._launch()

    def _launch(self) -> _Generation:
        module = self.module or PARENT_MODULE
        ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        tail: deque[str] = deque(maxlen=20)
        try:
            importer = subprocess.Popen(
                [sys.executable, "-m", module, "--fd", str(theirs.fileno()),
                 "--room", " " * TITLE_ROOM],
                cwd=PROJECT_ROOT,
                env={**self.env, ENVIRON_ROOM_VAR: " " * ENVIRON_ROOM},
                pass_fds=(theirs.fileno(),),
                stdin=subprocess.DEVNULL,
                stdout=subprocess.PIPE,
                stderr=subprocess.STDOUT,
                start_new_session=True,
                preexec_fn=die_with(os.getpid()),  # dies with the classroom
            )  # fmt: skip
        except OSError as exc:
            ours.close()
            raise WarmStartError(f"could not run the warm parent: {exc}") from None
        finally:
            theirs.close()
        assert importer.stdout is not None
        pump = threading.Thread(
            target=self._pump, args=(importer.stdout, tail), name="warm-parent-log", daemon=True
        )
        pump.start()
        ready: _Said = {}
        try:
            said = self._receive(ours, IMPORT_TIMEOUT_SEC, importer)
            if "imported" not in said:
                raise WarmStartError(said.get("error") or "it said nothing")
            with _adopting():
                _send(ours, {"adopt": True})
                ready = self._receive(ours, REPLY_TIMEOUT_SEC, importer)
            if not ready.get("ready"):
                raise WarmStartError(ready.get("error") or "it never said it was ready")
            importer.wait(ADOPT_TIMEOUT_SEC)
            pid = int(ready["pid"])
            if _parent_of(pid) != os.getpid():
                raise WarmStartError("the warm parent is not this classroom's child")
        except BaseException as exc:
            ours.close()
            _end(importer)  # and its process group: the copy too, if it was forked
            adopted = ready.get("pid")
            if isinstance(adopted, int) and _parent_of(adopted) == os.getpid():
                WarmChild(adopted, []).wait(ADOPT_TIMEOUT_SEC)
            if isinstance(exc, WarmStartError):
                # Its last lines may still be in the pipe when its end is seen (ci21: the
                # reason, "No module named ...", was missing): read them to the end first.
                pump.join(LAST_WORDS_WAIT_SEC)
                last = next((line.strip() for line in reversed(tail) if line.strip()), "")
                words = f"; its last words: {last}" if last and last not in str(exc) else ""
                raise WarmStartError(f"{exc}{words}") from None
            raise
        ready["missing"] = said.get("missing", [])
        return _Generation(ours, WarmChild(pid, [module]), float(said["seconds"]), ready, tail)

    def _receive(
        self, sock: socket.socket, timeout: float, importer: subprocess.Popen[bytes]
    ) -> _Said:
        deadline = time.monotonic() + timeout
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                raise WarmStartError(f"no answer in {timeout:.0f} s")
            readable, _, _ = select.select([sock], [], [], min(left, 0.5))
            if readable:
                data = sock.recv(64 * 1024)
                if not data:
                    try:
                        code: int | None = importer.wait(2.0)
                    except subprocess.TimeoutExpired:
                        code = None
                    raise WarmStartError(f"it ended ({describe_exit(code)})")
                result: _Said = json.loads(data)
                return result

    def _pump(self, stream: IO[bytes], tail: deque[str]) -> None:
        log = open(self.log_path, "ab") if self.log_path is not None else None
        try:
            for raw in stream:
                tail.append(raw.decode(errors="replace"))
                if log is not None:
                    log.write(raw)
                    log.flush()
        finally:
            stream.close()
            if log is not None:
                log.close()

    def check(self) -> None:
        """Call now and then: a warm parent that ended is said so and restarted (in a thread)."""
        with self._lock:
            current = self._current
            if current is None or current.process.poll() is None or self._restarting:
                return
            self._restarting = threading.Thread(
                target=self._restart_now, name="warm-parent-restart", daemon=True
            )
            self._restarting.start()

    def _restart_now(self) -> None:
        try:
            with self._lock:
                self._ensure()
        except WarmStartError:
            pass  # said in _ensure; learners start cold meanwhile
        finally:
            self._restarting = None

    def _ensure(self) -> _Generation:
        """The running warm parent; one that ended is said so and restarted (raises if not)."""
        current = self._current
        if current is not None and current.process.poll() is None:
            return current
        if current is not None:
            current.sock.close()
            self._current = None
            now = time.monotonic()
            self._deaths = [t for t in self._deaths if now - t < RESTART_WINDOW_SEC] + [now]
            self.say(
                f"Warm start: the warm parent (pid {current.process.pid}) ended "
                f"({describe_exit(current.process.returncode)}); restarting it."
            )
            if len(self._deaths) > MAX_RESTARTS:
                self.enabled = False
                self.say(
                    f"Warm start: off, the warm parent ended {len(self._deaths)} times in "
                    f"{RESTART_WINDOW_SEC / 60:.0f} minutes; dashboards start cold from now on."
                )
        if not self.enabled:
            raise WarmStartError("warm start is off for this classroom")
        try:
            self._current = self._launch()
        except WarmStartError as exc:
            self.say(f"Warm start: could not restart the warm parent ({exc}).")
            raise
        self.say(
            f"Warm start: the warm parent is back (pid {self._current.process.pid}, "
            f"imports in {self._current.import_sec:.1f} s)."
        )
        return self._current

    def close(self, timeout: float = 5.0) -> None:
        """End the warm parent (its learners keep running: they are not its children)."""
        with self._lock:
            current, self._current = self._current, None
            self.enabled = False
        if current is None:
            return
        current.sock.close()  # it reads the end and leaves
        try:
            current.process.wait(timeout)
        except subprocess.TimeoutExpired:
            current.process.kill()
            current.process.wait()

    # ---- learners

    def refusal(self, argv: list[str], env: Mapping[str, str]) -> str:
        """Why this learner cannot be a fork of the warm parent ('' when it can)."""
        if len(argv) < 3 or argv[0] != sys.executable or argv[1] != "-m":
            return "its command is not this interpreter's `-m MODULE`"
        differ = sorted(
            key
            for key in set(env) | set(self.env)
            if STARTUP_VARS.match(key) and env.get(key) != self.env.get(key)
        )
        if differ:
            return f"its environment differs from the warm parent's in {', '.join(differ)}"
        return ""

    def spawn(
        self,
        argv: list[str],
        env: Mapping[str, str],
        cwd: Path | str,
        user: Credentials | None = None,
    ) -> WarmChild:
        """Start ``argv`` (``python -m MODULE ...``) as a fork of the warm parent.

        The result is this process's child, in a session of its own, dying with
        this process, its output (stdout and stderr) on ``.stdout``. ``user``:
        the account it becomes first (this process must be root).
        """
        why = self.refusal(argv, env)
        if user is not None and os.geteuid() != 0:
            why = why or "becoming another account needs a classroom (or hub) run as root"
        if why:
            raise WarmStartError(why)
        with self._lock:
            try:
                return self._spawn(self._ensure(), argv, env, cwd, user)
            except _ParentGone:
                # Said and restarted by _ensure; the learner is never another's process.
                return self._spawn(self._ensure(), argv, env, cwd, user)

    def _spawn(
        self,
        parent: _Generation,
        argv: list[str],
        env: Mapping[str, str],
        cwd: Path | str,
        user: Credentials | None,
    ) -> WarmChild:
        self._next_id += 1
        request = self._next_id
        account = None if user is None else {**asdict(user), "groups": list(user.groups)}
        header = json.dumps(
            {"id": request, "argv": list(argv), "cwd": str(cwd), "user": account}
        ).encode()
        environ = b"".join(os.fsencode(f"{k}={v}") + b"\0" for k, v in env.items())
        out_r, out_w = os.pipe()
        go_r, go_w = os.pipe()
        try:
            with _adopting():
                try:
                    parent.sock.sendmsg(
                        [struct.pack("!I", len(header)), header, environ],
                        [(socket.SOL_SOCKET, socket.SCM_RIGHTS, array.array("i", [out_w, go_r]))],
                    )
                finally:
                    os.close(out_w)
                    os.close(go_r)
                reply = self._reply(parent, request)
            pid = reply.get("pid")
            if not isinstance(pid, int):
                raise WarmStartError(str(reply.get("error") or "no pid in its answer"))
            if _parent_of(pid) != os.getpid():
                raise WarmStartError(f"pid {pid} is not this classroom's child")
            os.write(go_w, b"g")
        except BaseException:
            os.close(go_w)  # a learner forked anyway reads the end and leaves
            _reap_announced(out_r)
            raise
        os.close(go_w)
        return WarmChild(pid, list(argv), os.fdopen(out_r, "rb"))

    def _reply(self, parent: _Generation, request: int) -> _Answer:
        deadline = time.monotonic() + REPLY_TIMEOUT_SEC
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                parent.process.kill()  # stuck: the next request gets a new one
                raise WarmStartError(f"the warm parent gave no answer in {REPLY_TIMEOUT_SEC:.0f} s")
            readable, _, _ = select.select([parent.sock], [], [], min(left, 0.5))
            if not readable:
                if parent.process.poll() is not None:
                    raise _ParentGone()
                continue
            data = parent.sock.recv(64 * 1024)
            if not data:
                try:
                    parent.process.wait(2.0)
                except subprocess.TimeoutExpired:  # its socket closed, yet it runs: end it
                    parent.process.kill()
                    parent.process.wait()
                raise _ParentGone()
            reply: _Answer = json.loads(data)
            if reply.get("id") == request:
                return reply


class _ParentGone(WarmStartError):
    """The warm parent ended during a request."""


def _reap_announced(out_r: int) -> None:
    """After a failed request: wait for a learner that was forked anyway, then close its pipe.

    Such a learner (the warm parent died between its fork and its answer) says its
    pid on its output before it waits for the go it will never get; once it has
    ended it is this process's child, to be reaped.
    """
    said = b""
    deadline = time.monotonic() + ANNOUNCE_TIMEOUT_SEC
    try:
        while time.monotonic() < deadline:
            readable, _, _ = select.select([out_r], [], [], deadline - time.monotonic())
            if not readable:
                break
            chunk = os.read(out_r, 4096)
            if not chunk:
                break
            said += chunk
    finally:
        os.close(out_r)
    found = _ANNOUNCE.search(said)
    if found and _parent_of(int(found.group(1))) == os.getpid():
        child = WarmChild(int(found.group(1)), [])
        try:
            child.wait(ANNOUNCE_TIMEOUT_SEC)
        except subprocess.TimeoutExpired:
            child.kill()
            child.wait()


def _end(process: subprocess.Popen[bytes]) -> None:
    """The importer and its process group (its forked copy, if any) end; it is reaped."""
    try:
        os.killpg(process.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    process.wait()


def cold_start_asked(env: Mapping[str, str]) -> bool:
    """``CLASSROOM_COLD_START=1``: the switch to start every dashboard cold."""
    return env.get(COLD_START_VAR, "").strip().lower() in ("1", "yes", "true", "on")


if __name__ == "__main__":
    raise SystemExit(main())

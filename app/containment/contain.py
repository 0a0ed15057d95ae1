"""Contain this process, then run one learner script in it (the launcher behind ``sandbox``).

Usage (``sandbox.contained_argv`` builds it)::

    python /path/to/contain.py --scratch DIR [--write DIR ...] [--hide DIR ...] [--no-ros]
        [limits] -- SCRIPT [ARGS...]

Started by path, never with ``-m`` from the scratch folder: ``-m`` puts the
working directory first on ``sys.path``, so a learner's ``app/`` folder there
would be imported while this process is still root.

The learner's code runs in this very process (no fork, no exec): the
supervisor's process group, stop signals and exit status all stay right.
Before the learner's first line, in this order:

1. rlimits: CPU seconds, address space, processes, file size, open files.
2. Landlock (Linux 6.12+, ABI 6): everything readable except the hidden
   folders and the home folders (Python's own files there stay readable),
   only the scratch folder, the ``--write`` folders (a build's build/,
   install/ and log/) and /dev/null writable, no TCP bind or connect, no
   signals and no abstract Unix sockets beyond this sandbox.
3. Identity: from root to a uid of its own (``UID_BASE + pid``). The process
   limit counts per uid, so it counts exactly this sandbox; the learner holds
   no capability and root-only files stay closed to it.
4. DDS: join the ROS graph now (``rclpy.init`` and a hidden node keep the
   participant and its UDP sockets, all on 127.0.0.1, alive); pin those
   sockets to ``lo``; the learner's own ``rclpy.init()`` becomes a no-op.
   ``--no-ros`` (a colcon build, the editor's completion worker): no
   participant, so no socket but Unix ones at all.
5. seccomp on every thread: no new sockets but AF_UNIX, no ``sendmsg`` (its
   IP_PKTINFO could send a loopback socket's datagram out of another
   interface; Fast DDS itself sends with ``sendto``), no io_uring, ptrace or
   new namespaces.
"""

from __future__ import annotations

import argparse
import atexit
import builtins
import ctypes
import errno
import functools
import importlib.util
import ipaddress
import linecache
import os
import platform
import resource
import signal
import socket
import stat
import struct
import sys
import traceback
import types
from collections.abc import Iterator, Sequence

UID_BASE = 1_600_000_000  # a contained process runs as UID_BASE + its pid ...
SANDBOX_GID = UID_BASE  # ... in this group, which may write the scratch folders
PID_MAX_LIMIT = 4_194_304  # the kernel's ceiling for pids
MIN_LANDLOCK_ABI = 6  # scoped signals and abstract sockets (Linux 6.12)
BOOTSTRAP_NODE = "_sandbox_bootstrap"
EXIT_LIMIT = 1  # exit code after a limit message

_libc = ctypes.CDLL(None, use_errno=True)
_libc.syscall.restype = ctypes.c_long
_libc.prctl.argtypes = [
    ctypes.c_int,
    ctypes.c_ulong,
    ctypes.c_ulong,
    ctypes.c_ulong,
    ctypes.c_ulong,
]

# --- Landlock (include/uapi/linux/landlock.h) -------------------------------
_SYS_LANDLOCK_CREATE_RULESET, _SYS_LANDLOCK_ADD_RULE, _SYS_LANDLOCK_RESTRICT_SELF = 444, 445, 446
_LL_EXECUTE, _LL_WRITE_FILE, _LL_READ_FILE, _LL_READ_DIR = 1 << 0, 1 << 1, 1 << 2, 1 << 3
_LL_TRUNCATE, _LL_IOCTL_DEV = 1 << 14, 1 << 15
_LL_FS_BY_ABI = {1: (1 << 13) - 1, 2: (1 << 14) - 1, 3: (1 << 15) - 1, 5: (1 << 16) - 1}
_LL_FILE_ONLY = _LL_EXECUTE | _LL_WRITE_FILE | _LL_READ_FILE | _LL_TRUNCATE | _LL_IOCTL_DEV
_LL_NET_BIND_TCP, _LL_NET_CONNECT_TCP = 1 << 0, 1 << 1
_LL_SCOPE_ABSTRACT_UNIX, _LL_SCOPE_SIGNAL = 1 << 0, 1 << 1
_LL_RULE_PATH_BENEATH = 1
_READ = _LL_EXECUTE | _LL_READ_FILE | _LL_READ_DIR
_WRITABLE_DEVICES = ("/dev/null", "/dev/zero", "/dev/full")
HOMES = ("/root", "/home")  # hidden too: nothing in a home folder is a learner's business


class _RulesetAttr(ctypes.Structure):
    _fields_ = [("fs", ctypes.c_uint64), ("net", ctypes.c_uint64), ("scoped", ctypes.c_uint64)]


class _PathBeneath(ctypes.Structure):
    _pack_ = 1
    _fields_ = [("allowed_access", ctypes.c_uint64), ("parent_fd", ctypes.c_int32)]


# --- seccomp ----------------------------------------------------------------
_PR_SET_PDEATHSIG, _PR_SET_NO_NEW_PRIVS = 1, 38
_M_ARENA_MAX = -8
_SECCOMP_SET_MODE_FILTER, _SECCOMP_GET_ACTION_AVAIL, _SECCOMP_FILTER_FLAG_TSYNC = 1, 2, 1
_RET_ALLOW, _RET_ERRNO, _RET_KILL_PROCESS = 0x7FFF0000, 0x00050000, 0x80000000
_CLONE_NAMESPACES = 0x7E020080  # NEWNS|NEWCGROUP|NEWUTS|NEWIPC|NEWUSER|NEWPID|NEWNET|NEWTIME
# Per architecture: the audit tag and the syscall numbers the filter names.
_SYSCALLS: dict[str, dict[str, int]] = {
    "x86_64": {
        "arch": 0xC000003E, "seccomp": 317, "socket": 41, "clone": 56, "clone3": 435,
        "sendmsg": 46, "sendmmsg": 307, "ptrace": 101, "process_vm_readv": 310,
        "process_vm_writev": 311, "unshare": 272, "setns": 308, "bpf": 321,
        "perf_event_open": 298, "userfaultfd": 323, "add_key": 248, "request_key": 249,
        "keyctl": 250, "io_uring_setup": 425, "io_uring_enter": 426, "io_uring_register": 427,
    },
    "aarch64": {
        "arch": 0xC00000B7, "seccomp": 277, "socket": 198, "clone": 220, "clone3": 435,
        "sendmsg": 211, "sendmmsg": 269, "ptrace": 117, "process_vm_readv": 270,
        "process_vm_writev": 271, "unshare": 97, "setns": 268, "bpf": 280,
        "perf_event_open": 241, "userfaultfd": 282, "add_key": 217, "request_key": 218,
        "keyctl": 219, "io_uring_setup": 425, "io_uring_enter": 426, "io_uring_register": 427,
    },
}  # fmt: skip
_DENIED = (
    "sendmsg", "sendmmsg", "ptrace", "process_vm_readv", "process_vm_writev", "unshare",
    "setns", "bpf", "perf_event_open", "userfaultfd", "add_key", "request_key", "keyctl",
    "io_uring_setup", "io_uring_enter", "io_uring_register",
)  # fmt: skip


class SandboxError(RuntimeError):
    """Containment could not be set up; the learner's code must not run."""


def _syscall(number: int, *args: object) -> int:
    # syscall() is variadic and reads longs: a plain int would leave the upper half undefined.
    words = [ctypes.c_long(a) if isinstance(a, int) else a for a in args]
    result = _libc.syscall(ctypes.c_long(number), *words)
    if result < 0:
        err = ctypes.get_errno()
        raise OSError(err, os.strerror(err))
    return int(result)


def _arch() -> dict[str, int]:
    table = _SYSCALLS.get(platform.machine())
    if table is None:
        raise SandboxError(f"no seccomp table for the {platform.machine()} architecture")
    return table


# --- what is missing (sandbox.sandbox_available uses this) -------------------


def landlock_abi() -> int:
    """Landlock ABI version of this kernel; 0 when Landlock is off or absent."""
    version = _libc.syscall(
        ctypes.c_long(_SYS_LANDLOCK_CREATE_RULESET), None, ctypes.c_long(0), ctypes.c_long(1)
    )
    return max(int(version), 0)


def _maps_sandbox_ids(map_file: str) -> bool:
    """True when this user namespace maps every id a sandbox may take."""
    need_low, need_high = UID_BASE, UID_BASE + PID_MAX_LIMIT
    try:
        with open(map_file) as lines:
            for line in lines:
                inner, _outer, count = (int(word) for word in line.split())
                if inner <= need_low and need_high < inner + count:
                    return True
    except OSError:
        return False
    return False


@functools.cache
def identity_problem() -> str | None:
    """Why learner code cannot get a uid and group of its own here; None when it can.

    Read once, from the id maps: as root in a user namespace that maps only a
    few ids (``unshare -r``, rootless Podman/Docker, Kubernetes user
    namespaces map 1 to 65536), chown, setgid and setuid to a sandbox id fail
    with EINVAL. Without a uid of its own a learner's program would keep the
    dashboard's (root's capabilities in the namespace included), signal its
    processes and share its process limit: it would not be contained.
    """
    if os.geteuid() != 0:
        return "the sandbox needs root: it runs learner code under a uid of its own"
    if not (_maps_sandbox_ids("/proc/self/uid_map") and _maps_sandbox_ids("/proc/self/gid_map")):
        return (
            "this user namespace (a rootless container, a Kubernetes user namespace, "
            "`unshare --map-root-user`) does not map the uids and gids "
            f"{UID_BASE}..{UID_BASE + PID_MAX_LIMIT} that learner programs run under, so they "
            "cannot be kept apart from the dashboard; run it as real root, or map that range "
            "into the container"
        )
    return None


def python_paths() -> list[str]:
    """Where this Python and its packages live: readable even inside a home folder."""
    paths = {sys.prefix, sys.base_prefix, sys.exec_prefix, sys.base_exec_prefix}
    paths.add(os.path.dirname(os.path.realpath(sys.executable)))
    paths.update(p for p in sys.path if p and os.path.isdir(p))
    return sorted({os.path.realpath(p) for p in paths})


def _unreachable(path: str) -> str | None:
    """The first folder on the way to ``path`` that the sandbox user may not enter.

    It enters a folder open to others, or one of the sandbox group (a
    learner's scratch folder, their workspace on a served dashboard).
    """
    folder = "/"
    for part in [""] + path.strip("/").split("/"):
        folder = os.path.join(folder, part)
        info = os.stat(folder)
        if not (
            info.st_mode & stat.S_IXOTH
            or (info.st_gid == SANDBOX_GID and info.st_mode & stat.S_IXGRP)
        ):
            return folder
    return None


def missing() -> str | None:
    """None when this machine can contain learner code, else what is missing (one line)."""
    if not sys.platform.startswith("linux"):
        return "the sandbox needs Linux"
    if platform.machine() not in _SYSCALLS:
        return f"the sandbox knows no seccomp syscall table for {platform.machine()}"
    if problem := identity_problem():
        return problem
    for path in python_paths():
        if blocked := _unreachable(path):
            return (
                f"the sandbox user cannot enter {blocked} on the way to Python ({path}): "
                f"`chmod o+x {blocked}` or use a Python installed elsewhere"
            )
    abi = landlock_abi()
    if abi < MIN_LANDLOCK_ABI:
        return f"Landlock ABI {abi}: the sandbox needs {MIN_LANDLOCK_ABI} (Linux 6.12+)"
    action = ctypes.c_uint32(_RET_ERRNO)
    try:
        _syscall(_arch()["seccomp"], _SECCOMP_GET_ACTION_AVAIL, 0, ctypes.byref(action))
    except OSError:
        return "seccomp filters are not available in this kernel"
    return None


# --- leftovers ---------------------------------------------------------------


def _real_uid(pid: int) -> int | None:
    """Real uid of a live process; None for a zombie or a process that is gone."""
    uid = None
    try:
        with open(f"/proc/{pid}/status") as status:
            for line in status:
                if line.startswith("State:") and line.split()[1] in ("Z", "X"):
                    return None
                if line.startswith("Uid:"):
                    uid = int(line.split()[1])
    except (OSError, ValueError, IndexError):
        return None
    return uid


def sandbox_processes(launcher_pid: int | None = None) -> list[int]:
    """Live pids under a sandbox uid: one launcher's, or (None) those whose launcher is gone.

    A launcher runs as ``UID_BASE + its pid``, and so does everything it forks;
    no contained process can change its uid. So "uid of a dead launcher" means
    "left behind", e.g. a child that outlived a SIGKILLed launcher.
    """
    found = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        uid = _real_uid(int(entry))
        if uid is None or not UID_BASE < uid <= UID_BASE + PID_MAX_LIMIT:
            continue
        owner = uid - UID_BASE
        if launcher_pid is None:
            if _real_uid(owner) != uid:  # its launcher ended (or the pid is someone else's now)
                found.append(int(entry))
        elif owner == launcher_pid:
            found.append(int(entry))
    return found


def kill_processes(pids: Sequence[int]) -> int:
    killed = 0
    for pid in pids:
        try:
            os.kill(pid, signal.SIGKILL)
            killed += 1
        except ProcessLookupError:
            pass
    return killed


# --- the containment steps ---------------------------------------------------


def _set_limits(args: argparse.Namespace) -> None:
    cpu = args.cpu_seconds
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu + 2))  # SIGXCPU, then SIGKILL
    for which, value in (
        (resource.RLIMIT_AS, args.memory_bytes),
        (resource.RLIMIT_NPROC, args.processes),
        (resource.RLIMIT_FSIZE, args.file_bytes),
        (resource.RLIMIT_NOFILE, args.open_files),
    ):
        resource.setrlimit(which, (value, value))
    # glibc reserves 64 MiB of address space per malloc arena, up to 8 per core:
    # on a big machine that alone would eat the address-space limit.
    _libc.mallopt(_M_ARENA_MAX, 2)


def _is_within(path: str, folder: str) -> bool:
    return path == folder or path.startswith(folder.rstrip("/") + "/")


def _readable(hidden: Sequence[str], path: str = "/") -> Iterator[str]:
    """The fewest paths whose subtrees cover the whole file system except ``hidden``.

    Landlock only grants, so a hidden folder's ancestors are split into their
    entries instead of granted whole; those ancestors cannot be listed, which
    also keeps the names inside them private. Symlinks are skipped: their
    targets get their own rule (or none).
    """
    if any(_is_within(path, h) for h in hidden):
        return
    if not any(_is_within(h, path) for h in hidden):
        yield path
        return
    try:
        entries = list(os.scandir(path))
    except OSError:
        return
    for entry in entries:
        if not entry.is_symlink():
            yield from _readable(hidden, entry.path)


def _add_rule(ruleset: int, path: str, access: int) -> None:
    try:
        fd = os.open(path, os.O_PATH | os.O_NOFOLLOW | os.O_CLOEXEC)
    except OSError:
        return  # gone meanwhile: nothing to grant
    try:
        if not stat.S_ISDIR(os.fstat(fd).st_mode):
            access &= _LL_FILE_ONLY
        rule = _PathBeneath(access, fd)
        _syscall(_SYS_LANDLOCK_ADD_RULE, ruleset, _LL_RULE_PATH_BENEATH, ctypes.byref(rule), 0)
    finally:
        os.close(fd)


def _landlock(scratch: str, hidden: Sequence[str], writable: Sequence[str] = ()) -> None:
    abi = landlock_abi()
    if abi < MIN_LANDLOCK_ABI:
        raise SandboxError(f"Landlock ABI {abi} < {MIN_LANDLOCK_ABI}")
    fs = _LL_FS_BY_ABI[max(v for v in _LL_FS_BY_ABI if v <= abi)]
    attr = _RulesetAttr(
        fs, _LL_NET_BIND_TCP | _LL_NET_CONNECT_TCP, _LL_SCOPE_ABSTRACT_UNIX | _LL_SCOPE_SIGNAL
    )
    ruleset = _syscall(_SYS_LANDLOCK_CREATE_RULESET, ctypes.byref(attr), ctypes.sizeof(attr), 0)
    try:
        for path in _readable([*hidden, *HOMES]):
            _add_rule(ruleset, path, _READ)
        for place in python_paths():
            for path in _readable(hidden, place):
                _add_rule(ruleset, path, _READ)
        for folder in (scratch, *writable):
            _add_rule(ruleset, folder, fs)
        for device in _WRITABLE_DEVICES:
            _add_rule(ruleset, device, _LL_READ_FILE | _LL_WRITE_FILE | _LL_TRUNCATE)
        _syscall(_SYS_LANDLOCK_RESTRICT_SELF, ruleset, 0)
    finally:
        os.close(ruleset)


def _open_scratch_to_group(scratch: str) -> None:
    """Let the sandbox group write the scratch folder: the folder only, no tree walk as root."""
    fd = os.open(scratch, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | os.O_CLOEXEC)
    try:
        os.fchown(fd, -1, SANDBOX_GID)
        os.fchmod(fd, 0o2770)  # setgid: what anyone creates there stays in the group
    finally:
        os.close(fd)


def _read_script(script: str) -> bytes:
    """Read as root, before the drop: the dashboard writes the copy 0600."""
    fd = os.open(script, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC)
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise SandboxError(f"{script} is not a regular file")
        chunks = []
        while chunk := os.read(fd, 1 << 20):
            chunks.append(chunk)
        return b"".join(chunks)
    finally:
        os.close(fd)


def _become_sandbox_user(parent: int) -> int:
    uid = UID_BASE + os.getpid()
    os.setgroups([])
    os.setresgid(SANDBOX_GID, SANDBOX_GID, SANDBOX_GID)
    os.setresuid(uid, uid, uid)  # all capabilities go with uid 0
    # A change of credentials clears the parent-death signal: set it again, then
    # make sure the parent did not die in between.
    if _libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) != 0 or os.getppid() != parent:
        os._exit(EXIT_LIMIT)
    return uid


def _environment(scratch: str, dds_profile: str | None) -> None:
    env = os.environ
    tmp = os.path.join(scratch, ".tmp")
    os.makedirs(tmp, exist_ok=True)
    # LTTng (loaded by rclpy) would wait 3 s for a tracing daemon it cannot reach from here.
    env.update(HOME=scratch, TMPDIR=tmp, LTTNG_UST_REGISTER_TIMEOUT="0")
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS"):  # else one thread per core
        env.setdefault(var, "1")
    env["RMW_IMPLEMENTATION"] = "rmw_fastrtps_cpp"  # the bootstrap relies on Fast DDS
    if dds_profile:
        env["FASTRTPS_DEFAULT_PROFILES_FILE"] = dds_profile
        env["CLASSROOM_DDS_NETWORK"] = "0"
        env.pop("ROS_AUTOMATIC_DISCOVERY_RANGE", None)
        env.pop("ROS_STATIC_PEERS", None)


_bootstrap_node: object = None  # keeps the DDS participant alive


def _join_ros_graph(argv: list[str]) -> None:
    """Create the DDS participant (and its sockets) now, while sockets may still be made."""
    global _bootstrap_node
    if importlib.util.find_spec("rclpy") is None:
        return  # no ROS here: nothing to join
    import rclpy
    import rclpy.utilities

    rclpy.init(args=[*argv, "--ros-args", "--disable-external-lib-logs"])
    _bootstrap_node = rclpy.create_node(
        f"{BOOTSTRAP_NODE}_{os.getpid()}",
        use_global_arguments=False,  # the learner's remappings are for their node
        enable_rosout=False,
        start_parameter_services=False,
    )
    real_init = rclpy.init
    default_context = rclpy.utilities.get_default_context()

    def init(**kwargs: object) -> None:
        """The sandbox already initialised ROS (with these arguments); a no-op then."""
        context = kwargs.get("context") or default_context
        if context is default_context and default_context.ok():
            return
        real_init(**kwargs)  # type: ignore[arg-type]

    rclpy.init = init


def _pin_sockets_to_loopback() -> int:
    """Pin every IP socket to ``lo``; refuse one bound to a non-loopback address.

    Fast DDS keeps a few sockets it never binds (it queries interfaces with
    them when the machine has more than ``lo``); those get 127.0.0.1 too, so
    that routing refuses any non-loopback destination from them. Undoing
    SO_BINDTODEVICE needs CAP_NET_RAW, which the learner lacks.
    """
    pinned = 0
    for name in os.listdir("/proc/self/fd"):
        fd = int(name)
        try:
            if not stat.S_ISSOCK(os.fstat(fd).st_mode):
                continue
            sock = socket.socket(fileno=os.dup(fd))
        except OSError:
            continue
        with sock:
            if sock.family not in (socket.AF_INET, socket.AF_INET6):
                continue
            address, port = sock.getsockname()[:2]
            if port == 0 and ipaddress.ip_address(address).is_unspecified:
                sock.bind(("127.0.0.1" if sock.family == socket.AF_INET else "::1", 0))
                address = sock.getsockname()[0]
            if not ipaddress.ip_address(address).is_loopback:
                raise SandboxError(
                    f"a DDS socket is bound to {address}, not loopback: "
                    "is the loopback profile (FASTRTPS_DEFAULT_PROFILES_FILE) in use?"
                )
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_BINDTODEVICE, b"lo")
            pinned += 1
    return pinned


Jump = str | int  # a label, or 0 for "the next instruction"


def _bpf_program() -> bytes:
    """The seccomp filter in classic BPF; a string in the list is a label."""
    nr = _arch()
    ld, jeq, jset, ret = 0x20, 0x15, 0x45, 0x06  # BPF_LD|W|ABS, JMP|JEQ|K, JMP|JSET|K, RET|K
    arch, number, arg0 = 4, 0, 16  # offsets in struct seccomp_data (arg0: low half)
    code: list[str | tuple[int, Jump, Jump, int]] = [
        (ld, 0, 0, arch),
        (jeq, 0, "kill", nr["arch"]),  # e.g. i386 syscalls from a 64-bit process
        (ld, 0, 0, number),
        (jeq, "socket", 0, nr["socket"]),
        (jeq, "clone", 0, nr["clone"]),
        (jeq, "enosys", 0, nr["clone3"]),  # flags behind a pointer; glibc falls back to clone
        *[(jeq, "eperm", 0, nr[name]) for name in _DENIED],
        (ret, 0, 0, _RET_ALLOW),
        "socket",
        (ld, 0, 0, arg0),
        (jeq, "allow", "eperm", socket.AF_UNIX),
        "clone",
        (ld, 0, 0, arg0),
        (jset, "eperm", "allow", _CLONE_NAMESPACES),
        "allow",
        (ret, 0, 0, _RET_ALLOW),
        "eperm",
        (ret, 0, 0, _RET_ERRNO | errno.EPERM),
        "enosys",
        (ret, 0, 0, _RET_ERRNO | errno.ENOSYS),
        "kill",
        (ret, 0, 0, _RET_KILL_PROCESS),
    ]
    labels: dict[str, int] = {}
    body: list[tuple[int, Jump, Jump, int]] = []
    for item in code:
        if isinstance(item, str):
            labels[item] = len(body)
        else:
            body.append(item)

    def offset(here: int, jump: Jump) -> int:
        return labels[jump] - here - 1 if isinstance(jump, str) else jump

    return b"".join(
        struct.pack("<HBBI", op, offset(i, jt), offset(i, jf), k)
        for i, (op, jt, jf, k) in enumerate(body)
    )


class _SockFprog(ctypes.Structure):
    _fields_ = [("len", ctypes.c_uint16), ("filter", ctypes.c_void_p)]


def _seccomp() -> None:
    program = ctypes.create_string_buffer(_bpf_program())
    fprog = _SockFprog(len(program.raw) // 8, ctypes.addressof(program))
    # TSYNC: Fast DDS's threads exist already and must carry the filter too.
    result = _syscall(
        _arch()["seccomp"],
        _SECCOMP_SET_MODE_FILTER,
        _SECCOMP_FILTER_FLAG_TSYNC,
        ctypes.byref(fprog),
    )
    if result != 0:
        raise SandboxError(f"seccomp could not reach thread {result}")


# --- running the learner's script -------------------------------------------


class _Learner:
    """What the messages need to know about this run."""

    launcher = os.getpid()
    limits: argparse.Namespace
    script = ""
    scratch = ""
    launcher_module: object = None


def _on_cpu_limit(signum: int, frame: object) -> None:
    _say(f"CPU time limit of {_Learner.limits.cpu_seconds} s reached")
    _kill_descendants()
    signal.signal(signal.SIGXCPU, signal.SIG_DFL)
    os.kill(os.getpid(), signal.SIGXCPU)


def _say(message: str) -> None:
    try:
        sys.stdout.flush()
    except Exception:
        pass
    os.write(2, f"sandbox: {message}\n".encode())


def _kill_descendants() -> None:
    """Everything this sandbox forked (same uid; Landlock scopes signals to this sandbox)."""
    if os.getpid() == _Learner.launcher:
        try:
            os.kill(-1, signal.SIGKILL)  # never signals the caller itself
        except OSError:
            pass


def _hint(exc: BaseException) -> str | None:
    """One line saying which sandbox limit explains ``exc``, if one does."""
    limits = _Learner.limits
    if isinstance(exc, MemoryError):
        return f"memory limit of {limits.memory_bytes // 2**20} MiB reached"
    if isinstance(exc, RuntimeError) and "can't start new thread" in str(exc):
        return f"process limit of {limits.processes} reached (threads count too)"
    if not isinstance(exc, OSError):
        return None
    if exc.errno == errno.EFBIG:
        return f"file size limit of {limits.file_bytes // 2**20} MiB reached"
    if exc.errno in (errno.ENFILE, errno.EMFILE):
        return f"open files limit of {limits.open_files} reached"
    text = "".join(traceback.format_exception(type(exc), exc, exc.__traceback__))
    if exc.errno == errno.EAGAIN and ("fork" in text or "_execute_child" in text):
        return f"process limit of {limits.processes} reached (threads count too)"
    if exc.errno in (errno.EPERM, errno.EACCES):
        return (
            f"blocked: contained code may write only in {_Learner.scratch}, "
            "opens no network connection (ROS 2 works) and cannot read other learners' files"
        )
    return None


def _print_learner_traceback(exc: BaseException) -> None:
    """The traceback from the learner's file down, as ``python script.py`` would print it."""
    tb = exc.__traceback__
    while tb is not None and tb.tb_frame.f_code.co_filename != _Learner.script:
        tb = tb.tb_next
    traceback.print_exception(type(exc), exc, tb or exc.__traceback__)


def _run(script: str, source: bytes) -> int:
    _Learner.launcher_module = sys.modules["__main__"]  # keep our globals alive
    main = types.ModuleType("__main__")
    main.__dict__.update(__file__=script, __builtins__=builtins, __cached__=None)
    sys.modules["__main__"] = main
    linecache.cache[script] = (
        len(source),
        None,
        source.decode(errors="replace").splitlines(True),
        script,
    )
    try:
        exec(compile(source, script, "exec", dont_inherit=True), main.__dict__)
    except SystemExit:
        raise
    except KeyboardInterrupt:
        raise
    except MemoryError as exc:
        hint = _hint(exc)
        del exc  # its traceback holds the frames that hold the memory
        _say(hint or "memory limit reached")
        return EXIT_LIMIT
    except BaseException as exc:
        hint = _hint(exc)
        _print_learner_traceback(exc)
        if hint:
            _say(hint)
        return 1
    return 0


def _parse(argv: Sequence[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="contain", description=__doc__.split("\n")[0])
    parser.add_argument("--scratch", required=True, help="the only writable folder")
    parser.add_argument("--hide", action="append", default=[], help="a folder it may not read")
    parser.add_argument(
        "--write", action="append", default=[], help="another folder it may write (a build's)"
    )
    parser.add_argument(
        "--no-ros", action="store_true", help="join no ROS graph: no socket but Unix ones"
    )
    parser.add_argument("--cpu-seconds", type=int, default=300)
    parser.add_argument("--memory-bytes", type=int, default=2 * 1024**3)
    parser.add_argument("--processes", type=int, default=64)
    parser.add_argument("--file-bytes", type=int, default=64 * 1024**2)
    parser.add_argument("--open-files", type=int, default=256)
    parser.add_argument("--dds-profile", help="Fast DDS profile (loopback only) to force")
    parser.add_argument("script")
    parser.add_argument("args", nargs=argparse.REMAINDER)
    return parser.parse_args(argv)


def main(argv: Sequence[str] | None = None) -> int:
    args = _parse(sys.argv[1:] if argv is None else argv)
    parent = os.getppid()
    if problem := missing():
        print(f"sandbox: cannot contain this program: {problem}", file=sys.stderr)
        return 2
    scratch = os.path.realpath(args.scratch)
    script = os.path.realpath(args.script)
    hidden = [os.path.realpath(h) for h in args.hide]
    writable = [os.path.realpath(w) for w in args.write]
    _Learner.limits, _Learner.script, _Learner.scratch = args, script, scratch
    if sys.path and os.path.realpath(sys.path[0]) == os.path.dirname(os.path.realpath(__file__)):
        del sys.path[0]  # our own folder: not the learner's business

    for folder in (scratch, *writable):
        if blocked := _unreachable(os.path.dirname(folder)):
            raise SandboxError(f"the sandbox user cannot enter {blocked} to reach {folder}")

    # As root: tidy up, open the scratch folder to the sandbox group, read the script.
    kill_processes(sandbox_processes())  # what SIGKILLed launchers left behind
    kill_processes(sandbox_processes(os.getpid()))  # a former launcher with our pid
    try:
        for folder in (scratch, *writable):
            _open_scratch_to_group(folder)
        source = _read_script(script)
    except OSError as exc:
        raise SandboxError(str(exc)) from None

    _set_limits(args)
    if _libc.prctl(_PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0:
        raise SandboxError("prctl(PR_SET_NO_NEW_PRIVS) failed")
    _landlock(scratch, hidden, writable)
    _become_sandbox_user(parent)
    os.umask(0o007)
    _environment(scratch, args.dds_profile)
    learner_argv = [script, *args.args]
    if not args.no_ros:
        _join_ros_graph(learner_argv)
    _pin_sockets_to_loopback()
    _seccomp()

    signal.signal(signal.SIGXCPU, _on_cpu_limit)
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # EFBIG, a readable error, not a silent kill
    atexit.register(_kill_descendants)
    sys.argv = learner_argv
    sys.path.insert(0, os.path.dirname(script))
    os.chdir(scratch)
    return _run(script, source)


def _exit_code(code: object) -> int:
    if code is None or isinstance(code, int):
        return code or 0
    print(code, file=sys.stderr)
    return 1


if __name__ == "__main__":
    try:
        status: object = main()
    except SandboxError as exc:
        print(f"sandbox: cannot contain this program: {exc}", file=sys.stderr)
        status = 2
    except SystemExit as exc:
        status = exc.code
    if os.getpid() != _Learner.launcher:
        # A fork of the learner's ends here: the parent's atexit handlers and the
        # teardown of a DDS participant whose threads it does not have are not its own.
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(_exit_code(status))
    sys.exit(_exit_code(status))

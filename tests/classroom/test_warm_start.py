"""Warm start: learners' dashboards fork from one warm parent that imported all and started nothing.

The warm parent (app/warm_start.py) is checked from outside: its threads, its
open files, what its forks are (their own pid, session, environment, command
line, this process as their parent) and that they share no written memory;
then a warm parent that dies (restarted, said so, its forks unharmed), a fork
that fails (answered, so the learner starts cold), a learner killed while it
starts (nothing left), and the classroom itself: two learners started warm,
each served on its own port and domain, and a classroom whose warm parent
cannot start (everyone cold, said so).
"""

from __future__ import annotations

import array
import errno
import json
import os
import pwd
import re
import shutil
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request
from pathlib import Path

import psutil
import pytest

import app.dds
import app.warm_start as warm_start
from app import PROJECT_ROOT
from app.classroom import Classroom, plan
from app.warm_start import Credentials, WarmParent, WarmStarter, WarmStartError
from tests.conftest import free_port, wait_until
from tests.wire_client import WireClient

pytestmark = pytest.mark.ros

PROBE = [sys.executable, "-m", "tests.classroom.warm_probe"]


@pytest.fixture
def said() -> list[str]:
    return []


@pytest.fixture
def starter(ros_env, said):
    warm = WarmStarter(ros_env, say=said.append)
    try:
        warm.start()
        yield warm
    finally:
        warm.close()


def _lines(stream, out: list[str]) -> threading.Thread:
    """Read a child's output into ``out`` (a thread, so its pipe never fills)."""

    def read() -> None:
        for raw in stream:
            out.append(raw.decode(errors="replace"))
        stream.close()

    thread = threading.Thread(target=read, daemon=True)
    thread.start()
    return thread


def _show(starter: WarmStarter, env: dict[str, str]) -> dict:
    child = starter.spawn([*PROBE, "show"], env, PROJECT_ROOT)
    assert child.stdout is not None
    out = child.stdout.read().decode()
    assert child.wait(10) == 0, out
    return json.loads(out.strip().splitlines()[-1])


def _session_members(sid: int) -> list[int]:
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                if int((entry / "stat").read_text().rsplit(")", 1)[1].split()[3]) == sid:
                    found.append(int(entry.name))
            except (OSError, IndexError, ValueError):
                continue
    return found


def _our_zombies() -> list[int]:
    me = psutil.Process()
    return [p.pid for p in me.children() if p.status() == psutil.STATUS_ZOMBIE]


def _port_free(port: int) -> bool:
    with socket.socket() as probe:
        try:
            probe.bind(("127.0.0.1", port))
        except OSError:
            return False
    return True


def test_warm_parent_imports_everything_and_starts_nothing(starter, ros_env):
    ready = starter.ready
    assert ready["missing"] == [], ready  # every module a dashboard imports by its ready line
    assert ready["threads"] == 1 and ready["python_threads"] == ["MainThread"], ready
    assert ready["open_files"] == [], ready
    pid = starter.pid
    # From outside: one thread; stdin, stdout, stderr and one socket (the classroom's pair).
    assert os.listdir(f"/proc/{pid}/task") == [str(pid)]
    files = {int(fd): os.readlink(f"/proc/{pid}/fd/{fd}") for fd in os.listdir(f"/proc/{pid}/fd")}
    assert files.pop(0) == "/dev/null"
    assert files.pop(1).startswith("pipe:") and files.pop(2).startswith("pipe:")
    assert len(files) == 1 and next(iter(files.values())).startswith("socket:"), files
    process = psutil.Process(pid)
    assert process.ppid() == os.getpid()  # the classroom's child (adopted), not an orphan
    assert process.cmdline()[-2:] == ["-m", "app.warm_start"]
    assert not process.net_connections(kind="inet")  # no DDS participant, no server
    assert len(process.net_connections(kind="unix")) == 1  # the classroom's socket pair
    # A fork gets what a cold process that loads rclpy gets: LTTng's listener threads too.
    cold = subprocess.run(
        [sys.executable, "-c", "import os, rclpy; print(len(os.listdir('/proc/self/task')))"],
        cwd=PROJECT_ROOT, env=ros_env, capture_output=True, text=True, timeout=60, check=True,
    )  # fmt: skip
    assert _show(starter, dict(starter.env))["threads"] == int(cold.stdout)


def test_no_warm_import_keeps_what_differs_between_hub_learners(ros_env, tmp_path):
    """HOME is not a start-up variable (each hub learner has their own): nothing keeps it.

    Imported once with every per-learner variable set to a marked value, no module
    keeps one; the one known keeper, ``site.USER_SITE`` (from HOME), shows the look
    finds what it is after, and a venv never reads it.
    """
    per_learner = {
        "HOME": str(tmp_path / "home-sentinel"),
        "USER": "user-sentinel",
        "ROS_DOMAIN_ID": "93",
        "CLASSROOM_TOKEN": "classroom-token-sentinel",
        "CLASSROOM_TEACHER_URL": "http://teacher-sentinel/",
        "JUPYTERHUB_API_TOKEN": "hub-token-sentinel",
        "JUPYTERHUB_USER": "hub-user-sentinel",
        "JUPYTERHUB_SERVICE_PREFIX": "/user/prefix-sentinel/",
        "JUPYTERHUB_API_URL": "http://hub-sentinel/hub/api",
        "JUPYTERHUB_CLIENT_ID": "client-sentinel",
        "JUPYTERHUB_OAUTH_CALLBACK_URL": "/user/callback-sentinel/oauth_callback",
    }
    done = subprocess.run(
        [*PROBE, "kept"],
        env={**ros_env, **per_learner},
        cwd=PROJECT_ROOT,
        capture_output=True,
        text=True,
        timeout=180,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    hits = json.loads(done.stdout.strip().splitlines()[-1])
    assert sorted(hits) == ["HOME site.USER_BASE", "HOME site.USER_SITE"], hits
    assert not warm_start.STARTUP_VARS.match("HOME")
    import site

    assert not site.ENABLE_USER_SITE  # the project's venv: user site-packages are never read


def test_each_fork_is_its_own_process(starter):
    env_a = {**starter.env, "CLASSROOM_TOKEN": "token-of-alpha"}
    env_b = {**starter.env, "CLASSROOM_TOKEN": "token-of-beta"}
    a = _show(starter, env_a)
    b = _show(starter, env_b)
    for shown, token in ((a, "token-of-alpha"), (b, "token-of-beta")):
        assert shown["ppid"] == os.getpid()  # the classroom waits for it, as for a cold start
        assert shown["sid"] == shown["pid"]  # own session and process group
        assert shown["token"] == token  # its own environment, never another learner's
        assert shown["proc_token"] == token  # also where `ps e` and psutil read it
        assert shown["cwd"] == str(PROJECT_ROOT)
        assert shown["argv"] == ["show"]
        assert shown["cmdline"] == " ".join([*PROBE, "show"])  # what `ps` shows
        # Nothing leads back to the warm parent or another learner: no socket, no other pipe.
        assert not [f for f in shown["files"] if f.startswith("socket:")], shown["files"]
        assert len({f for f in shown["files"] if f.startswith("pipe:")}) == 1, shown["files"]
    assert a["pid"] != b["pid"]


def test_a_fork_becomes_the_learners_account_before_it_runs_their_command(starter):
    """As the hub's system-user spawner asks: uid, gid and groups switched, and what the
    switch undoes set back (its own /proc readable by itself, the parent-death signal)."""
    nobody = pwd.getpwnam("nobody")
    user = Credentials(nobody.pw_uid, nobody.pw_gid, (nobody.pw_gid,))
    # The probe where any account can read it (pytest's folders are the test's own).
    shared = Path(tempfile.mkdtemp(prefix="warm-probe-", dir="/var/tmp"))
    try:
        shared.chmod(0o755)
        shutil.copy(Path(__file__).with_name("warm_probe.py"), shared / "warm_probe.py")
        (shared / "warm_probe.py").chmod(0o644)
        env = {**starter.env, "CLASSROOM_TOKEN": "token-of-nobody"}
        child = starter.spawn([sys.executable, "-m", "warm_probe", "show"], env, shared, user)
        assert child.stdout is not None
        out = child.stdout.read().decode()
        assert child.wait(10) == 0, out
    finally:
        shutil.rmtree(shared)
    shown = json.loads(out.strip().splitlines()[-1])
    assert (shown["uid"], shown["euid"], shown["gid"]) == (nobody.pw_uid,) * 2 + (nobody.pw_gid,)
    assert shown["groups"] == [nobody.pw_gid]  # none of the warm parent's (root's) groups
    assert shown["proc_token"] == "token-of-nobody"  # dumpable again: /proc/self is its own
    assert shown["pdeathsig"] == signal.SIGTERM  # the switch cleared it; set again
    assert shown["ppid"] == os.getpid() and shown["cwd"] == str(shared)


def test_memory_written_by_one_fork_is_not_seen_by_another(starter):
    writer = starter.spawn([*PROBE, "write", "alphaalpha"], dict(starter.env), PROJECT_ROOT)
    out: list[str] = []
    reader_thread = _lines(writer.stdout, out)
    try:
        wait_until(lambda: any(line.startswith("written") for line in out), what="the write")
        written = json.loads(next(line for line in out if line.startswith("written"))[8:])
        assert written["module_attribute"] == "alphaalpha"
        assert written["string_start"] == "alphaalpha!!"  # its own page, written in place
        reader = starter.spawn([*PROBE, "read"], dict(starter.env), PROJECT_ROOT)
        seen = json.loads(reader.stdout.read().decode().strip().splitlines()[-1])
        assert reader.wait(10) == 0
    finally:
        writer.terminate()
        writer.wait(10)
        reader_thread.join(5)
    original = (app.dds.__doc__ or "")[:12]
    assert seen == {"module_attribute": None, "path_entry": [], "string_start": original}


def test_a_warm_parent_that_dies_is_restarted_and_its_forks_live_on(starter, said):
    sleeper = starter.spawn([*PROBE, "sleep"], dict(starter.env), PROJECT_ROOT)
    first = starter.pid
    try:
        os.kill(first, signal.SIGKILL)
        wait_until(lambda: not psutil.pid_exists(first) or _our_zombies(), what="its death")
        shown = _show(starter, dict(starter.env))  # waits for the restart, then forks
        assert starter.pid != first
        assert shown["ppid"] == os.getpid()
        assert sleeper.poll() is None  # a learner is no child of the warm parent
        joined = "\n".join(said)
        assert f"the warm parent (pid {first}) ended (killed by SIGKILL); restarting it" in joined
        assert f"the warm parent is back (pid {starter.pid}" in joined
    finally:
        sleeper.terminate()
        assert sleeper.wait(10) == -signal.SIGTERM


def test_a_fork_that_fails_is_answered(monkeypatch):
    """The warm parent answers a failed fork with the reason; the classroom then starts cold."""
    ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
    out_r, out_w = os.pipe()
    go_r, go_w = os.pipe()

    def no_fork() -> int:
        raise OSError(errno.EAGAIN, "Resource temporarily unavailable")

    monkeypatch.setattr(os, "fork", no_fork)
    try:
        header = json.dumps({"id": 7, "argv": [*PROBE, "show"], "cwd": "/"}).encode()
        ours.sendmsg(
            [struct.pack("!I", len(header)), header, b"CLASSROOM_TOKEN=secret\0"],
            [(socket.SOL_SOCKET, socket.SCM_RIGHTS, array.array("i", [out_w, go_r]))],
        )
        ours.shutdown(socket.SHUT_WR)
        parent = WarmParent(theirs, warm_start._LttngUst([]), os.getppid())
        assert parent.serve() is None  # the request answered, then the end of the socket
        reply = json.loads(ours.recv(4096))
        assert reply["id"] == 7 and "Resource temporarily unavailable" in reply["error"]
    finally:
        for fd in (out_r, out_w, go_r, go_w):
            try:
                os.close(fd)
            except OSError:
                pass  # the warm parent closes what it was sent
        ours.close()
        theirs.close()


def test_a_learner_killed_while_it_starts_leaves_nothing(starter, ros_env, tmp_path):
    shm_before = set(os.listdir("/dev/shm"))
    for delay in (0.0, 1.0):
        port = free_port()
        argv = [sys.executable, "-m", "app", "serve", "--port", str(port),
                "--domain-id", ros_env["ROS_DOMAIN_ID"], "--progress-dir",
                str(tmp_path / f"progress-{delay}")]  # fmt: skip
        child = starter.spawn(argv, {**starter.env, **ros_env}, PROJECT_ROOT)
        out: list[str] = []
        reader = _lines(child.stdout, out)
        time.sleep(delay)
        child.kill()
        assert child.wait(10) == -signal.SIGKILL
        reader.join(10)
        assert not reader.is_alive(), "its output pipe stayed open"
        wait_until(lambda c=child: not _session_members(c.pid), what="its session to empty")
        assert not _our_zombies()
        assert _port_free(port)
    assert set(os.listdir("/dev/shm")) <= shm_before
    assert _show(starter, dict(starter.env))["ppid"] == os.getpid()  # the warm parent serves on


def _start_room(ros_env, tmp_path, learners: int) -> tuple[subprocess.Popen, list[str], int, int]:
    base_port = free_port()
    while not all(_port_free(base_port + i) for i in range(-1, learners)):
        base_port = free_port()
    base_domain = int(ros_env["ROS_DOMAIN_ID"]) % 90 + 1
    room = subprocess.Popen(
        [sys.executable, "-m", "app", "classroom", "--learners", str(learners),
         "--base-port", str(base_port), "--base-domain-id", str(base_domain),
         "--progress-dir", str(tmp_path)],
        cwd=PROJECT_ROOT, env=ros_env, stdout=subprocess.PIPE, text=True,
    )  # fmt: skip
    lines: list[str] = []
    assert room.stdout is not None
    while not lines or "Press Ctrl+C" not in lines[-1]:
        line = room.stdout.readline()
        if not line:
            room.wait(10)
            pytest.fail(f"the classroom ended early: {lines}")
        lines.append(line)
    return room, lines, base_port, base_domain


def test_a_classroom_starts_two_learners_warm(ros_env, tmp_path):
    room, lines, base_port, base_domain = _start_room(ros_env, tmp_path, 2)
    clients: list[WireClient] = []
    try:
        text = "".join(lines)
        assert re.search(r"Warm start: the dashboards fork from one warm parent \(pid \d+\)", text)
        assert "starting it cold" not in text
        learners = [p for p in psutil.Process(room.pid).children() if "serve" in p.cmdline()]
        assert len(learners) == 2  # the classroom's children, as cold ones are
        for i in range(2):
            port = base_port + i
            with urllib.request.urlopen(f"http://127.0.0.1:{port}", timeout=10) as page:
                assert page.status == 200
            assert any(str(port) in p.cmdline() for p in learners)  # `ps` tells them apart
            client = WireClient(f"http://127.0.0.1:{port}")
            clients.append(client)
            wait_until(
                lambda c=client, d=base_domain + i: f"Domain id **{d}**" in c.markdown(),
                what=f"learner{i + 1}'s domain id",
            )
        descendants = psutil.Process(room.pid).children(recursive=True)
    finally:
        for client in clients:
            client.close()
        room.send_signal(signal.SIGINT)
        code = room.wait(timeout=30)
    assert code == 0
    assert not [p for p in descendants if p.is_running() and p.status() != psutil.STATUS_ZOMBIE]


def test_a_killed_classroom_takes_its_warm_learners_and_warm_parent_along(ros_env, tmp_path):
    room, lines, _, _ = _start_room(ros_env, tmp_path, 2)
    try:
        children = psutil.Process(room.pid).children()
        assert len(children) == 3, [c.cmdline() for c in children]  # 2 learners, 1 warm parent
    finally:
        room.kill()  # no Ctrl+C, no stop(): only the parent-death signal is left
        room.wait(10)

    def alive() -> list[str]:
        return [
            " ".join(c.cmdline()[1:5])
            for c in children
            if c.is_running() and c.status() != psutil.STATUS_ZOMBIE
        ]

    wait_until(lambda: not alive(), timeout=20, what=lambda: f"these to end: {alive()}")


def test_a_classroom_whose_warm_parent_cannot_start_starts_everyone_cold(
    ros_env, tmp_path, monkeypatch
):
    monkeypatch.setattr(warm_start, "PARENT_MODULE", "tests.classroom.no_such_warm_parent")
    said: list[str] = []
    learners = plan(2, base_port=free_port(), base_domain=int(ros_env["ROS_DOMAIN_ID"]) % 90 + 1,
                    progress_root=tmp_path)  # fmt: skip
    while not all(_port_free(learner.port) for learner in learners):
        learners = plan(2, base_port=free_port(), base_domain=learners[0].domain_id,
                        progress_root=tmp_path)  # fmt: skip
    room = Classroom(learners, ros_env, say=said.append)
    try:
        room.start()
        assert room.wait_ready() == []
        for learner in learners:
            with urllib.request.urlopen(f"http://127.0.0.1:{learner.port}", timeout=10) as page:
                assert page.status == 200
        pids = list(room.pids().values())
    finally:
        room.stop()
    assert any(
        line.startswith("Warm start unavailable (") and "every dashboard starts cold" in line
        for line in said
    ), said
    assert "no_such_warm_parent" in "\n".join(said)  # the reason, in the IT person's log
    assert not [pid for pid in pids if psutil.pid_exists(pid)]
    with pytest.raises(WarmStartError):
        WarmStarter(ros_env).start()  # the same, seen directly

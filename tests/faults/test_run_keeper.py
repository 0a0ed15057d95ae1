"""`make test` killed from outside still ends everything it started.

pytest dies on SIGTERM without its teardown, and a dashboard or a node a test
started lives in a session of its own, so it used to run on as an orphan
(seen when a CI run was stopped). tests/run.py keeps the private network
namespace it made and ends whatever is left in it once its child has ended.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys

import psutil
import pytest

from app import PROJECT_ROOT
from tests.conftest import wait_until

# Starts a program in a session of its own (as the dashboard fixture does),
# says its pid, then either waits to be killed or exits at once.
LEAVES_A_PROGRAM = """
import pathlib, subprocess, sys, time
child = subprocess.Popen(
    [sys.executable, "-c", "import time; time.sleep(300)  # left behind"], start_new_session=True
)
pathlib.Path(sys.argv[1]).write_text(str(child.pid))
if sys.argv[2] == "wait":
    time.sleep(300)
"""


def _gone(pid: int) -> bool:
    try:
        return psutil.Process(pid).status() == psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return True


@pytest.mark.parametrize("ending", ["killed from outside", "exits leaving it"])
def test_a_run_ends_what_it_started_and_names_it(tmp_path, ending):
    script, pid_file = tmp_path / "leaves_a_program.py", tmp_path / "pid"
    script.write_text(LEAVES_A_PROGRAM)
    how = "wait" if ending == "killed from outside" else "exit"
    # Without the marker, run.py makes its own namespace and keeps it, as `make test` does.
    env = {k: v for k, v in os.environ.items() if k != "CLASSROOM_PRIVATE_NETNS"}
    run = subprocess.Popen(
        [sys.executable, "tests/run.py", "--script", str(script), str(pid_file), how],
        cwd=PROJECT_ROOT,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    try:
        wait_until(pid_file.exists, timeout=30, what="the script to start its program")
        left = int(pid_file.read_text())
        if how == "wait":
            run.send_signal(signal.SIGTERM)
        out, _ = run.communicate(timeout=30)
    finally:
        if run.poll() is None:
            run.kill()
            run.wait()
    assert run.returncode != 0, out
    assert "still running (killed now)" in out and f"pid {left}:" in out, out
    assert "# left behind" in out, out
    wait_until(lambda: _gone(left), timeout=10, what=f"pid {left} to be gone")


# Run by `tests/run.py --workers 2`: each test notes its worker and namespace,
# and the first leaves a program behind (in its own session, as a dashboard is).
IN_WORKERS = """
import os, pathlib, socket, subprocess, sys, time

NOTES = pathlib.Path(os.environ["NOTES_DIR"])


def _note(i):
    time.sleep(0.5)  # so that both workers get tests
    names = ",".join(name for _, name in socket.if_nameindex())
    ns = os.readlink("/proc/self/ns/net")
    (NOTES / f"{i}.txt").write_text(f"{os.environ['PYTEST_XDIST_WORKER']} {ns} {names}")


def test_leaves_a_program():
    child = subprocess.Popen(
        [sys.executable, "-c", "import time; time.sleep(300)  # left in a worker"],
        start_new_session=True,
    )
    (NOTES / "left.pid").write_text(str(child.pid))
    _note(0)


def test_1():
    _note(1)


def test_2():
    _note(2)


def test_3():
    _note(3)
"""


def test_workers_have_namespaces_of_their_own_and_the_keeper_ends_what_they_leave(tmp_path):
    tests, notes = tmp_path / "test_in_workers.py", tmp_path / "notes"
    tests.write_text(IN_WORKERS)
    notes.mkdir()
    env = {k: v for k, v in os.environ.items() if k != "CLASSROOM_PRIVATE_NETNS"}
    run = subprocess.run(
        [sys.executable, "tests/run.py", "--workers", "2", "-c", "pyproject.toml", str(tests)],
        cwd=PROJECT_ROOT,
        env={**env, "NOTES_DIR": str(notes)},
        capture_output=True,
        text=True,
        timeout=120,
    )
    out = run.stdout + run.stderr
    assert "4 passed" in out, out
    seen = [(notes / f"{i}.txt").read_text().split() for i in range(4)]
    by_worker = {worker: (ns, names) for worker, ns, names in seen}
    assert set(by_worker) == {"gw0", "gw1"}, seen  # both workers ran tests
    assert by_worker["gw0"][0] != by_worker["gw1"][0], seen  # in two namespaces
    assert all(ns != os.readlink("/proc/self/ns/net") for ns, _ in by_worker.values()), seen
    assert all(names == "lo" for _, names in by_worker.values()), seen
    left = int((notes / "left.pid").read_text())
    assert run.returncode != 0, out
    assert "still running (killed now)" in out and f"pid {left}:" in out, out
    assert "# left in a worker" in out, out
    wait_until(lambda: _gone(left), timeout=10, what=f"pid {left} to be gone")

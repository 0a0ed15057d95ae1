"""Shared fixtures: private DDS domain per test, a probe node, the dashboard, a browser."""

from __future__ import annotations

import itertools
import os
import socket
import subprocess
import sys
import time
from collections.abc import Callable, Collection, Iterator
from pathlib import Path
from typing import IO

import psutil
import pytest

from app import PROJECT_ROOT
from app.dds import configure_dds_env
from app.ros.liveness import GUARD_NAME
from bench import _reaper
from tests import hang_watchdog, heavy_slots, worker_plan

# pytest keeps each test module with its asserts rewritten in __pycache__, unless Python
# is told not to write bytecode (PYTHONDONTWRITEBYTECODE, set on this project's machines):
# then each of tests/run.py's workers rewrote all ~380 modules at its start, 10 CPU-s
# each. Allowed while collecting, in this process only (the programs tests start keep the
# environment's setting); tests/run.py collects once ahead of the workers to fill it.
_DONT_WRITE_BYTECODE = sys.dont_write_bytecode
sys.dont_write_bytecode = False


def pytest_collection_finish(session: pytest.Session) -> None:
    sys.dont_write_bytecode = _DONT_WRITE_BYTECODE


# One folder per xdist worker (tests/run.py): workers live in namespaces of
# their own, so two of them may serve on the same port number and would write
# the same dashboard-<port>.log.
ARTIFACTS = PROJECT_ROOT / "test-artifacts" / os.environ.get("PYTEST_XDIST_WORKER", "")
# The browser tests' Chromium: Debian's headless shell (`make browser`), the same build as
# its full browser without the windows, whose every new page also loaded the omnibox's
# web page in a renderer of its own (bench/results/findings.md).
BROWSER_EXECUTABLE = "/usr/lib/chromium/chromium-headless-shell"
# A ROS teardown watchdog that ends a worker (or a dashboard it started) says why in the
# worker's timeline: its stderr would die with the worker's captured output. The name is
# app.ros.runtime.WATCHDOG_LOG_VARIABLE (not imported here: that imports rclpy).
os.environ.setdefault("CLASSROOM_WATCHDOG_LOG", str(ARTIFACTS / "timeline.txt"))
_domain_ids = itertools.count(1 + os.getpid() % 50)


def in_private_netns() -> bool:
    return [name for _, name in socket.if_nameindex()] == ["lo"]


def run_cli(
    *args: str, env: dict[str, str] | None = None, timeout: float = 60
) -> subprocess.CompletedProcess[str]:
    """``python -m app ARGS`` as a learner runs ``ros2-classroom ARGS``, output captured."""
    return subprocess.run(
        [sys.executable, "-m", "app", *args],
        cwd=PROJECT_ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=timeout,
    )


def wait_until(
    predicate: Callable[[], object],
    timeout: float = 15.0,
    interval: float = 0.05,
    what: str | Callable[[], str] = "",
) -> object:
    """Poll until ``predicate()`` is truthy; fail the test with ``what`` on timeout.

    ``what`` may be a callable, evaluated at the timeout to describe the state then.
    """
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() > deadline:
            described = what() if callable(what) else what
            pytest.fail(f"timed out after {timeout:.0f} s waiting for {described or predicate}")
        time.sleep(interval)


def _same_netns(pid: int) -> bool:
    try:
        return os.readlink(f"/proc/{pid}/ns/net") == os.readlink("/proc/self/ns/net")
    except OSError:
        return False


def _pid_of(entry: str) -> int:
    """The pid in a ``leftover_node_processes`` entry: ``"nodes.talker (pid 42)"``."""
    return int(entry.rsplit(" ", 1)[1].rstrip(")"))


def leftover_node_processes() -> list[str]:
    """Catalog node processes still alive in this test run's network namespace."""
    import psutil

    found = []
    for proc in psutil.process_iter(["pid", "cmdline", "status"]):
        cmdline = proc.info["cmdline"] or []
        if proc.info["status"] == psutil.STATUS_ZOMBIE or "-m" not in cmdline:
            continue
        module = cmdline[cmdline.index("-m") + 1] if cmdline[-1] != "-m" else ""
        if module.startswith("nodes.") and _same_netns(proc.info["pid"]):
            found.append(f"{module} (pid {proc.info['pid']})")
    return found


@pytest.fixture
def ros_env(monkeypatch: pytest.MonkeyPatch) -> Iterator[dict[str, str]]:
    """A fresh ROS domain on loopback for one test; fails (never skips) outside the netns.

    A test must leave no node process behind: a leftover would show up in the
    graph of a later test that happens to get the same domain id.
    """
    if not in_private_netns():
        pytest.fail(
            "DDS tests must run inside a private network namespace with only loopback: "
            "run them with `make test` (tests/run.py)"
        )
    domain = next(_domain_ids) % 100 + 1
    env = dict(os.environ)
    configure_dds_env(env, domain_id=domain, network=False)
    for key in ("ROS_DOMAIN_ID", "FASTRTPS_DEFAULT_PROFILES_FILE", "RMW_IMPLEMENTATION"):
        monkeypatch.setenv(key, env[key])
    monkeypatch.delenv("ROS_AUTOMATIC_DISCOVERY_RANGE", raising=False)
    yield env
    fail_on_leftover_nodes("the test")


def fail_on_leftover_nodes(who: str, kept: Collection[int] = ()) -> None:
    """Fail (and kill them) if catalog node processes outlive ``who`` by 8 s; the pids in
    ``kept`` are meant to run on."""

    def leftover() -> list[str]:
        return [p for p in leftover_node_processes() if _pid_of(p) not in kept]

    deadline = time.monotonic() + 8.0
    while (left := leftover()) and time.monotonic() < deadline:
        time.sleep(0.2)
    if left:
        for entry in left:  # do not let them spoil later tests either
            os.kill(_pid_of(entry), 9)
        pytest.fail(f"{who} left node processes running: {', '.join(left)}")


@pytest.fixture
def probe(ros_env):
    """A ROS node in the test process, spun in its own thread, to observe over DDS."""
    from app.ros.runtime import RosRuntime

    runtime = RosRuntime("test_probe")
    yield runtime
    runtime.shutdown()


@pytest.fixture
def supervisor(ros_env):
    from app.supervisor import Supervisor

    sup = Supervisor(ros_env)
    yield sup
    sup.shutdown()


def started_by(pid: int) -> list[psutil.Process]:
    """The processes a dashboard started: its descendants, less its ROS liveness guard
    (app/ros/liveness.py), which every dashboard has from its start."""
    out = []
    for child in psutil.Process(pid).children(recursive=True):
        try:
            if GUARD_NAME not in child.cmdline():
                out.append(child)
        except psutil.NoSuchProcess:
            continue
    return out


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


class DashboardProcess:
    """``ros2-classroom serve`` as a real child process."""

    _until = "is ready"  # also for subclasses with their own __init__ (test_kill_restart)

    def __init__(
        self,
        env: dict[str, str],
        port: int,
        extra: list[str] | None = None,
        until: str = "is ready",  # "is starting": once the page answers (app/ui/opening.py)
    ):
        self.port = port
        self._until = until
        self.url = f"http://127.0.0.1:{port}"
        self.log_path = ARTIFACTS / f"dashboard-{port}.log"
        ARTIFACTS.mkdir(parents=True, exist_ok=True)
        self._log = open(self.log_path, "wb")
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "app", "serve", "--port", str(port), *(extra or [])],
            cwd=PROJECT_ROOT,
            env={**env, "PYTHONUNBUFFERED": "1"},
            stdout=self._log,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
        wait_until(self._ready, timeout=40, interval=0.2, what="the dashboard to serve")

    def _ready(self) -> bool:
        if self.proc.poll() is not None:
            pytest.fail(f"dashboard exited early ({self.proc.returncode}):\n{self.log()}")
        return self._until in self.log()

    def log(self) -> str:
        return Path(self.log_path).read_text(errors="replace")

    def stop(self, timeout: float = 10.0) -> int:
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self._log.close()
        return self.proc.returncode


@pytest.fixture
def progress_dir(tmp_path) -> Path:
    return tmp_path / "progress"


@pytest.fixture
def dashboard(ros_env, progress_dir) -> Iterator[DashboardProcess]:
    dash = DashboardProcess(ros_env, free_port(), ["--progress-dir", str(progress_dir)])
    yield dash
    dash.stop()


@pytest.fixture(scope="session")
def browser():
    from playwright.sync_api import sync_playwright

    if not Path(BROWSER_EXECUTABLE).exists():
        pytest.fail(
            "Debian's chromium-headless-shell is missing: `make test` installs it "
            "(apt-get install chromium-headless-shell)"
        )
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(
            executable_path=BROWSER_EXECUTABLE,
            args=[
                "--no-sandbox",
                "--disable-dev-shm-usage",
                "--disable-background-networking",
                "--disable-component-update",
                "--no-first-run",
            ],
        )
        yield browser
        browser.close()


@pytest.fixture
def page(browser, dashboard, request):
    context = browser.new_context(viewport={"width": 1400, "height": 900})
    page = context.new_page()
    from tests.browser.helpers import open_page  # playwright: imported by browser tests only

    open_page(page, dashboard.url)
    yield page
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    page.screenshot(path=str(ARTIFACTS / f"{request.node.name}.png"))
    context.close()


@pytest.hookimpl(optionalhook=True, tryfirst=True)
def pytest_xdist_make_scheduler(config: pytest.Config, log: object) -> object:
    """tests/run.py's workers share the tests as tests/worker_plan.py says."""
    return worker_plan.make_scheduler(config, log)


_HEAVY_SLOTS = heavy_slots.for_this_worker()


@pytest.hookimpl(wrapper=True)
def pytest_runtest_protocol(item: pytest.Item, nextitem: pytest.Item | None) -> Iterator[None]:
    """A test that keeps a core busy waits for one of the run's slots (tests/heavy_slots.py)."""
    waited = _HEAVY_SLOTS.before(item)
    if waited >= 1:
        _timeline(f"waited {waited:.0f} s for a core's slot: {item.nodeid}")
    try:
        with hang_watchdog.armed(hang_watchdog.limit_for(_own_timeout(item)), _hang_log()):
            return (yield)
    finally:
        _HEAVY_SLOTS.after(item, nextitem)


def _own_timeout(item: pytest.Item) -> float | None:
    """The test's pytest-timeout limit: its mark's, else the ini's."""
    marker = item.get_closest_marker("timeout")
    if marker is not None and marker.args:
        return float(marker.args[0])
    return float(item.config.getini("timeout") or 0) or None


_HANG_LOGS: list[IO[str]] = []  # the worker's timeline, open for faulthandler's C thread


def _hang_log() -> IO[str]:
    if not _HANG_LOGS:
        try:
            ARTIFACTS.mkdir(parents=True, exist_ok=True)
            _HANG_LOGS.append(open(ARTIFACTS / "timeline.txt", "a", encoding="utf-8"))
        except OSError:  # a read-only checkout: the stacks go to the worker's stderr
            _HANG_LOGS.append(sys.__stderr__ or sys.stderr)
    return _HANG_LOGS[0]


# Tests that take the cores on purpose (to prove a check holds on a slow
# computer) are marked ``loaded``: tests/run.py runs them after the rest, one at
# a time, so their load never starves another worker's test.
LOADED = "loaded"
BUSY_LOOP = "while True: pass"


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", f"{LOADED}: takes the cores on purpose; runs alone")
    config.addinivalue_line(
        "markers", "alone: needs the machine's real time to itself (tests/run.py runs it alone)"
    )


@pytest.fixture
def busy_cores(request: pytest.FixtureRequest) -> Iterator[list[subprocess.Popen]]:
    """Two processes that spin for the test's duration; ended whatever happens."""
    if request.node.get_closest_marker(LOADED) is None:
        pytest.fail(f"a test that uses busy_cores is marked @pytest.mark.{LOADED} (runs alone)")
    loops = [subprocess.Popen([sys.executable, "-c", BUSY_LOOP]) for _ in range(2)]
    try:
        yield loops
    finally:
        for loop in loops:
            loop.kill()
        for loop in loops:
            loop.wait(timeout=10)


@pytest.hookimpl(tryfirst=True)  # before ``-m`` selects: "not ros" leaves them out
def pytest_itemcollected(item: pytest.Item) -> None:
    # A test that needs DDS, through any fixture, carries the ``ros`` mark even if its
    # module forgot it (tests/unit/test_steady_executor.py did).
    if "ros_env" in getattr(item, "fixturenames", ()):
        item.add_marker(pytest.mark.ros)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    # Every worker collects, and all must list the same order: the plan is a pure function.
    if os.environ.get("PYTEST_XDIST_WORKER"):
        items[:] = worker_plan.spread(items)


# Nothing a test started outlives the session: every process this session
# starts inherits this mark, and the session fails naming any still running at
# its end (after killing them), however they were started (bench/_reaper.py).
_RUN_MARK = _reaper.mark_this_run("test")


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    left = _reaper.end_leftovers(_RUN_MARK)
    if left:
        print("\nFAILED: processes started by the tests were still running (killed now):")
        print("\n".join(f"  {line}" for line in left))
        session.exitstatus = 1


# When each test ran, per worker, and how loaded the machine was as it began: a test that
# starved (a page that answered nothing for 30 s) can then be laid beside what the other
# workers ran at that moment (test-artifacts/<worker>/timeline.txt).
# With the CPU seconds the test's processes took (the worker and everything below it):
# the suite is bound by the cores on two of them, so that is what a slow test costs.
def pytest_runtest_logstart(nodeid: str, location: tuple) -> None:
    _cpu_at_start[nodeid] = _tree_cpu_seconds()
    _timeline(f"start {nodeid} load {os.getloadavg()[0]:.1f}")


def pytest_runtest_logfinish(nodeid: str, location: tuple) -> None:
    before, now = _cpu_at_start.pop(nodeid, None), _tree_cpu_seconds()
    _timeline(f"end   {nodeid}{_cpu_figure(before, now)}")


def _cpu_figure(before: float | None, now: float | None) -> str:
    """The timeline's CPU figure for a test: what the tree took between two reads. A
    process below that worked and was then left to init (its parent ended first) takes
    its seconds out of the tree, so the difference can fall below zero (a session's
    last test, tearing its fixtures down): that is said, never written as a figure."""
    if before is None or now is None:
        return ""
    if now < before:
        return f" cpu unknown ({before - now:.1f} s left the tree with a process left to init)"
    return f" cpu {now - before:.1f}"


_cpu_at_start: dict[str, float | None] = {}
_TICKS = os.sysconf("SC_CLK_TCK")


def _tree_cpu_seconds() -> float | None:
    """CPU seconds taken so far by this process and every live one below it, with the
    children each of them has reaped (their time is then counted in the reaper's); None
    where /proc cannot be read. A process left to init's care is not counted."""
    parent_of: dict[int, int] = {}
    ticks: dict[int, int] = {}
    try:
        entries = [e.name for e in os.scandir("/proc") if e.name.isdigit()]
    except OSError:
        return None
    for name in entries:
        try:
            with open(f"/proc/{name}/stat", "rb") as stat:
                data = stat.read()
            # After the command name (in parentheses, which may hold spaces): state, ppid,
            # ... then utime, stime, cutime and cstime at 11-14.
            fields = data[data.rindex(b")") + 2 :].split()
            parent_of[int(name)] = int(fields[1])
            ticks[int(name)] = sum(int(x) for x in fields[11:15])
        except (OSError, ValueError, IndexError):
            continue  # ended meanwhile
    children: dict[int, list[int]] = {}
    for pid, parent in parent_of.items():
        children.setdefault(parent, []).append(pid)
    total, todo = 0, [os.getpid()]
    while todo:
        pid = todo.pop()
        total += ticks.get(pid, 0)
        todo += children.get(pid, [])
    return total / _TICKS


def pytest_runtest_logreport(report: pytest.TestReport) -> None:
    """A failure (of a test or its fixtures) in the timeline too, as it happens: a run
    still going shows which test failed, not only that one did."""
    if report.failed:
        _timeline(f"FAILED {report.when} {report.nodeid}")


def _timeline(line: str) -> None:
    try:
        ARTIFACTS.mkdir(parents=True, exist_ok=True)
        with open(ARTIFACTS / "timeline.txt", "a", encoding="utf-8") as out:
            out.write(f"{time.strftime('%H:%M:%S')} {line}\n")
    except OSError:  # a read-only checkout: the timeline is a diagnosis aid only
        pass

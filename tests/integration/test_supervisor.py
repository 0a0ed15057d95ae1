"""The supervisor runs real node processes on a private DDS domain."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time

import psutil
import pytest
from std_msgs.msg import String

from app import PROJECT_ROOT
from app.ros.graph import live_and_ghost_nodes
from app.ros.monitor import TopicMonitor
from app.supervisor import NodeState, NodeStatus
from tests.conftest import wait_until

pytestmark = pytest.mark.ros


def test_talker_and_listener_talk_over_dds(supervisor, probe):
    tap = TopicMonitor(probe.node, "/chatter", String, qos=10)
    supervisor.start("talker")
    supervisor.start("listener")
    wait_until(lambda: tap.count >= 3, what="/chatter messages at the probe")
    assert tap.recent()[-1][1].data.startswith("Hello World: ")
    wait_until(
        lambda: any("I heard" in line for line in supervisor.output("listener")),
        what="the listener to log what it heard",
    )
    nodes = wait_until(
        lambda: {"/talker", "/listener"} <= set(_node_names(probe)) and _node_names(probe),
        what="both nodes in the graph",
    )
    assert "/talker" in nodes


def test_stop_is_clean_and_leaves_the_graph(supervisor, probe):
    supervisor.start("talker")
    wait_until(lambda: "/talker" in _node_names(probe), what="/talker in the graph")
    supervisor.note_visible_nodes(_node_names(probe))
    assert supervisor.status("talker").state is NodeState.RUNNING
    pid = supervisor.status("talker").pid
    status = supervisor.stop("talker").result(timeout=10)
    assert status.state is NodeState.STOPPED
    assert status.exit_code == 0, supervisor.output("talker")  # SIGINT handled cleanly
    assert not psutil.pid_exists(pid) or psutil.Process(pid).status() == psutil.STATUS_ZOMBIE
    # Gone as the dashboard sees the graph: no node of that name owns an endpoint. A raw name
    # can outlive its process for good when its last discovery messages cross its exit (a
    # "ghost", app.ros.graph.endpoint_owners; ci28 waited 5 s for one). 25 s: longer than
    # DDS's 20 s lease, should the participant's goodbye itself be lost on a loaded machine.
    wait_until(
        lambda: "/talker" not in live_and_ghost_nodes(probe.node)[0],
        timeout=25,
        what="/talker to leave",
    )


def test_crash_is_reported_with_exit_code_and_restart_works(supervisor):
    supervisor.start("crashing_node")
    status = wait_until(
        lambda: (s := supervisor.status("crashing_node")).state is NodeState.CRASHED and s,
        timeout=30,
        what="crashing_node to crash",
    )
    assert status.exit_code == 1
    assert status.describe() == "crashed (exit code 1)"
    assert any("simulated bug" in line for line in supervisor.output("crashing_node"))
    restarted = supervisor.restart("crashing_node")
    assert restarted.state is NodeState.STARTING and restarted.pid != status.pid


def test_stubborn_process_is_escalated_to_sigkill(ros_env):
    from app.supervisor import Supervisor

    sup = Supervisor(ros_env, sigint_timeout=0.5, sigterm_timeout=0.5)
    try:
        sup.start("talker")
        wait_until(lambda: sup.output("talker"), what="talker output")
        pid = sup.status("talker").pid
        # Make the node ignore Ctrl+C and SIGTERM, as a hung program would.
        os.kill(pid, signal.SIGSTOP)
        status = sup.stop("talker").result(timeout=10)
        assert status.state is NodeState.STOPPED
        assert status.exit_code == -signal.SIGKILL
    finally:
        sup.shutdown()


def test_a_program_leaves_nothing_of_its_group_behind(ros_env, tmp_path):
    """A launcher killed by the stop's SIGTERM takes the node it started with it.

    The child ignores SIGINT and SIGTERM (a node hung in start-up); the parent
    dies of SIGTERM before it can clean up, as a launch file's launcher does.
    """
    from app.supervisor import LearnerProgram, Supervisor

    script = textwrap.dedent(
        """
        import signal, subprocess, sys, time
        child = subprocess.Popen([sys.executable, "-c",
            "import signal, time; signal.signal(signal.SIGINT, signal.SIG_IGN); "
            "signal.signal(signal.SIGTERM, signal.SIG_IGN); print('ready', flush=True); "
            "time.sleep(600)"],
            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)  # its own output, as launch
        child.stdout.readline()  # both signals ignored from here on
        print("child", child.pid, flush=True)
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        time.sleep(600)
        """
    )
    program = LearnerProgram("exercise:group", "/group", (sys.executable, "-c", script), tmp_path)
    sup = Supervisor(ros_env, sigint_timeout=0.5, sigterm_timeout=2.0)
    child = None
    try:
        sup.start_program(program)
        line = wait_until(
            lambda: next((s for s in sup.output(program.name) if s.startswith("child")), None),
            what="the child's pid",
        )
        child = psutil.Process(int(line.split()[1]))
        status = sup.stop(program.name).result(timeout=10)
        assert status.exit_code == -signal.SIGTERM  # the parent died of the escalation
        child.wait(timeout=5)  # ...and its child with it, though it ignored both signals
    finally:
        sup.shutdown()
        if child is not None and child.is_running():
            child.kill()  # a failed run must not leave it to later tests


def test_output_buffer_is_bounded(ros_env):
    from app.supervisor import Supervisor

    sup = Supervisor(ros_env, max_log_lines=5)
    try:
        sup.start("talker")
        wait_until(lambda: sup.status("talker").dropped_lines > 0, what="old lines to drop")
        assert len(sup.output("talker")) == 5
    finally:
        sup.shutdown()


def test_no_child_survives_a_sigkilled_dashboard(ros_env):
    """The supervisor's owner dies by SIGKILL with three nodes running: none survives."""
    script = textwrap.dedent(
        """
        import os, sys, time
        from app.supervisor import Supervisor
        sup = Supervisor(os.environ)
        for name in ("talker", "listener", "listener2"):
            print(sup.start(name).pid, flush=True)
        time.sleep(600)
        """
    )
    owner = subprocess.Popen(
        [sys.executable, "-c", script],
        cwd=PROJECT_ROOT,
        env=ros_env,
        stdout=subprocess.PIPE,
        text=True,
    )
    pids = [int(owner.stdout.readline()) for _ in range(3)]
    assert all(psutil.pid_exists(pid) for pid in pids)
    owner.kill()
    owner.wait()
    wait_until(lambda: not any(_alive(pid) for pid in pids), timeout=10, what="every child to end")


def _alive(pid: int) -> bool:
    try:
        return psutil.Process(pid).status() != psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return False


def _node_names(probe) -> list[str]:
    return [f"{ns.rstrip('/')}/{n}" for n, ns in probe.node.get_node_names_and_namespaces()]


def _node_children(module: str) -> list[psutil.Process]:
    me = psutil.Process()
    return [
        p
        for p in me.children(recursive=True)
        if p.status() != psutil.STATUS_ZOMBIE and f"nodes.{module}" in p.cmdline()
    ]


def test_two_concurrent_starts_make_one_process(supervisor):
    """A double click on Start once spawned two /talker processes and lost the first."""
    import threading

    barrier = threading.Barrier(4)
    pids: list[int | None] = []

    def click() -> None:
        barrier.wait()
        pids.append(supervisor.start("talker").pid)

    threads = [threading.Thread(target=click) for _ in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(10)
    assert len(set(pids)) == 1, f"several processes started: {pids}"
    assert [p.pid for p in _node_children("talker")] == pids[:1]
    supervisor.stop("talker").result(timeout=10)
    assert _node_children("talker") == []


def test_start_right_after_stop_starts_a_new_process(supervisor):
    """Start during a stop used to be a no-op: the node stayed stopped (flaky 50-cycle test)."""
    first = supervisor.start("talker").pid
    supervisor.stop("talker")  # not waited for: the process is still being stopped
    second = supervisor.start("talker")
    assert second.pid != first
    assert second.state is NodeState.STARTING
    assert [p.pid for p in _node_children("talker")] == [second.pid]
    supervisor.stop("talker").result(timeout=10)


def test_listeners_hear_each_start_stop_and_end(supervisor):
    """The moments a node joins or leaves the graph, told as they happen (the dashboard then
    looks at the graph often for a while, instead of fifty times a second all day)."""
    import threading

    heard: list[tuple[str, NodeState]] = []
    ended = threading.Event()

    def broken(status: NodeStatus) -> None:
        if status.state is NodeState.STOPPING:
            # A slow listener: the talker ends on SIGINT well within this, so its reap
            # races this telling (ci100 heard STOPPED before STOPPING without any sleep).
            time.sleep(1.5)
        raise RuntimeError("a listener's bug")

    def listen(status: NodeStatus) -> None:
        heard.append((status.name, status.state))
        if status.state is NodeState.STOPPED:
            ended.set()

    supervisor.on_change(broken)  # logged; the others are still told, the work goes on
    supervisor.on_change(listen)
    started = supervisor.start("talker")
    assert heard == [("talker", NodeState.STARTING)]
    assert supervisor.start("talker").pid == started.pid  # running already: nothing new
    assert len(heard) == 1
    supervisor.stop("talker").result(timeout=10)
    assert ended.wait(5), heard
    assert heard == [
        ("talker", NodeState.STARTING),
        ("talker", NodeState.STOPPING),
        ("talker", NodeState.STOPPED),
    ]

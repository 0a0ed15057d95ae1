"""Make Fast DDS 2.14.5 deadlock (eProsima/Fast-DDS#6502), and watch our guard end it.

The deadlock: a participant's discovery thread, removing a remote writer, holds
the PDP lock and waits for the event thread to finish its batch of timers; the
event thread, in that batch, checks a remote participant's lease and waits for
the PDP lock. It needs the writer's first-ACKNACK timer to be running at that
moment, so short-lived writers are the risk. This tool makes that common:

- IDLE participants with a short lease (0.3 s), so that the victim checks some
  remote participant's lease many times a second;
- CHURN programs that each create a publisher on one of four topics and
  destroy it 50-250 ms later, again and again;
- the victim: 200 readers on those four topics (each removal stops 50 writer
  proxies while their timers run), and ``app.ros.liveness.ParticipantLiveness``
  with a 20 s limit, as the dashboard runs it with 60 s.

When the victim stops probing, the tool takes its native stacks with gdb (if
installed), keeps them in a file and says whether they show the two threads of
the cycle; then the guard ends the victim with SIGABRT and the tool starts
another. Measured on 2 cores: a victim deadlocked after 10-130 s (8 in 12
minutes). With the dashboard's real load a participant has a few readers per
topic and the odds are far lower (one hang in about 16 test-suite runs).

Run it inside a private network namespace (it starts DDS participants):

    .venv/bin/python tests/run.py --script tools/fastdds_deadlock.py [MINUTES]
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
from app.dds import LOOPBACK_PROFILE, configure_dds_env  # noqa: E402

IDLE, CHURN, TOPICS, READERS = 20, 6, 4, 200
LEASE_MS = 300
LIMIT_SEC = 20  # the victim's guard
SILENT_SEC = 6  # the victim's probes stopped this long: take its stacks
CYCLE = ("ResourceEvent::unregister_timer", "PDP::check_remote_participant_liveliness")

_IDLE = """
import time, rclpy
rclpy.init()
node = rclpy.create_node('idle_%d' % __import__('os').getpid())
while True:
    time.sleep(1)
"""
_CHURN = f"""
import os, random, time, rclpy
from std_msgs.msg import String
rclpy.init()
node = rclpy.create_node('churn_%d' % os.getpid())
k = 0
while True:
    k += 1
    pub = node.create_publisher(String, '/churn%d' % (k % {TOPICS}), 10)
    time.sleep(random.uniform(0.05, 0.25))
    node.destroy_publisher(pub)
"""
_VICTIM = f"""
import faulthandler, resource, sys, threading, time, rclpy
from rclpy.executors import SingleThreadedExecutor
from std_msgs.msg import String
from app.ros.liveness import ParticipantLiveness
faulthandler.enable()
resource.setrlimit(resource.RLIMIT_CORE, (0, resource.getrlimit(resource.RLIMIT_CORE)[1]))
rclpy.init()
node = rclpy.create_node('victim')
readers = [node.create_subscription(String, '/churn%d' % (i % {TOPICS}), lambda m: None, 10)
           for i in range({READERS})]
executor = SingleThreadedExecutor()
executor.add_node(node)
threading.Thread(target=executor.spin, daemon=True).start()
liveness = ParticipantLiveness(node, limit={LIMIT_SEC})
liveness.start()
while True:
    time.sleep(0.5)
    print(liveness.probes, flush=True)  # stops with the GIL held by a blocked probe
"""


def _short_lease_profile() -> Path:
    """Our loopback profile with a 0.3 s lease, announced five times per lease."""
    text = LOOPBACK_PROFILE.read_text().replace(
        "<leaseAnnouncement><sec>0</sec><nanosec>250000000</nanosec></leaseAnnouncement>",
        f"<leaseDuration><sec>0</sec><nanosec>{LEASE_MS * 1_000_000}</nanosec></leaseDuration>"
        f"<leaseAnnouncement><sec>0</sec><nanosec>{LEASE_MS // 5 * 1_000_000}</nanosec>"
        "</leaseAnnouncement>",
    )
    fd, name = tempfile.mkstemp(prefix="short-lease-", suffix=".xml")
    os.write(fd, text.encode())
    os.close(fd)
    return Path(name)


def _native_stacks(pid: int) -> str:
    gdb = shutil.which("gdb")
    if gdb is None:
        return ""
    command = [gdb, "-p", str(pid), "-batch", "-ex", "thread apply all bt"]
    return subprocess.run(command, capture_output=True, text=True, timeout=120).stdout


def _one_victim(env: dict[str, str], deadline: float) -> str:
    """Run a victim until it hangs and its guard ends it, or the time is up."""
    started = time.monotonic()
    victim = subprocess.Popen(
        [sys.executable, "-c", _VICTIM], cwd=ROOT, env=env,
        stdout=subprocess.PIPE, stderr=subprocess.PIPE,
    )  # fmt: skip
    assert victim.stdout is not None
    os.set_blocking(victim.stdout.fileno(), False)
    last, stacks = time.monotonic(), ""
    try:
        while time.monotonic() < deadline and victim.poll() is None:
            time.sleep(0.5)
            if victim.stdout.read():
                last = time.monotonic()
            elif not stacks and time.monotonic() - last > SILENT_SEC:
                stacks = _native_stacks(victim.pid) or "(no gdb)"
        if victim.poll() is None:
            return f"no hang in {time.monotonic() - started:.0f} s"
        ended = time.monotonic()
        said = victim.stderr.read().decode(errors="replace") if victim.stderr else ""
        cycle = all(frame in stacks for frame in CYCLE)
        kept = Path(tempfile.gettempdir()) / f"fastdds-deadlock-{victim.pid}.txt"
        kept.write_text(stacks + "\n--- stderr ---\n" + said)
        return (
            f"hung after {last - started:.0f} s; ended by "
            f"{'SIGABRT' if victim.returncode == -signal.SIGABRT else victim.returncode} "
            f"{ended - last:.0f} s after its last probe (limit {LIMIT_SEC} s); "
            f"guard's line {'present' if 'stopped answering' in said else 'MISSING'}; "
            f"stacks {'show the #6502 cycle' if cycle else 'do NOT show the cycle'} ({kept})"
        )
    finally:
        if victim.poll() is None:
            victim.kill()
        victim.wait()


def main() -> int:
    minutes = float(sys.argv[1]) if len(sys.argv) > 1 else 10.0
    env = dict(os.environ)
    configure_dds_env(env, domain_id=77, network=False)
    profile = _short_lease_profile()
    idle_env = {**env, "FASTRTPS_DEFAULT_PROFILES_FILE": str(profile)}
    helpers: list[subprocess.Popen[bytes]] = []
    deadline = time.monotonic() + minutes * 60
    hangs = victims = 0
    try:
        helpers += [subprocess.Popen([sys.executable, "-c", _IDLE], env=idle_env)
                    for _ in range(IDLE)]  # fmt: skip
        helpers += [subprocess.Popen([sys.executable, "-c", _CHURN], env=env)
                    for _ in range(CHURN)]  # fmt: skip
        while time.monotonic() < deadline:
            victims += 1
            result = _one_victim(env, deadline)
            hangs += result.startswith("hung")
            print(f"victim {victims}: {result}", flush=True)
    finally:
        for helper in helpers:
            helper.kill()
        for helper in helpers:
            helper.wait()
        profile.unlink()
    print(f"{hangs} hang(s) in {minutes:g} min, {victims} victim(s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

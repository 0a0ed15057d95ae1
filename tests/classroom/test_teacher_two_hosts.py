"""The teacher's view of a class spread over two hosts (two network namespaces).

Host A runs ``classroom --learners 2`` (with tokens, and the teacher page we
watch); host B runs ``classroom --learners 1``. Both report on one classroom
domain over the veth cable (``--network``, UDP only). Learners move through
steps and pass an exercise in their real dashboards; the teacher page and
``classroom status`` on host A follow within 2 s. The teacher's messages and
settings reach the right dashboards, and each page opens only with its own
token.

The browsers are wire clients (tests/wire_client.py) driven by a small
program inside each host (``DRIVER``), since only processes in a host's
namespace reach its pages.
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

import tests.classroom.test_two_hosts as two_host_setup
from app import PROJECT_ROOT
from app.dds import configure_dds_env
from app.lessons.panel import answer_button_label
from tests.conftest import ARTIFACTS
from tests.faults.helpers import record

pytestmark = pytest.mark.ros

two_hosts = two_host_setup.two_hosts  # the fixture: hosts A and B joined by a veth pair
_in = two_host_setup._in

FOLLOW_SEC = 2.0
PORT_A, PORT_B = 8180, 8280  # each host has a loopback of its own
STUCK_MINUTES = "Stuck: minutes without progress while a check fails"
# Lesson 1, step 2's one question (how does a new node find the others?), answered wrong.
WRONG_ANSWER = answer_button_label("It asks the roscore master over XML-RPC", chosen=False)

# Reads one JSON command a line, answers one JSON line; times are time.monotonic(),
# which every namespace of this kernel shares.
DRIVER = textwrap.dedent(
    """
    import json, sys, time, urllib.error, urllib.request
    from tests.wire_client import NEXT_OR_SKIP, WireClient
    pages = {}

    def until(check, timeout):
        deadline = time.monotonic() + timeout
        while True:
            value = check()
            if value or time.monotonic() > deadline:
                return value
            time.sleep(0.05)

    for line in sys.stdin:
        cmd = json.loads(line)
        op, page = cmd["op"], pages.get(cmd.get("page"))
        out = {"ok": True}
        try:
            if op == "open":
                pages[cmd["page"]] = WireClient(cmd["url"])
            elif op == "wait_text":
                seen = until(lambda: cmd["text"] in page.markdown(), cmd.get("timeout", 15))
                out = {"ok": bool(seen), "t": time.monotonic(), "markdown": page.markdown()}
                if not seen:  # was the page still connected, and still being sent frames?
                    out["closed"] = page.closed_reason
                    out["quiet_s"] = round(time.monotonic() - page.last_frame_at, 1)
            elif op == "wait_regex":
                import re
                pattern = re.compile(cmd["regex"])
                seen = until(lambda: pattern.search(page.markdown()), cmd.get("timeout", 15))
                out = {"ok": bool(seen), "t": time.monotonic(), "markdown": page.markdown()}
            elif op == "wait_label":
                seen = until(lambda: page.find(cmd["label"]), cmd.get("timeout", 15))
                out = {"ok": bool(seen), "t": time.monotonic()}
            elif op == "click":
                # "Next" reads "Skip (N checks not passed)" until the step's checks pass.
                label = NEXT_OR_SKIP if cmd["label"] == "Next" else cmd["label"]
                until(lambda: page.find(label, "GuiButtonMessage"), 15)
                out["t"] = time.monotonic()
                page.click(label)
            elif op == "set":
                uuid = until(lambda: page.find(cmd["label"]), 15)
                if cmd.get("option"):  # a dropdown: wait until the value is offered
                    until(lambda: cmd["value"] in (page.gui[uuid].get("options") or ()), 15)
                page.set_value(uuid, cmd["value"])
            elif op == "markdown":
                out["markdown"] = page.markdown()
            elif op == "http":
                try:
                    with urllib.request.urlopen(cmd["url"], timeout=10) as answer:
                        out.update(status=answer.status, body=answer.read().decode()[:20000])
                except urllib.error.HTTPError as exc:
                    out.update(status=exc.code, body="")
            elif op == "quit":
                break
        except Exception as exc:
            out = {"ok": False, "error": f"{type(exc).__name__}: {exc}"}
        print(json.dumps(out), flush=True)
    for client in pages.values():
        client.close()
    """
)


class Driver:
    """The driver program inside one host."""

    def __init__(self, host_pid: int, env: dict[str, str]) -> None:
        self.proc = subprocess.Popen(
            _in(host_pid, sys.executable, "-c", DRIVER),
            cwd=PROJECT_ROOT, env=env, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
            text=True, start_new_session=True,
        )  # fmt: skip

    def __call__(self, op: str, **fields: object) -> dict:
        assert self.proc.stdin is not None and self.proc.stdout is not None
        self.proc.stdin.write(json.dumps({"op": op, **fields}) + "\n")
        self.proc.stdin.flush()
        line = self.proc.stdout.readline()
        assert line, f"the driver ended during {op}"
        answer = json.loads(line)
        assert answer.get("ok", True) or "error" not in answer, answer
        return answer

    def close(self) -> None:
        if self.proc.poll() is None:
            try:
                self("quit")
            except (AssertionError, OSError, ValueError):
                pass
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait()


def _start_classroom(
    host: int, env: dict[str, str], log: Path, progress: Path, *args: str
) -> tuple[subprocess.Popen, str]:
    with open(log, "w") as out:
        proc = subprocess.Popen(
            _in(host, sys.executable, "-m", "app", "classroom", "--network",
                "--progress-dir", str(progress), *args),
            cwd=PROJECT_ROOT, env={**env, "PYTHONUNBUFFERED": "1"}, stdout=out,
            stderr=subprocess.STDOUT, start_new_session=True,
        )  # fmt: skip
    return proc, str(log)


def _wait_ready(proc: subprocess.Popen, log: str, timeout: float = 120.0) -> str:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        text = Path(log).read_text()
        if "Press Ctrl+C" in text:
            return text
        assert proc.poll() is None, f"classroom ended early:\n{text}"
        time.sleep(0.2)
    raise AssertionError(f"classroom not ready in {timeout} s:\n{Path(log).read_text()}")


def _stop(proc: subprocess.Popen) -> int:
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGINT)
    try:
        return proc.wait(30)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        return -9


def _row(learner: str, site: str, domain: int, rest: str) -> str:
    """A teacher-table row's start, as a regex: learner, where, then the next cells."""
    return rf"\| {learner} \| {site} · domain {domain} \| {rest}"


def test_teacher_follows_three_learners_on_two_hosts(ros_env, two_hosts, tmp_path):
    host_a, host_b = two_hosts
    env = configure_dds_env(dict(ros_env), network=True)
    env["FASTDDS_BUILTIN_TRANSPORTS"] = "UDPv4"  # no shared-memory shortcut between "hosts"
    base_a, base_b = 40, 50  # learners' own domains: A 40-41, B 50
    # This test's own domain, unless it is one of the learners' (then one that is not).
    classroom_domain = int(env["ROS_DOMAIN_ID"])
    if classroom_domain in (40, 41, 50):
        classroom_domain += 20
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    progress_a, progress_b = tmp_path / "A", tmp_path / "B"
    room_a, log_a = _start_classroom(
        host_a, env, ARTIFACTS / "teacher-host-a.log", progress_a, "--learners", "2",
        "--allow-remote", "--site", "A", "--base-port", str(PORT_A),
        "--base-domain-id", str(base_a), "--classroom-domain-id", str(classroom_domain),
    )  # fmt: skip
    room_b, log_b = _start_classroom(
        host_b, env, ARTIFACTS / "teacher-host-b.log", progress_b, "--learners", "1",
        "--site", "B", "--base-port", str(PORT_B),
        "--base-domain-id", str(base_b), "--classroom-domain-id", str(classroom_domain),
    )  # fmt: skip
    drivers: list[Driver] = []
    latencies: dict[str, float] = {}
    try:
        text_a = _wait_ready(room_a, log_a)
        _wait_ready(room_b, log_b)
        learner_urls = re.findall(r"learner\d\s+(http://\S+)", text_a)
        teacher_url = re.search(r"Teacher page: (http://\S+)", text_a).group(1)
        teacher_token = teacher_url.split("token=")[1]
        assert len(learner_urls) == 2 and all("token=" in u for u in learner_urls), text_a
        learner_token = learner_urls[0].split("token=")[1]
        assert teacher_token not in (learner_token, learner_urls[1].split("token=")[1])
        a, b = Driver(host_a, env), Driver(host_b, env)
        drivers += [a, b]

        # -- tokens: each page opens with its own token only --------------------------
        bare_teacher = f"http://127.0.0.1:{PORT_A - 1}/"
        bare_learner = f"http://127.0.0.1:{PORT_A}/"
        assert a("http", url=bare_teacher)["status"] == 401
        assert a("http", url=f"{bare_teacher}?token={learner_token}")["status"] == 401
        assert a("http", url=f"{bare_learner}?token={teacher_token}")["status"] == 401
        assert a("http", url=f"{bare_learner}?token={learner_token}")["status"] == 200
        assert a("http", url=teacher_url)["status"] == 200

        # -- everyone shows up, from both hosts ----------------------------------------
        a("open", page="teacher", url=teacher_url)
        for learner, site, domain in (("learner1", "A", 40), ("learner2", "A", 41)):
            seen = a("wait_regex", page="teacher", regex=_row(learner, site, domain, "1 · 1/"))
            assert seen["ok"], seen["markdown"]
        seen = a(
            "wait_regex", page="teacher", regex=_row("learner1", "B", 50, "1 · 1/"), timeout=40
        )
        assert seen["ok"], seen["markdown"]  # crossed the cable

        a("open", page="a1", url=learner_urls[0])
        a("open", page="a2", url=learner_urls[1])
        b("open", page="b1", url=f"http://127.0.0.1:{PORT_B}")

        # -- steps: a learner on A, then one on B; the teacher page follows -----------
        clicked = a("click", page="a2", label="Next")["t"]
        seen = a("wait_regex", page="teacher", regex=_row("learner2", "A", 41, "1 · 2/5"))
        assert seen["ok"], seen["markdown"]
        latencies["step on host A -> teacher page"] = seen["t"] - clicked
        # ...where learner2 answers the quiz wrong: a failing check (stuck, further down).
        a("set", page="teacher", label=STUCK_MINUTES, value=0.1)  # 6 s, for the test
        a("click", page="a2", label=WRONG_ANSWER)
        seen = a("wait_regex", page="teacher", regex=_row("learner2", "A", 41, "1 · 2/5 \\| ✓✗"))
        assert seen["ok"], seen["markdown"]

        b("click", page="b1", label="Next")
        b("wait_text", page="b1", text="Step 2 of")
        clicked = b("click", page="b1", label="Next")["t"]
        seen = a("wait_regex", page="teacher", regex=_row("learner1", "B", 50, "1 · 3/5"))
        assert seen["ok"], seen["markdown"]
        latencies["step on host B -> teacher page"] = seen["t"] - clicked

        # ...and `classroom status` on host A prints the same row.
        clicked = b("click", page="b1", label="Next")["t"]
        status_row = re.compile(r"learner1\s+B · domain 50\s+1 · 4/5")
        run_sec = 0.0  # the command's own longest run: a new Python process joining DDS
        while True:
            started = time.monotonic()
            printed = subprocess.run(
                _in(host_a, sys.executable, "-m", "app", "classroom", "status",
                    "--progress-dir", str(progress_a)),
                cwd=PROJECT_ROOT, env=env, capture_output=True, text=True, timeout=30,
            )  # fmt: skip
            answered = time.monotonic()  # an upper bound: the table was read before this
            run_sec = max(run_sec, answered - started)
            assert printed.returncode == 0, printed.stderr
            if status_row.search(printed.stdout):
                break
            assert answered - clicked < 10 * FOLLOW_SEC, printed.stdout
        latencies["step on host B -> classroom status printed"] = answered - clicked
        assert re.search(r"learner2\s+A · domain 41\s+1 · 2/5", printed.stdout), printed.stdout
        assert "3 learners." in printed.stdout

        # -- an exercise: learner1 on A saves code, runs and checks it -----------------
        # First a recorded mistake (a timer ten times too fast), then the reference.
        exercise_dir = PROJECT_ROOT / "lessons/04_first_node/exercises/heartbeat_logger"
        code_dir = progress_a / "learner1" / "learner1.code"
        code_dir.mkdir(parents=True, exist_ok=True)
        code = code_dir / "heartbeat_logger.py"
        code.write_text((exercise_dir / "mistakes/too_fast.py").read_text())  # as the editor saves
        a("set", page="teacher", label="Learner", value="A/learner1", option=True)
        seen = a("wait_text", page="teacher", text='self.get_logger().info(f"beat {self.count}")')
        assert seen["ok"], seen["markdown"]  # the teacher reads the learner's code
        assert "Exercise `heartbeat_logger`" in seen["markdown"]
        a("click", page="a1", label="Run my node")
        seen = a("wait_regex", page="teacher", regex=_row("learner1", "A", 40, r".*heartbeat"))
        assert seen["ok"], seen["markdown"]  # their node shows as running
        a("wait_text", page="a1", text="Started your node")
        a("click", page="a1", label="Check my node")
        done = a("wait_text", page="a1", text="checks passed: not yet", timeout=60)
        assert done["ok"], done["markdown"][-3000:]
        # Kept where the teacher's docs say: <progress-dir>/bags/<learner>/attempts/<exercise>/.
        kept = sorted((progress_a / "bags/learner1/attempts/heartbeat_logger").iterdir())
        assert [p.name.endswith("-fail") for p in kept] == [True], kept
        # The teacher sees the failure by the mistake it matched: in the learner's row, in
        # the exercises across the class, and in the learner's detail.
        seen = a(
            "wait_regex",
            page="teacher",
            regex=_row("learner1", "A", 40, r".*heartbeat\\_logger ✗ too fast \|"),
        )
        assert seen["ok"], seen["markdown"]
        across = "heartbeat\\_logger: 0 passed, 1 trying — too fast: learner1 \\(A\\)"
        seen = a("wait_text", page="teacher", text=across)
        assert seen["ok"], seen["markdown"]
        assert "### Exercises across the class" in seen["markdown"]
        assert "1 failed; last failure: too fast" in seen["markdown"]
        # The Learner's attempts tab lists it with its failed line, and plays it in the page
        # (a topic-only exercise: the messages' timeline).
        seen = a("wait_text", page="teacher", text="learner1's attempts at `heartbeat_logger`")
        assert seen["ok"], seen["markdown"]
        assert re.search(r"UTC · fail · seed \d+\*\*", seen["markdown"]), seen["markdown"]
        assert "- ✗ **" in seen["markdown"]
        a("click", page="teacher", label="Watch this attempt")
        seen = a(
            "wait_regex",
            page="teacher",
            regex=r"learner1's attempt at heartbeat_logger[\s\S]*\d+ messages in \d+\.\d s",
        )
        assert seen["ok"], seen["markdown"][-3000:]

        code.write_text((exercise_dir / "reference.py").read_text())
        a("click", page="a1", label="Run my node")
        a("wait_text", page="a1", text="Started your node")
        a("click", page="a1", label="Check my node")
        done = a("wait_text", page="a1", text="All checks pass", timeout=60)
        assert done["ok"], done["markdown"][-3000:]
        seen = a(
            "wait_regex",
            page="teacher",
            regex=_row("learner1", "A", 40, r".*1 passed · 2 attempts \| heartbeat\\_logger ✓"),
        )
        assert seen["ok"], seen["markdown"]
        latencies["exercise passed -> teacher page"] = seen["t"] - done["t"]
        seen = a("wait_text", page="teacher", text="heartbeat\\_logger: 1 passed, 0 trying")
        assert seen["ok"], seen["markdown"]

        # -- messages: to one learner on B, then to everyone ----------------------------
        a("set", page="teacher", label="To", value="B/learner1", option=True)
        a("set", page="teacher", label="Message", value="Look again at the QoS step")
        a("click", page="teacher", label="Send")
        seen = b("wait_text", page="b1", text="Look again at the QoS step")
        assert seen["ok"], seen["markdown"]
        assert "Look again" not in a("markdown", page="a2")["markdown"]  # not addressed to A/2
        a("set", page="teacher", label="To", value="everyone")
        a("set", page="teacher", label="Message", value="Five minutes left")
        a("click", page="teacher", label="Send")
        seen = a("wait_text", page="a2", text="Five minutes left")
        # Once (ci86) a2 never showed it: say what the teacher page answered Send with, and if
        # a2's page was still connected.
        sent = re.findall(r"(?:Sent to|⚠)[^\n]*", a("markdown", page="teacher")["markdown"])
        assert seen["ok"], (sent, seen.get("closed"), seen.get("quiet_s"), seen["markdown"][-1500:])
        assert b("wait_text", page="b1", text="Five minutes left")["ok"]

        # -- the teacher decides when solutions show ------------------------------------
        label = "Reference solution: after passing or 1 failed checks"
        assert not b("wait_label", page="b1", label=label, timeout=0.5)["ok"]
        a("set", page="teacher", label="Solution after N failed checks (0: each exercise's own)",
          value=1)  # fmt: skip
        a("click", page="teacher", label="Apply to every learner")
        assert b("wait_label", page="b1", label=label)["ok"]

        # -- no progress while a check fails: the teacher sees who is stuck ---------------
        seen = a("wait_regex", page="teacher", regex=_row("learner2", "A", 41, ".*⚠ no progress"))
        assert seen["ok"], seen["markdown"]
        assert not re.search(_row("learner1", "B", 50, ".*⚠"), seen["markdown"])

        # -- CSV export ---------------------------------------------------------------
        csv = a("http", url=f"{bare_teacher}classroom/teacher/progress.csv?token={teacher_token}")
        assert csv["status"] == 200
        rows = csv["body"].strip().splitlines()
        assert rows[0].startswith("site,learner,domain_id,lesson_id")
        assert len(rows) == 4, rows
        assert any(r.startswith("A,learner1,40,") and ",heartbeat_logger," in r for r in rows)
        no_token = a("http", url=f"{bare_teacher}classroom/teacher/progress.csv")
        assert no_token["status"] == 401
    finally:
        for driver in drivers:
            driver.close()
        codes = [_stop(room_a), _stop(room_b)]
    assert codes == [0, 0], (Path(log_a).read_text()[-2000:], Path(log_b).read_text()[-2000:])
    record("teacher view over two hosts", **{k: round(v, 3) for k, v in latencies.items()})
    # The command line's figure includes its own start-up (2.8 s seen on a loaded CI
    # machine): it is judged on the time left after its longest run.
    bounds = {k: FOLLOW_SEC for k in latencies}
    bounds["step on host B -> classroom status printed"] = FOLLOW_SEC + run_sec
    slow = {k: v for k, v in latencies.items() if v > bounds[k]}
    assert not slow, (latencies, bounds)

"""The classroom command as an LTI 1.3 tool: a launch seats the LMS learner, their pass goes back.

``ros2-classroom classroom`` runs as a teacher starts it, with
``CLASSROOM_LTI_URL`` set; the LMS is the test platform of tests/lti, in
this process, over loopback. The pass arrives as a dashboard sends it: a
progress record of seat learner1 on the classroom domain (published here,
every half second, since learner1's real dashboard keeps publishing its own,
unpassed state under the same key).
"""

from __future__ import annotations

import json
import re
import signal
import subprocess
import sys
import time
from dataclasses import replace

import pytest

from app import PROJECT_ROOT
from app.lti.routes import ToolUrls
from tests.conftest import free_port
from tests.lti.platform import TestPlatform
from tests.lti.service import request, wait_for
from tests.lti.test_service import EXERCISE, exercise_record, graded_link, launch, write_platforms

pytestmark = pytest.mark.ros

SITE = "room-a"


class Tool:
    def __init__(self, base: str) -> None:
        self.urls = ToolUrls.from_base(base)


def test_an_lms_learner_gets_a_seat_and_their_pass_reaches_the_lms(ros_env, tmp_path):
    from app.ros.side_participant import SideParticipant
    from app.teacher import wire

    platform = TestPlatform()
    write_platforms(tmp_path / "lti", platform)
    base_port = free_port()
    base_domain = int(ros_env["ROS_DOMAIN_ID"]) % 80 + 1
    classroom_domain = base_domain + 10
    lti_port = free_port()
    base = f"http://127.0.0.1:{lti_port}"
    env = {
        **ros_env,
        "CLASSROOM_LTI_URL": base,
        "CLASSROOM_LTI_PORT": str(lti_port),
        "CLASSROOM_LTI_DIR": str(tmp_path / "lti"),
    }
    room = subprocess.Popen(
        [sys.executable, "-m", "app", "classroom", "--learners", "2",
         "--base-port", str(base_port), "--base-domain-id", str(base_domain),
         "--classroom-domain-id", str(classroom_domain), "--site", SITE,
         "--teacher-port", str(free_port()), "--progress-dir", str(tmp_path / "progress")],
        cwd=PROJECT_ROOT, env=env, stdout=subprocess.PIPE, text=True,
    )  # fmt: skip
    side = None
    try:
        lines: list[str] = []
        while not lines or "Press Ctrl+C" not in lines[-1]:
            line = room.stdout.readline()
            assert line, f"classroom ended early: {lines}"
            lines.append(line)
        text = "".join(lines)
        assert f"LMS (LTI 1.3): {base}" in text, text
        [gradebook] = re.findall(r"Gradebook: (\S+)", text)
        platform.tool_jwks = json.loads(request("GET", f"{base}/lti/jwks").body)

        link = graded_link(platform.lineitem_url("11"), {"exercise": EXERCISE})
        seated = launch(Tool(base), platform, **link)
        landing = f"http://127.0.0.1:{base_port}/?exercise={EXERCISE}"  # at the launched one
        assert (seated.status, seated.location) == (303, landing)

        side = SideParticipant("lti_test_dashboard", classroom_domain)
        publisher = side.node.create_publisher(
            wire.LearnerProgress, wire.PROGRESS_TOPIC, wire.PROGRESS_PUB_QOS
        )
        passed = replace(exercise_record("learner1", passed=True), site=SITE)
        deadline = time.monotonic() + 30
        while not platform.scores["11"] and time.monotonic() < deadline:
            publisher.publish(wire.to_message(replace(passed, last_activity=time.time())))
            time.sleep(0.5)
        [score] = platform.scores["11"]
        assert score["userId"] == "learner-42"

        # The LMS holds the score a moment before the classroom hears back, and the
        # gradebook says "✓ sent" only then (tests/lti/service.py: wait_delivered).
        wait_for(lambda: "✓ sent" in request("GET", gradebook).body, why="the gradebook's ✓ sent")
        page = request("GET", gradebook)
        assert page.status == 200
        assert "Ada Lovelace" in page.body and "learner1" in page.body and "✓ sent" in page.body
        assert request("GET", gradebook.split("?")[0]).status == 403
    finally:
        if side is not None:
            side.shutdown()
        room.send_signal(signal.SIGINT)
        code = room.wait(timeout=30)
        platform.close()
    assert code == 0
    assert len(platform.score_requests) == 1

"""A dashboard served from a rootless container starts, and says what containment does there.

Rootless Podman/Docker and Kubernetes user namespaces run the dashboard as
root in a user namespace that maps only a few ids. ``unshare -rn`` makes one
(it maps uid and gid 0 only, and gives a network namespace with only ``lo``):
there the sandbox's group cannot be given to the learner's workspace
(``fchown`` fails with EINVAL), which used to end ``serve`` with a traceback.
It must serve the page, refuse learner code with the reason, and stop on
SIGTERM.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import textwrap

import pytest

from app import PROJECT_ROOT
from tests.conftest import in_private_netns

TOKEN = "rootless-test-token-0123456789abcdef"
PORT = 8765

# Runs inside the new namespaces: loopback up, serve, fetch the page, SIGTERM, report.
IN_NAMESPACE = textwrap.dedent(
    """
    import os, signal, subprocess, sys, time, urllib.request
    sys.path.insert(0, os.getcwd())
    from tests.run import bring_loopback_up

    print("uid_map:", open("/proc/self/uid_map").read().split(), flush=True)
    bring_loopback_up()
    port, token, log_path, home = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4]
    log = open(log_path, "wb")
    serve = subprocess.Popen(
        [sys.executable, "-m", "app", "serve", "--host", "0.0.0.0", "--port", port,
         "--allow-remote", "--token", token, "--allow-learner-code",
         "--progress-dir", os.path.join(home, "progress"), "--domain-id", "7"],
        stdout=log, stderr=subprocess.STDOUT, env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    deadline = time.monotonic() + 90
    while b"is ready" not in open(log_path, "rb").read():
        if serve.poll() is not None or time.monotonic() > deadline:
            print("serve never got ready, exit code", serve.poll(), flush=True)
            serve.kill()
            sys.exit(1)
        time.sleep(0.2)
    with urllib.request.urlopen(f"http://127.0.0.1:{port}/?token={token}", timeout=20) as page:
        print("page:", page.status, len(page.read()), flush=True)
    serve.send_signal(signal.SIGTERM)
    print("exit code:", serve.wait(30), flush=True)
    """
)


@pytest.mark.timeout(180)
def test_serve_in_a_rootless_user_namespace_starts_and_refuses_learner_code(tmp_path):
    if not in_private_netns():
        pytest.fail("run through tests/run.py: this test serves on 0.0.0.0")
    unshare = shutil.which("unshare")
    assert unshare, "util-linux unshare is needed"
    log = tmp_path / "serve.log"
    home = tmp_path / "home"
    home.mkdir()
    tmp_path.chmod(0o777)  # root of the user namespace is the same user, but be sure
    run = subprocess.run(
        [unshare, "--user", "--map-root-user", "--net", "--",
         sys.executable, "-c", IN_NAMESPACE, str(PORT), TOKEN, str(log), str(home)],
        cwd=PROJECT_ROOT,
        capture_output=True,
        text=True,
        timeout=150,
    )  # fmt: skip
    served = log.read_text(errors="replace") if log.exists() else ""
    report = f"{run.stdout}\n{run.stderr}\n--- serve's log ---\n{served}"
    assert "uid_map: ['0', '0', '1']" in run.stdout, report  # only one id mapped: the case
    assert "Traceback" not in served and "Traceback" not in run.stderr, report
    assert "page: 200" in run.stdout, report
    assert "exit code: 0" in run.stdout, report
    # It says what containment does here: learner code refused, with the reason.
    assert "Learner code: REFUSED despite --allow-learner-code" in served, report
    assert "does not map the uids and gids" in served, report
    assert run.returncode == 0, report

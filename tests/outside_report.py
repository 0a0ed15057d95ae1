"""A node of ours judged from outside: a plain-rclpy client process and its JSON report.

The client imports only rclpy and message packages (no module of ours), runs
with a clean PYTHONPATH from a folder outside the project, drives the nodes
the supervisor started, and prints one JSON line: what it measured, one entry
per scenario. Each test then judges one part of that report.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from app.dds import configure_dds_env
from tests.conftest import ARTIFACTS, _domain_ids, fail_on_leftover_nodes, in_private_netns


def private_dds_env() -> dict[str, str]:
    """This process's environment on a fresh loopback domain; fails outside the netns."""
    if not in_private_netns():
        pytest.fail("DDS tests must run inside a private network namespace (tests/run.py)")
    env = dict(os.environ)
    configure_dds_env(env, domain_id=next(_domain_ids) % 100 + 1, network=False)
    return env


# The simulated world's scenarios wait on simulated time, which a loaded machine slows:
# measured 45 s alone, 101 s and over 150 s in fresh-clone CI runs beside browser tests.
CLIENT_TIMEOUT_SEC = 360


def run_outside_client(
    env: dict[str, str], folder: Path, client: Path, members: list[str], watched: str, label: str
) -> dict:
    """Start ``members`` under a supervisor, run ``client`` against them, return its report.

    The report also carries ``watched``'s log and whether it was still alive at the end.
    """
    from app.supervisor import Supervisor

    supervisor = Supervisor(env)
    try:
        for member in members:
            supervisor.start(member)
        clean = {k: v for k, v in env.items() if k not in ("PYTHONPATH", "PYTHONSTARTUP")}
        done = subprocess.run(
            [sys.executable, "-I", str(client)],  # -I: no user site, no cwd on sys.path
            cwd=folder,
            env={**clean, "PYTHONUNBUFFERED": "1"},
            capture_output=True,
            text=True,
            timeout=CLIENT_TIMEOUT_SEC,
            check=False,
        )
        log = supervisor.output(watched)
        status = supervisor.status(watched)
    finally:
        supervisor.shutdown()
    fail_on_leftover_nodes(f"the {label} tests")
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    (ARTIFACTS / f"{label}-client.out").write_text(f"{done.stdout}\n{done.stderr}")
    assert done.returncode == 0, done.stderr[-3000:]
    result = json.loads(done.stdout.strip().splitlines()[-1])
    result["node_log"] = log
    result["node_alive_at_end"] = status.active
    (ARTIFACTS / f"{label}-client.json").write_text(json.dumps(result, indent=1))
    return result


def part(report: dict, name: str) -> dict:
    """One scenario's figures; a scenario that did not run or failed fails the test."""
    data = report.get(name)
    assert data is not None, f"scenario {name} did not run"
    assert "error" not in data, f"{name}: {data['error']}\nnode log:\n" + "\n".join(
        report["node_log"][-30:]
    )
    return data

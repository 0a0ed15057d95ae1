"""deploy/: what an operator applies, checked as far as a test can without Kubernetes.

The one-server config also runs for real in test_jupyterhub.py and
test_lean_hub.py (the test hubs load it); here: it loads in JupyterHub's
config loader with what it promises in both single-user modes, the Helm
values are valid YAML with per-learner limits from our measurements, the LTI
example loads and makes instructors teachers, the image installs with the
Makefile's own steps, and the hub image's teacher service imports without ROS.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import textwrap
from importlib import metadata
from pathlib import Path

import pytest
import yaml
from jupyterhub.spawner import LocalProcessSpawner
from packaging.requirements import Requirement
from traitlets.config.loader import PyFileConfigLoader
from traitlets.utils.importstring import import_item

from app import PROJECT_ROOT
from app.hub.spawner import is_lean

DEPLOY = PROJECT_ROOT / "deploy"


def _load(path: Path):
    return PyFileConfigLoader(path.name, path=str(path.parent)).load_config()


@pytest.mark.parametrize("same_account", ["0", "1"])
def test_the_one_server_config_loads_and_registers_the_teacher_service(monkeypatch, same_account):
    monkeypatch.setenv("CLASSROOM_SAME_ACCOUNT", same_account)
    monkeypatch.setenv("CLASSROOM_TEACHERS", "ada, grace")
    monkeypatch.delenv("CLASSROOM_SINGLEUSER", raising=False)
    c = _load(DEPLOY / "jupyterhub_config.py")
    spawner = import_item(c.JupyterHub.spawner_class)
    assert issubclass(spawner, LocalProcessSpawner)
    assert spawner.__name__ == ("ClassroomLocalSpawner" if same_account == "1" else
                                "ClassroomSystemUserSpawner")  # fmt: skip
    (service,) = c.JupyterHub.services
    assert service["name"] == "classroom-teacher"
    assert service["command"][1:] == ["-m", "app.hub.teacher_service"]
    assert c.Spawner.environment["CLASSROOM_TEACHER_URL"] == (
        f"{service['url']}/services/classroom-teacher/"
    )
    assert c.JupyterHub.load_groups == {"teachers": {"users": ["ada", "grace"]}}
    (role,) = c.JupyterHub.load_roles
    assert role["groups"] == ["teachers"]
    assert role["scopes"] == ["access:services!service=classroom-teacher"]
    assert Path(c.ConfigurableHTTPProxy.command[0]).is_file(), "make setup installs the proxy"
    # The lean mode unless the operator asks for JupyterLab: the dashboard is the server.
    assert c.Spawner.cmd[1:] == ["-m", "app", "serve", "--jupyterhub"]
    assert is_lean(c.Spawner.cmd) and "default_url" not in c.Spawner


def test_the_lab_mode_serves_jupyterlab_whose_launcher_has_the_classroom(monkeypatch):
    monkeypatch.setenv("CLASSROOM_SINGLEUSER", "lab")
    c = _load(DEPLOY / "jupyterhub_config.py")
    assert c.Spawner.cmd[1:] == ["-m", "jupyterhub.singleuser"] and not is_lean(c.Spawner.cmd)
    assert c.Spawner.default_url == "/lab"
    # What the lab needs is what `make setup` installs (the test extra pulls in hub).
    pyproject = (PROJECT_ROOT / "pyproject.toml").read_text()
    test_extra = re.search(r"^test = \[(.*?)^\]", pyproject, re.M | re.S)
    hub_extra = re.search(r"^hub = \[(.*?)^\]", pyproject, re.M | re.S)
    assert test_extra and hub_extra and '"ros2-classroom[hub]"' in test_extra[1]
    pins = dict(re.findall(r'"([a-z-]+)==([0-9.]+)"', hub_extra[1]))
    assert {"jupyterhub", "jupyterlab", "jupyter-server", "jupyter-server-proxy"} <= set(pins)
    for name, version in pins.items():  # and the venv has exactly those
        assert metadata.version(name) == version, name
    # jupyter-server-proxy's JupyterLab extension draws the launcher tile.
    labextensions = Path(sys.prefix) / "share" / "jupyter" / "labextensions"
    assert (labextensions / "@jupyterhub" / "jupyter-server-proxy" / "package.json").is_file()
    monkeypatch.setenv("CLASSROOM_SINGLEUSER", "notebook")
    with pytest.raises(ValueError, match="dashboard or lab"):
        _load(DEPLOY / "jupyterhub_config.py")


def _measured_mb(name: str) -> float:
    """A per-process figure bench/hub_spawn.py measured, as bench/results/hub_spawn.md states it."""
    text = (PROJECT_ROOT / "bench" / "results" / "hub_spawn.md").read_text()
    match = re.search(rf"{name} RSS (\d+) MB", text)
    assert match, f"bench/results/hub_spawn.md states no '{name} RSS N MB'"
    return float(match[1])


def test_the_helm_values_are_yaml_with_limits_per_learner_from_our_measurements():
    values = yaml.safe_load((DEPLOY / "z2jh-values.yaml").read_text())
    single = values["singleuser"]
    units = {"M": 1e6, "G": 1e9}

    def mb(text: str) -> float:
        match = re.fullmatch(r"([0-9.]+)([MG])", text)
        assert match, f"not a Kubernetes size: {text}"
        return float(match[1]) * units[match[2]] / 2**20

    assert 0 < single["cpu"]["guarantee"] <= single["cpu"]["limit"]
    guarantee, limit = mb(single["memory"]["guarantee"]), mb(single["memory"]["limit"])
    assert 0 < guarantee <= limit
    # In a pod nothing is shared with other learners: RSS is what counts. The guarantee
    # holds the lean dashboard with two tutorial nodes running, the limit a dozen nodes.
    dashboard, node = _measured_mb("lean dashboard"), _measured_mb("tutorial node")
    assert guarantee >= dashboard + 2 * node, (guarantee, dashboard, node)
    assert limit >= dashboard + 12 * node, (limit, dashboard, node)
    assert guarantee <= 2 * (dashboard + 2 * node), "a guarantee far above use wastes the node"
    assert is_lean(single["cmd"]) and "defaultUrl" not in single
    assert single["extraEnv"]["CLASSROOM_TEACHER_URL"].endswith("/services/classroom-teacher/")
    service = values["hub"]["services"]["classroom-teacher"]
    assert service["command"][-1] == "app.hub.teacher_service"
    port = int(service["url"].rsplit(":", 1)[1])
    assert port in [p["port"] for p in values["hub"]["service"]["extraPorts"]]
    role = values["hub"]["loadRoles"]["classroom-teachers"]
    assert role["scopes"] == ["access:services!service=classroom-teacher"]


def test_the_lti_example_loads_and_makes_instructors_teachers():
    c = _load(DEPLOY / "lti_config.py")
    assert c.JupyterHub.authenticator_class.startswith("ltiauthenticator.lti13")
    hook = c.Authenticator.post_auth_hook
    claim = "https://purl.imsglobal.org/spec/lti/claim/roles"
    teacher = {"name": "t@x.edu", "auth_state": {claim: [
        "http://purl.imsglobal.org/vocab/lis/v2/membership#Instructor"]}}  # fmt: skip
    learner = {"name": "l@x.edu", "auth_state": {claim: [
        "http://purl.imsglobal.org/vocab/lis/v2/membership#Learner"]}}  # fmt: skip
    assert hook(None, None, teacher)["groups"] == ["teachers"]
    assert hook(None, None, learner)["groups"] == []


def _run_lines(dockerfile: str, stage: str) -> list[str]:
    """The RUN commands of one stage, continuation lines joined."""
    text = dockerfile.replace("\\\n", " ")
    stages = re.split(r"^FROM ", text, flags=re.M)
    (body,) = [s for s in stages if re.match(rf"\S+ AS {stage}\b", s)]
    return [line[4:].strip() for line in body.splitlines() if line.startswith("RUN ")]


def test_the_image_installs_the_project_with_the_makefiles_own_steps():
    dockerfile = (DEPLOY / "Dockerfile").read_text()
    runs = _run_lines(dockerfile, "singleuser")
    installs = [r for r in runs if re.search(r"\b(pip|npm|make)\b", r)]
    # The project, its wheels, interfaces, editor and proxy: `make setup` and nothing else.
    assert [r for r in installs if "make setup" in r], runs
    for run in installs:
        assert not re.search(r"\bpip3? install\b|\bnpm (ci|install)\b", run), run
    # No browser in the image: neither Chromium nor the targets that bring it.
    for run in runs:
        assert "chromium" not in run and not re.search(r"make .*\b(browser|test)\b", run), run
    assert "COPY --chown=jovyan:jovyan . ." in dockerfile
    assert "USER jovyan" in dockerfile
    # What `make setup` does in a fresh checkout (-B: as if nothing were installed).
    plan = subprocess.run(
        ["make", "-n", "-B", "setup"], cwd=PROJECT_ROOT, capture_output=True, text=True, check=True
    ).stdout
    # Our modules compiled by setup, so no pod (nor any process here) compiles them as it starts.
    compiled = re.search(r"-m compileall -q -j 0 ([\w/ ]+?) >/dev/null", plan)
    assert compiled, "make setup does not compile the project's modules"
    for folder in compiled.group(1).split():
        assert (PROJECT_ROOT / folder).is_dir() and any((PROJECT_ROOT / folder).rglob("*.py"))
    assert {"app", "nodes"} <= set(compiled.group(1).split())
    for step in (
        "npm ci --prefix app/hub/proxy",
        "npm ci --prefix app/exercises/editor",
        "pip install --quiet -e '.[test,interfaces-build]'",
        "pip install --quiet -e ./ros_python",
    ):
        assert step in plan, step
    # The tools `make setup` calls before it installs anything are in the image.
    apt = next(r for r in runs if "apt-get install" in r)
    for tool in ("make", "npm", "g++"):
        assert re.search(rf"\s{re.escape(tool)}\s", apt + " "), tool
    # The single-user servers the hub starts exist in the venv `make setup` builds: the
    # image's default (lean) and the lab mode's.
    cmd = re.search(r"^CMD (\[.*\])$", dockerfile, re.M)
    assert cmd and json.loads(cmd[1]) == ["ros2-classroom", "serve", "--jupyterhub"]
    for program in ("ros2-classroom", "jupyterhub-singleuser"):
        assert (PROJECT_ROOT / ".venv" / "bin" / program).is_file(), program


def _hub_image_modules() -> set[str]:
    """Top-level modules of jupyterhub and everything it requires: the hub image's Python."""
    wanted, seen = ["jupyterhub"], set()
    while wanted:
        name = wanted.pop().lower().replace("_", "-")
        if name in seen:
            continue
        seen.add(name)
        for line in metadata.requires(name) or []:
            requirement = Requirement(line)  # only what applies here, without extras
            if requirement.marker is None or requirement.marker.evaluate({"extra": ""}):
                wanted.append(requirement.name)
    modules = set()
    for module, dists in metadata.packages_distributions().items():
        if any(d.lower().replace("_", "-") in seen for d in dists):
            modules.add(module)
    return modules


def test_the_teacher_service_imports_in_the_hub_image_without_ros():
    """The hub image is JupyterHub's own plus our app/ folder: no rclpy, viser or numpy."""
    allowed = _hub_image_modules()
    assert "tornado" in allowed and "rclpy" not in allowed and "viser" not in allowed
    script = textwrap.dedent(
        f"""
        import importlib.abc, sys
        ALLOWED = {sorted(allowed)!r}
        class HubImageOnly(importlib.abc.MetaPathFinder):
            def find_spec(self, name, path=None, target=None):
                top = name.split(".")[0]
                private = top.startswith("_")  # the interpreter's own (_sysconfigdata_...)
                if top in sys.stdlib_module_names or top in ALLOWED or top == "app" or private:
                    return None
                raise ImportError(f"{{name}} is not in the hub image")
        sys.meta_path.insert(0, HubImageOnly())
        import app.hub.teacher_service
        assert "rclpy" not in sys.modules and "viser" not in sys.modules
        print("imported")
        """
    )
    done = subprocess.run(
        [sys.executable, "-c", script],
        cwd=PROJECT_ROOT,
        env={**os.environ, "PYTHONPATH": str(PROJECT_ROOT)},
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0 and "imported" in done.stdout, done.stderr[-2000:]

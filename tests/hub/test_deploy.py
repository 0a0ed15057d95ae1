"""deploy/: what an operator applies, checked as far as a test can without Kubernetes.

The one-server config also runs for real in test_jupyterhub.py (the test hub
loads it); here: it loads in JupyterHub's config loader with what it promises,
the Helm values are valid YAML with per-learner limits, the LTI example loads
and makes instructors teachers, and the image installs with the Makefile's
own steps.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest
import yaml
from jupyterhub.spawner import LocalProcessSpawner
from traitlets.config.loader import PyFileConfigLoader
from traitlets.utils.importstring import import_item

from app import PROJECT_ROOT

DEPLOY = PROJECT_ROOT / "deploy"


def _load(path: Path):
    return PyFileConfigLoader(path.name, path=str(path.parent)).load_config()


@pytest.mark.parametrize("same_account", ["0", "1"])
def test_the_one_server_config_loads_and_registers_the_teacher_service(monkeypatch, same_account):
    monkeypatch.setenv("CLASSROOM_SAME_ACCOUNT", same_account)
    monkeypatch.setenv("CLASSROOM_TEACHERS", "ada, grace")
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
    assert c.Spawner.default_url == "/ros2-classroom/"


def test_the_helm_values_are_yaml_with_limits_per_learner():
    values = yaml.safe_load((DEPLOY / "z2jh-values.yaml").read_text())
    single = values["singleuser"]
    units = {"M": 1e6, "G": 1e9}

    def size(text: str) -> float:
        match = re.fullmatch(r"([0-9.]+)([MG])", text)
        assert match, f"not a Kubernetes size: {text}"
        return float(match[1]) * units[match[2]]

    assert 0 < single["cpu"]["guarantee"] <= single["cpu"]["limit"]
    assert 0 < size(single["memory"]["guarantee"]) <= size(single["memory"]["limit"])
    assert single["defaultUrl"] == "/ros2-classroom/"
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
    # The single-user server the hub starts exists in the venv `make setup` builds.
    assert 'CMD ["jupyterhub-singleuser"]' in dockerfile
    assert (PROJECT_ROOT / ".venv" / "bin" / "jupyterhub-singleuser").is_file()

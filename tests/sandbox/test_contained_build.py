"""`colcon build` on a dashboard served to other machines follows the rule for learner code.

A build runs the learner's setup.py, so on a served dashboard it runs only
with the teacher's consent, and then contained (app.learner_ws.build): the
workspace lives in the learner's own scratch folder; the build reads src/,
writes only build/, install/ and log/, reads no other learner's files,
opens no network socket and stays under the sandbox's limits. Each hostile
setup.py below also runs uncontained as a control where that is safe, so a
sandbox that stopped nothing would fail here.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

import pytest

from app.containment.contain import SANDBOX_GID, UID_BASE, sandbox_processes
from app.containment.policy import RunPolicy
from app.learner_ws import build, overlay, served
from app.learner_ws.folder import LearnerWorkspace
from app.ros.errors import Ros2Error
from app.supervisor import LearnerProgram, Supervisor
from tests.conftest import wait_until
from tests.sandbox.conftest import SECRET, Classroom
from tests.sandbox.test_hostile import LOCAL, Listeners, non_loopback  # noqa: F401 (fixture)

pytestmark = pytest.mark.ros

PACKAGE_XML = """<?xml version="1.0"?>
<package format="3">
  <name>{name}</name>
  <version>0.0.0</version>
  <description>A learner's package</description>
  <maintainer email="learner@example.com">learner</maintainer>
  <license>Apache-2.0</license>
  <exec_depend>rclpy</exec_depend>
  <export>
    <build_type>ament_python</build_type>
  </export>
</package>
"""

SETUP_PY = """from setuptools import find_packages, setup

package_name = '{name}'
{hostile}
setup(
    name=package_name,
    version='0.0.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    entry_points={{'console_scripts': ['hello = {name}.hello:main']}},
)
"""

HELLO = """import os


def main():
    print(f'Hi from my own package, uid {os.getuid()}', flush=True)
"""

BUILD_SECONDS = 240.0  # an ament_python build takes seconds; a busy CI machine, more


def make_package(ws: LearnerWorkspace, name: str, hostile: str = "") -> Path:
    """An ament_python package as `ros2 pkg create` writes it, with extra code in setup.py."""
    package = ws.src / name
    (package / name).mkdir(parents=True)
    (package / "resource").mkdir()
    (package / "resource" / name).write_text("")
    (package / name / "__init__.py").write_text("")
    (package / name / "hello.py").write_text(HELLO)
    (package / "package.xml").write_text(PACKAGE_XML.format(name=name))
    (package / "setup.cfg").write_text(
        f"[develop]\nscript_dir=$base/lib/{name}\n[install]\ninstall_scripts=$base/lib/{name}\n"
    )
    (package / "setup.py").write_text(SETUP_PY.format(name=name, hostile=hostile))
    return package


def served_workspace(classroom: Classroom) -> LearnerWorkspace:
    """Alice's workspace as `serve --allow-remote` places it: in her scratch folder."""
    return LearnerWorkspace(classroom.scratch / "ros2_ws", remote=True, group=SANDBOX_GID).ensure()


def allowed(classroom: Classroom) -> RunPolicy:
    return RunPolicy(allowed=True, contained=True, hidden=tuple(classroom.hidden))


def run_to_end(supervisor: Supervisor, program: LearnerProgram) -> tuple[int | None, str]:
    supervisor.start_program(program)
    wait_until(
        lambda: not supervisor.status(program.name).active,
        timeout=BUILD_SECONDS,
        interval=0.2,
        what=f"{program.name} to end",
    )
    return supervisor.status(program.name).exit_code, "\n".join(supervisor.output(program.name))


def test_a_served_build_is_contained_and_so_is_the_node_it_installed(
    classroom: Classroom, supervisor: Supervisor
):
    ws = served_workspace(classroom)
    make_package(ws, "my_package")
    program = served.colcon_program(ws, ["build", "--symlink-install"], allowed(classroom))
    assert program.argv[1].endswith("contain.py") and "--no-ros" in program.argv
    code, output = run_to_end(supervisor, program)
    assert code == 0, output
    assert "Finished <<< my_package" in output
    executable = ws.root / "install" / "my_package" / "lib" / "my_package" / "hello"
    built_by = executable.lstat().st_uid
    assert built_by > UID_BASE, "the build ran as a sandbox uid, not as the dashboard's user"
    assert (ws.src / "my_package" / "setup.py").stat().st_uid == os.getuid()  # src untouched
    # ros2 run of the executable on a served dashboard: contained too.
    overlay.source(ws.root / "install")  # as `source install/setup.bash` in the Console
    try:
        env = overlay.child_env()
    finally:
        overlay.forget()
    plain = LearnerProgram("own:/my_package/hello", "/hello", (str(executable),), ws.root, env=env)
    node = served.node_program(ws, plain, allowed(classroom))
    assert node.argv[1].endswith("contain.py") and node.after_exit is not None
    with pytest.raises(Ros2Error, match="--allow-learner-code"):
        served.node_program(ws, plain, RunPolicy(allowed=False, contained=True))
    code, output = run_to_end(supervisor, node)
    assert code == 0, output
    uid = int(output.split("uid ")[1].split()[0])
    assert uid > UID_BASE and uid != built_by


def test_without_the_teachers_consent_no_build_runs(classroom: Classroom):
    ws = served_workspace(classroom)
    make_package(ws, "my_package")
    for policy in (RunPolicy(allowed=False, contained=True), None):
        with pytest.raises(build.BuildRefused, match="runs your setup.py"):
            served.colcon_program(ws, ["build"], policy)
    assert not (ws.root / "build").exists() and not (ws.root / "install").exists()


ATTEMPTS = """
import json, os, socket, sys
results = {{}}


def attempt(name, action):
    try:
        action()
        results[name] = 'done'
    except OSError as exc:
        results[name] = type(exc).__name__


def tcp():
    with socket.create_connection(({local!r}, {tcp}), timeout=3) as conn:
        conn.sendall(b'from-setup-py')


def udp():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        sock.sendto(b'from-setup-py', ({local!r}, {udp}))


attempt('read progress', lambda: open({secret!r}).read())
attempt('read other scratch', lambda: open({notes!r}).read())
attempt('read other workspace', lambda: open({theirs!r}).read())
attempt('write outside', lambda: open({outside!r}, 'w').write('defaced'))
attempt('write own src', lambda: open({own_src!r}, 'w').write('rewritten by setup.py'))
attempt('tcp out', tcp)
attempt('udp out', udp)
print('ATTEMPTS ' + json.dumps(results), file=sys.stderr)
"""


def test_hostile_setup_py_is_contained_and_reported(
    classroom: Classroom,
    supervisor: Supervisor,
    non_loopback: Listeners,  # noqa: F811 (the fixture)
):
    """Read another learner's files, write outside the workspace (and into its src/),
    talk to a non-loopback address: all done uncontained, all refused contained."""
    theirs = classroom.bob / "ros2_ws" / "src" / "their_package" / "setup.py"
    theirs.parent.mkdir(parents=True)
    theirs.write_text("# bob's own work\n")
    theirs.chmod(0o644)
    outside = classroom.shared / "defaced.txt"
    before = {p: p.read_bytes() for p in (classroom.progress / "bob.json", theirs)}

    def hostile(ws: LearnerWorkspace) -> str:
        return ATTEMPTS.format(
            local=LOCAL,
            tcp=non_loopback.tcp.getsockname()[1],
            udp=non_loopback.udp.getsockname()[1],
            secret=str(classroom.progress / "bob.json"),
            notes=str(classroom.bob / "notes.txt"),
            theirs=str(theirs),
            outside=str(outside),
            own_src=str(ws.src / "probe" / "package.xml"),
        )

    def attempts(output: str) -> dict[str, str]:
        lines = [line for line in output.splitlines() if line.startswith("ATTEMPTS ")]
        assert lines, output
        found = [json.loads(line.split(" ", 1)[1]) for line in lines]
        assert all(f == found[0] for f in found)  # colcon runs setup.py more than once
        return found[0]

    # The control: the same setup.py, built as on the learner's own machine.
    mine = LearnerWorkspace(classroom.root / "control_ws").ensure()
    make_package(mine, "probe", hostile(mine))
    code, output = run_to_end(supervisor, build.colcon_program(mine, ["build"]))
    assert code == 0, output
    assert set(attempts(output).values()) == {"done"}, output
    wait_until(lambda: len(non_loopback.received) >= 2, timeout=5, what="the control's packets")
    assert outside.read_text() == "defaced"
    outside.unlink()
    non_loopback.received.clear()
    non_loopback.frames.clear()

    ws = served_workspace(classroom)
    package = make_package(ws, "probe", hostile(ws))
    package_xml = (package / "package.xml").read_bytes()
    program = served.colcon_program(ws, ["build"], allowed(classroom))
    code, output = run_to_end(supervisor, program)
    assert code == 0, output  # the build itself goes on: setup.py caught its own errors
    results = attempts(output)
    assert results == {name: "PermissionError" for name in results}, output
    assert SECRET not in output and "bob's" not in output
    time.sleep(0.5)
    assert non_loopback.received == [] and non_loopback.frames == []
    assert not outside.exists()
    assert (package / "package.xml").read_bytes() == package_xml
    assert all(path.read_bytes() == data for path, data in before.items())


def test_a_failing_setup_py_names_its_line_and_what_stopped_it(
    classroom: Classroom, supervisor: Supervisor
):
    ws = served_workspace(classroom)
    hostile = f"secret = open({str(classroom.progress / 'bob.json')!r}).read()\n"
    make_package(ws, "probe", hostile)
    code, output = run_to_end(supervisor, served.colcon_program(ws, ["build"], allowed(classroom)))
    assert code != 0
    assert "PermissionError: [Errno 13] Permission denied" in output
    assert SECRET not in output
    lines = build.build_errors(output.splitlines(), ws)
    assert "~/ros2_ws/src/probe/setup.py, line 4" in "\n".join(lines), lines


FORK_BOMB = """
import os
while True:
    os.fork()
"""


# Its 32 spinning processes take both cores for a moment (load average 88 in ci55, while
# two browser pages starved): it runs with the loaded tests, alone.
@pytest.mark.loaded
def test_a_fork_bomb_in_setup_py_hits_the_process_limit_and_nothing_is_left(
    classroom: Classroom, supervisor: Supervisor
):
    ws = served_workspace(classroom)
    make_package(ws, "bomb", FORK_BOMB)
    program = served.colcon_program(ws, ["build"], allowed(classroom))
    started = time.monotonic()
    code, output = run_to_end(supervisor, program)
    assert code != 0
    assert "Resource temporarily unavailable" in output or "BlockingIOError" in output, output
    assert time.monotonic() - started < BUILD_SECONDS
    pid = supervisor.status(program.name).pid
    assert pid is not None
    wait_until(lambda: not sandbox_processes(pid), timeout=10, what="the bomb's processes to go")
    assert (ws.src / "bomb" / "setup.py").is_file()  # the learner's files are all there


def test_a_served_workspace_is_readable_by_the_sandbox_group_only(classroom: Classroom):
    ws = served_workspace(classroom)
    for folder in (ws.home, ws.root, ws.src):
        info = folder.stat()
        assert info.st_gid == SANDBOX_GID
        assert info.st_mode & 0o007 == 0, oct(info.st_mode)  # nothing for other users


def test_the_editors_completion_worker_runs_contained_when_served(classroom: Classroom):
    """Jedi imports compiled modules it finds on its path: served, it runs as learner code."""
    from app.exercises import code_assist

    policy = allowed(classroom)
    worker = code_assist.AssistProcess(
        lambda: code_assist.worker_argv(policy, classroom.scratch), classroom.scratch
    )
    try:
        code = "import rclpy\nnode = rclpy.create_node('n')\nnode.create_pub"
        answer = worker.request(
            {"op": "complete", "code": code, "path": str(classroom.scratch / "x.py"),
             "project": str(classroom.scratch), "line": 3, "column": 15, "sys_path": []}
        ).result(120)  # fmt: skip
        assert [item["name"] for item in answer["items"]] == ["create_publisher"], answer
        pid = worker._proc.pid  # type: ignore[union-attr]
        uid = int(Path(f"/proc/{pid}/status").read_text().split("Uid:")[1].split()[0])
        assert uid > UID_BASE
    finally:
        worker.close()

"""Builds and the learner's own executables under the rule for learner code.

A build runs the learner's setup.py and CMakeLists.txt, and ``ros2 run`` of
their package runs their node: learner code. On the learner's own machine it
runs as they would run it in a terminal (``app.learner_ws.build``). On a
dashboard served to other machines it runs only when the teacher allows
learner code, and then contained exactly like exercise code
(``app.containment.contain``):

* a build reads src/ and writes only build/, install/ and log/ (and its own
  temporary folder in build/); the learner's node writes only their scratch
  folder, the folder the workspace lives in;
* no other learner's files (their scratch folders and workspaces, every
  progress and code folder) can be read;
* no network socket at all for a build (it joins no ROS graph); a node gets
  ROS 2 over loopback and nothing else;
* the sandbox's limits on processes, CPU seconds, memory, file size and open
  files, under a uid of its own, all of it ended when the program ends.

Kept apart from ``build`` because the lessons' checks import ``build`` and
must not import the exercises (import-linter's layers).
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

from app.containment import sandbox
from app.containment.policy import RunPolicy
from app.learner_ws import build
from app.learner_ws.folder import LearnerWorkspace
from app.ros.errors import Ros2Error
from app.supervisor import LearnerProgram

COLCON_MAIN = Path(__file__).resolve().parent / "launcher" / "colcon_main.py"
# colcon, setup.py, CMake, make and the compilers are processes (and threads) of one
# sandbox uid; each process gets these CPU seconds and this much address space.
PROCESSES = 128
CPU_SECONDS = 600
MEMORY_BYTES = 3 * 1024**3
OPEN_FILES = 1024


def _allowed(policy: RunPolicy | None, what: str) -> RunPolicy:
    if policy is None or not policy.allowed:
        why = policy.refusal() if policy is not None else "No rule for learner code was given."
        raise build.BuildRefused(f"{what} runs your own code. {why}")
    return policy


def colcon_program(
    workspace: LearnerWorkspace, words: list[str], policy: RunPolicy | None
) -> LearnerProgram:
    """``colcon WORDS`` in the workspace: as the learner's user, or (served) contained."""
    if not workspace.remote:
        return build.colcon_program(workspace, words)
    words = build.check_words(words)
    policy = _allowed(policy, "colcon runs your setup.py and CMakeLists.txt, i.e. it")
    sandbox.require_sandbox("builds", build.BuildRefused)
    workspace.ensure()
    build_dir, install, log = workspace.colcon_folders()
    limits = sandbox.SandboxLimits(
        cpu_seconds=CPU_SECONDS,
        memory_bytes=MEMORY_BYTES,
        processes=PROCESSES,
        file_bytes=workspace.limits.file_bytes,
        open_files=OPEN_FILES,
    )
    argv = sandbox.contained_argv(
        COLCON_MAIN, build_dir, policy.hidden, limits, writable=(install, log), ros=False
    )
    return LearnerProgram(
        name=f"{build.PROGRAM_PREFIX}{' '.join(words[:1])}",
        node_name="/_colcon_is_no_node",
        names_its_node=False,
        argv=(*argv, str(workspace.root), *words),
        cwd=build_dir,
        env=build.build_env(workspace),
        after_exit=sandbox.kill_leftovers,
    )


def node_program(
    workspace: LearnerWorkspace, program: LearnerProgram, policy: RunPolicy | None
) -> LearnerProgram:
    """The learner's installed executable (``argv[0]``) as ``program`` starts it, or (served)
    contained, writing only the folder the workspace lives in."""
    if not workspace.remote:
        return program
    policy = _allowed(policy, "your package's executable")
    sandbox.require_sandbox("your node", Ros2Error)
    script, *tail = program.argv
    argv = sandbox.contained_argv(Path(script), workspace.home, policy.hidden) + tail
    return dataclasses.replace(
        program, argv=tuple(argv), cwd=workspace.home, after_exit=sandbox.kill_leftovers
    )

"""`colcon build` / `colcon test` in the learner's workspace, as one supervised program.

The build is real colcon (colcon-core, colcon-ros, colcon-python-setup-py,
colcon-cmake from PyPI) run by the project's Python in the workspace root, so
``build/``, ``install/`` and ``log/`` appear there as in a terminal. It runs
the learner's ``setup.py`` and ``CMakeLists.txt``, i.e. learner code, so:

* only the options the tutorials use are accepted (package selection,
  ``--symlink-install``, ``--merge-install``, ...): nothing typed may move
  the build, install or log folders out of the workspace or pick a compiler;
* every file the build writes is capped (RLIMIT_FSIZE, set in the process
  before colcon starts), and the caller stops the build when it runs too
  long or when the workspace outgrows its disk budget (``BuildLimits``);
* a dashboard served to other machines refuses builds (see ``BuildRefused``).

CMake packages (rosidl interface packages) get the ROS wheels' prefix and our
toolchain file (``cmake/toolchain.cmake``) through the environment; the
learner's CMakeLists.txt stays as the tutorial writes it.
"""

from __future__ import annotations

import os
import re
import sys
from pathlib import Path

from app.learner_ws import overlay
from app.learner_ws.folder import LearnerWorkspace
from app.ros.errors import Ros2Error
from app.supervisor import LearnerProgram

TOOLCHAIN = Path(__file__).resolve().parent / "cmake" / "toolchain.cmake"
PROGRAM_PREFIX = "colcon:"
VERBS = ("build", "test", "test-result", "list", "graph", "info")
_PACKAGE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_-]*$")
# option -> how many values: "n" one or more package names, int a fixed count
_OPTIONS: dict[str, dict[str, object]] = {
    "build": {
        "--packages-select": "n", "--packages-up-to": "n", "--packages-skip": "n",
        "--packages-ignore": "n", "--symlink-install": 0, "--merge-install": 0,
        "--parallel-workers": 1, "--continue-on-error": 0, "--cmake-clean-cache": 0,
        "--cmake-clean-first": 0, "--cmake-force-configure": 0,
        "--executor": 1, "--event-handlers": "n",
    },
    "test": {
        "--packages-select": "n", "--packages-up-to": "n", "--packages-skip": "n",
        "--merge-install": 0, "--parallel-workers": 1, "--executor": 1,
        "--return-code-on-test-failure": 0, "--event-handlers": "n",
    },
    "test-result": {"--all": 0, "--verbose": 0, "--result-files-only": 0},
    "list": {"--names-only": 0, "--paths-only": 0, "--topological-order": 0},
    "graph": {"--density": 0},
    "info": {},
}  # fmt: skip
_SAFE_VALUE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.+-]*$")
# The per-file size cap first, then colcon's own entry point in the same process
# (one interpreter start, as the `colcon` script has).
_LAUNCHER = (
    "import resource, sys\n"
    "cap = int(sys.argv[1])\n"
    "resource.setrlimit(resource.RLIMIT_FSIZE, (cap, cap))\n"
    "sys.argv = ['colcon', *sys.argv[2:]]\n"
    "from colcon_core.command import main\n"
    "sys.exit(main())\n"
)


class BuildRefused(Ros2Error):
    """This build may not run here (bad options, or a served dashboard)."""


def check_words(words: list[str]) -> list[str]:
    """``colcon VERB [options]`` as typed, checked option by option; returns them."""
    if not words:
        raise BuildRefused(f"usage: colcon {{{','.join(VERBS)}}} [options]")
    verb, rest = words[0], words[1:]
    if verb not in VERBS:
        raise BuildRefused(f"colcon: unknown verb '{verb}' here (one of: {', '.join(VERBS)})")
    allowed = _OPTIONS[verb]
    i = 0
    while i < len(rest):
        flag = rest[i]
        if flag not in allowed:
            known = ", ".join(allowed) or "none"
            raise BuildRefused(
                f"colcon {verb}: option {flag!r} is not available here (options: {known}); "
                "build, install and log folders stay in your workspace"
            )
        count = allowed[flag]
        i += 1
        if count == "n":
            start = i
            while i < len(rest) and not rest[i].startswith("-"):
                check = _PACKAGE if flag.startswith("--packages") else _SAFE_VALUE
                if not check.match(rest[i]):
                    raise BuildRefused(f"colcon {verb}: {flag} got {rest[i]!r}, not a name")
                i += 1
            if i == start:
                raise BuildRefused(f"colcon {verb}: {flag} needs at least one value")
        elif isinstance(count, int) and count:
            if i >= len(rest) or not _SAFE_VALUE.match(rest[i]):
                raise BuildRefused(f"colcon {verb}: {flag} needs a value")
            i += 1
    return list(words)


def build_env(workspace: LearnerWorkspace) -> dict[str, str]:
    """What colcon gets over the supervisor's environment."""
    sourced = overlay.child_env()
    venv_bin = str(Path(sys.executable).parent)  # cmake, ninja and colcon of the venv
    ours = [str(p) for p in overlay.overlay()]
    return {
        # Only sourced workspaces: colcon warns about prefixes without local_setup files.
        overlay.PREFIX_ENV: os.pathsep.join(ours),
        "CMAKE_PREFIX_PATH": os.pathsep.join(ours),
        "PYTHONPATH": sourced["PYTHONPATH"],
        "LD_LIBRARY_PATH": sourced["LD_LIBRARY_PATH"],
        "PATH": os.pathsep.join([venv_bin, sourced["PATH"]]),
        "CMAKE_TOOLCHAIN_FILE": str(TOOLCHAIN),
        "CLASSROOM_PYTHON": sys.executable,
        "CLASSROOM_UNDERLAY": sys.prefix,
        "PYTHONUNBUFFERED": "1",
        "PYTHONDONTWRITEBYTECODE": "1",
        "COLCON_HOME": str(workspace.root / ".colcon"),
    }


def colcon_argv(workspace: LearnerWorkspace, words: list[str]) -> list[str]:
    """The process: our launcher (file-size cap), then colcon's main with WORDS."""
    cap = str(workspace.limits.file_bytes)
    return [sys.executable, "-c", _LAUNCHER, cap, *check_words(words)]


def colcon_program(workspace: LearnerWorkspace, words: list[str]) -> LearnerProgram:
    """``colcon WORDS`` in the workspace root, for the supervisor."""
    if workspace.remote:
        raise BuildRefused(
            "colcon runs your setup.py and CMakeLists.txt, i.e. your own code; on a dashboard "
            "served to other machines builds are not available yet (they would need the same "
            "containment as exercise code). Build on your own machine's dashboard."
        )
    return LearnerProgram(
        name=f"{PROGRAM_PREFIX}{' '.join(words[:1])}",
        node_name="/_colcon_is_no_node",
        argv=tuple(colcon_argv(workspace, words)),
        cwd=workspace.ensure().root,
        env=build_env(workspace),
    )


def disk_usage(root: Path, folders: tuple[str, ...] = ("build", "install", "log")) -> int:
    """Bytes the build's folders take (allocated blocks), without following links."""
    total = 0
    for name in folders:
        for folder, _dirs, files in os.walk(root / name):
            for file_name in files:
                try:
                    total += os.lstat(os.path.join(folder, file_name)).st_blocks * 512
                except OSError:
                    continue
    return total

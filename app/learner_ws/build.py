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
* on a dashboard served to other machines a build follows the rule for
  learner code (``app.learner_ws.served``): refused unless the teacher
  allows learner code, and then contained like exercise code.

CMake packages (rosidl interface packages) get the ROS wheels' prefix and our
toolchain file (``cmake/toolchain.cmake``) from our colcon extension
(``colcon_extension``), as ``colcon build`` in a terminal does; the learner's
CMakeLists.txt stays as the tutorial writes it.
"""

from __future__ import annotations

import os
import re
import sys
from dataclasses import dataclass
from pathlib import Path

from app.learner_ws import overlay
from app.learner_ws.folder import LearnerWorkspace
from app.ros.errors import Ros2Error
from app.supervisor import LearnerProgram

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
    """This build may not run here (bad options, or a served dashboard's rule)."""


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
    """What colcon gets over the supervisor's environment: the Console's sourced workspaces
    (a terminal's shell has its own); the toolchain comes from our colcon extension."""
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
        "PYTHONUNBUFFERED": "1",
        "PYTHONDONTWRITEBYTECODE": "1",
        "COLCON_HOME": str(workspace.root / ".colcon"),
    }


def colcon_argv(workspace: LearnerWorkspace, words: list[str]) -> list[str]:
    """The process: our launcher (file-size cap), then colcon's main with WORDS."""
    cap = str(workspace.limits.file_bytes)
    return [sys.executable, "-c", _LAUNCHER, cap, *check_words(words)]


def colcon_program(workspace: LearnerWorkspace, words: list[str]) -> LearnerProgram:
    """``colcon WORDS`` in the workspace root, for the supervisor, as the learner's own user.

    A served workspace's builds go through ``app.learner_ws.served`` (the rule for
    learner code, containment); here they are refused.
    """
    words = check_words(words)
    if workspace.remote:
        raise BuildRefused(
            "colcon runs your setup.py and CMakeLists.txt, i.e. your own code: on a served "
            "dashboard only contained (app.learner_ws.served)"
        )
    return LearnerProgram(
        name=f"{PROGRAM_PREFIX}{' '.join(words[:1])}",
        node_name="/_colcon_is_no_node",
        names_its_node=False,
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


# -- what a failed build says, pointed at the learner's files -----------------------------

_FRAME = re.compile(r'^\s*File "(?P<file>[^"]+)", line (?P<line>\d+)(?P<rest>.*)$')
_STRING_WARNING = re.compile(r"^<string>:(?P<line>\d+): (?P<rest>.*)$")
_STDERR_BLOCK = re.compile(r"^--- stderr: (?P<package>\S+)")
_FAILED = re.compile(r"^Failed\s+<<< (?P<package>\S+)")
_IDENTIFICATION = re.compile(
    r"ERROR:colcon\.colcon_core\.package_identification:Exception in package identification "
    r"extension '[^']+' in '(?P<path>[^']+)'"
)
_CMAKE = re.compile(r"^CMake (?P<kind>Error|Warning)(?: \(dev\))? at (?P<file>[^:]+):(?P<line>\d+)")
_COMPILER = re.compile(
    r"^(?P<file>/[^:\s]+):(?P<line>\d+):(?:\d+:)? (?P<kind>error|fatal error): (?P<text>.*)$"
)
MAX_LINE = 160


@dataclass(frozen=True)
class BuildError:
    """One error of a build, where it is in the learner's files: for the Console's last lines."""

    where: str  # "~/ros2_ws/src/my_package/setup.py, line 4" ("" when colcon's own)
    text: str  # "FileNotFoundError: [Errno 2] No such file or directory: ..."

    def line(self) -> str:
        return f"{self.where}: {self.text}" if self.where else self.text


def package_folders(ws: LearnerWorkspace | None) -> dict[str, Path]:
    """Package name -> its folder, from every package.xml under src/ (read on failure only)."""
    found: dict[str, Path] = {}
    if ws is None or not ws.src.is_dir():
        return found
    for manifest in sorted(ws.src.glob("**/package.xml")):
        try:
            text = manifest.read_text(encoding="utf-8", errors="replace")
        except OSError:
            continue
        match = re.search(r"<name>\s*([^<\s]+)\s*</name>", text)
        found.setdefault(match.group(1) if match else manifest.parent.name, manifest.parent)
    return found


def _is_tool(path: str) -> bool:
    return "/site-packages/" in path or "/lib/python3" in path or path.startswith("/usr/")


class _Reader:
    """Walks colcon's lines once; keeps the learner's, rewrites paths the way they read them."""

    def __init__(self, lines: list[str], ws: LearnerWorkspace | None) -> None:
        self.lines, self.ws = lines, ws
        self.folders = package_folders(ws)

    def shown(self, path: Path) -> str:
        return self.ws.shown(path) if self.ws is not None else str(path)

    def setup_py(self, package: str | None) -> str:
        if package is None:
            return "setup.py"
        folder = self.folders.get(package)
        if folder is None and self.ws is not None and (self.ws.root / package).is_dir():
            folder = self.ws.root / package  # a path from colcon's identification error
        return self.shown(folder / "setup.py") if folder is not None else f"{package}/setup.py"

    def package_after(self, index: int) -> str | None:
        """The package a traceback belongs to, from the line colcon prints after it."""
        for line in self.lines[index:]:
            for pattern, key in ((_IDENTIFICATION, "path"), (_FAILED, "package"),
                                 (_STDERR_BLOCK, "package")):  # fmt: skip
                match = pattern.search(line)
                if match:
                    return match.group(key)
        return None

    def source_file(self, package: str | None, relative: str) -> str:
        folder = self.folders.get(package or "")
        return self.shown(folder / relative) if folder is not None else relative

    def read(self) -> tuple[list[str], list[BuildError]]:
        kept: list[str] = []
        errors: list[BuildError] = []
        block: str | None = None  # inside colcon's "--- stderr: PKG" block
        inside_tool = after_run_setup = False
        where = ""
        for index, line in enumerate(self.lines):
            text = line.strip()
            if match := _STDERR_BLOCK.match(line):
                block = match["package"]
            elif text == "---":
                block = None
            frame = _FRAME.match(line)
            if frame is not None:
                file = frame["file"]
                if file == "<string>" and after_run_setup:  # setup.py, run by colcon's helper
                    package = block or self.package_after(index)
                    where = f"{self.setup_py(package)}, line {frame['line']}"
                    kept.append(f"  {where}{frame['rest']}")
                    inside_tool = after_run_setup = False
                    continue
                after_run_setup = "run_setup" in frame["rest"]
                inside_tool = file == "<string>" or _is_tool(file)
                if inside_tool:
                    continue
                where = f"{self.shown(Path(file))}, line {frame['line']}"
                kept.append(f"  {where}{frame['rest']}")
                continue
            if inside_tool and line.startswith("    "):
                continue  # the source line (and its ^^^ marks) of a tool's frame
            inside_tool = False
            if (
                not text
                or set(text) <= set("^~ ")
                or text.startswith(("Traceback", "Starting >>>", "subprocess.CalledProcessError"))
            ):
                continue
            if match := _IDENTIFICATION.search(line):
                shown = (
                    self.setup_py(match["path"].rsplit("/", 1)[-1])
                    if self.folders
                    else match["path"]
                )
                line = f"colcon could not read {shown}: it failed (the error above)"
                where = ""
            elif match := _STRING_WARNING.match(text):
                package = block or self.package_after(index)
                line = f"{self.setup_py(package)}, line {match['line']}: {match['rest']}"
            elif match := _CMAKE.match(text):
                file = self.source_file(block, match["file"])
                where = f"{file}, line {match['line']}"
                line = f"CMake {match['kind']} at {where}{text[match.end() :]}"
                if match["kind"] == "Error":
                    errors.append(BuildError(where, self._next_text(index)))
            elif match := _COMPILER.match(text):
                where = f"{self.shown(Path(match['file']))}, line {match['line']}"
                line = f"{where}: {match['kind']}: {match['text']}"
                errors.append(BuildError(where, match["text"]))
            elif (
                where
                and not line.startswith((" ", "\t"))
                and ("Error" in text.split(":", 1)[0] or "Exception" in text.split(":", 1)[0])
            ):
                errors.append(BuildError(where, text))  # the exception that ends a traceback
                where = ""
            kept.append(line if len(line) <= MAX_LINE else line[: MAX_LINE - 3] + "...")
        return kept, errors

    def _next_text(self, index: int) -> str:
        for line in self.lines[index + 1 : index + 6]:
            if line.strip():
                return line.strip()
        return ""


def build_errors(lines: list[str], ws: LearnerWorkspace | None = None) -> list[str]:
    """What of colcon's output is about the learner's files, their paths as the learner
    reads them (``~/ros2_ws/src/pkg/setup.py, line 4``); frames inside colcon,
    setuptools or Python itself are left out, long lines are cut.

    colcon reads setup.py by running its text through a helper, so a traceback
    says ``File "<string>", line N`` there: that is setup.py's line N, of the
    package the lines around it name.
    """
    return _Reader(lines, ws).read()[0]


def error_summary(lines: list[str], ws: LearnerWorkspace | None = None) -> list[BuildError]:
    """Each error of a failed build with its file and line (the Console's closing lines)."""
    return _Reader(lines, ws).read()[1]

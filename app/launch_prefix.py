"""An ament prefix for `ros2 launch`: the catalog's programs and launch files, as on ROS.

``launch_ros`` finds a Node's executable at ``<prefix>/lib/<package>/<exe>``
and ``ros2 launch PACKAGE FILE`` finds the file under
``<prefix>/share/<package>/`` through the ament index, exactly as on a ROS 2
installation. This module writes such a prefix for the catalog:

* ``lib/<package>/<name>`` for every catalog entry (``turtlesim/turtlesim_node``,
  ``tutorial_nodes/talker``), ``lib/tutorial_nodes/<module>`` for every
  program module, and turtlesim's ``mimic``: small scripts that exec
  ``python -m nodes.<module>`` with the entry's own arguments;
* ``share/tutorial_nodes/launch/<group>.launch.py`` for every catalog launch
  group (``app.launch.launch_file_text``) and upstream's
  ``share/turtlesim/launch/multisim.launch.py``: real launch files;
* the ``packages`` markers of the ament resource index.

It is written once per catalog content into a folder every process can read
(contained learner code included: it may read everything but the home
folders), and rewritten whenever the catalog changes.
"""

from __future__ import annotations

import hashlib
import os
import sys
import tempfile
from collections.abc import Mapping
from pathlib import Path

import ros2launch
from nav2_bringup import share_files as nav2_bringup_files

from app.ament_prefix import write_prefix
from app.catalog import ENTRIES, GROUPS, CatalogEntry
from app.containment import sandbox
from app.containment.policy import RunPolicy
from app.launch import PACKAGE, launch_file_text
from app.supervisor import LearnerProgram
from app.tf2_launch_files import LAUNCH_FILES as TF2_LAUNCH_FILES

PREFIX_ENV = "AMENT_PREFIX_PATH"
# Upstream executable names the catalog files under another name.
_ALIASES: dict[tuple[str, str], str] = {
    ("turtlesim", "mimic"): "turtle_mimic",
    # learning_tf2_py: the package the tf2 tutorials have the learner write
    **{
        ("learning_tf2_py", exe): exe
        for exe in (
            "static_turtle_tf2_broadcaster",
            "turtle_tf2_broadcaster",
            "turtle_tf2_listener",
            "fixed_frame_tf2_broadcaster",
            "dynamic_frame_tf2_broadcaster",
        )
    },
    ("urdf_tutorial_r2d2", "state_publisher"): "r2d2_state_publisher",
}

MULTISIM = '''"""turtlesim's multisim.launch.py: two turtlesims, in /turtlesim1 and /turtlesim2."""

from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription(
        [
            Node(
                package="turtlesim",
                executable="turtlesim_node",
                output="screen",
                namespace="turtlesim1",
            ),
            Node(
                package="turtlesim",
                executable="turtlesim_node",
                output="screen",
                namespace="turtlesim2",
            ),
        ]
    )
'''


def _script(module: str, words: list[str]) -> str:
    return (
        f"#!{sys.executable}\n"
        f'"""ROS 2 Classroom: this executable is the catalog program nodes.{module}."""\n'
        "import os\nimport sys\n\n"
        f"argv = [sys.executable, '-m', 'nodes.{module}', *{words!r}, *sys.argv[1:]]\n"
        "os.execv(sys.executable, argv)\n"
    )


def _entry_words(entry: CatalogEntry) -> list[str]:
    return entry.argv_tail()


def _files() -> dict[str, str]:
    """Relative path -> content of every file of the prefix."""
    files: dict[str, str] = {}
    by_name = {entry.name: entry for entry in ENTRIES}
    for entry in ENTRIES:
        files.setdefault(f"lib/{PACKAGE}/{entry.module}", _script(entry.module, []))
    for entry in ENTRIES:
        files[f"lib/{entry.package}/{entry.name}"] = _script(entry.module, _entry_words(entry))
    for (package, exe), name in _ALIASES.items():
        entry = by_name[name]
        files[f"lib/{package}/{exe}"] = _script(entry.module, _entry_words(entry))
    for group in GROUPS:
        files[f"share/{PACKAGE}/launch/{group.name}.launch.py"] = launch_file_text(group)
    files["share/turtlesim/launch/multisim.launch.py"] = MULTISIM
    files.update(TF2_LAUNCH_FILES)  # issue 23: turtle_tf2_py's demo launch files
    files.update(nav2_bringup_files())  # issue 40: nav2_bringup's launch files and params
    packages = {path.split("/")[1] for path in files}
    for package in packages:
        files[f"share/ament_index/resource_index/packages/{package}"] = ""
        files[f"share/{package}/package.xml"] = (
            f'<?xml version="1.0"?>\n<package format="3">\n  <name>{package}</name>\n'
            "  <version>0.0.0</version>\n  <description>ROS 2 Classroom catalog programs"
            '</description>\n  <maintainer email="classroom@localhost">ROS 2 Classroom'
            "</maintainer>\n  <license>Apache-2.0</license>\n</package>\n"
        )
    return files


def catalog_prefix(parent: Path | None = None) -> Path:
    """The prefix for the current catalog, written if missing; safe to call concurrently."""
    files = _files()
    digest = hashlib.sha256(
        repr(sorted(files.items())).encode() + sys.executable.encode()
    ).hexdigest()[:16]
    parent = parent or Path(tempfile.gettempdir()) / f"ros2_classroom_ament_{os.getuid()}"
    return write_prefix(parent / digest, files)


def with_catalog_prefix(env: Mapping[str, str], prefix: Path | None = None) -> dict[str, str]:
    """``env`` whose AMENT_PREFIX_PATH ends with the catalog prefix (overlays stay first)."""
    prefix = prefix or catalog_prefix()
    out = dict(env)
    paths = [p for p in out.get(PREFIX_ENV, "").split(os.pathsep) if p and p != str(prefix)]
    # Before the venv's own prefix, never after it: the wheels' turtlesim there
    # holds only the interfaces, and would hide the catalog's turtlesim (its
    # executables and launch files), as one package of a real install would not.
    wheels = os.path.realpath(sys.prefix)
    at = next((i for i, p in enumerate(paths) if os.path.realpath(p) == wheels), len(paths))
    out[PREFIX_ENV] = os.pathsep.join([*paths[:at], str(prefix), *paths[at:]])
    return out


# ``ros2 launch`` itself, started by path (the sandbox runs scripts by path, never with -m).
ROS2LAUNCH_MAIN = Path(ros2launch.__file__ or "ros2launch").resolve().parent / "__main__.py"


def launch_env(env: Mapping[str, str] | None = None) -> dict[str, str]:
    """What a launch program adds to the supervisor's environment, as a sourced shell would.

    The ament prefixes (the Console's sourced workspaces first, the catalog last),
    and the sourced packages' Python and library folders: a learner's node that
    imports the learner's own interface package needs all three.
    """
    from app.learner_ws.overlay import child_env, overlay

    base = os.environ if env is None else env
    if env is not None:
        return {PREFIX_ENV: with_catalog_prefix(base)[PREFIX_ENV]}
    # Not child_env's whole search path: its fallback underlay (the venv, whose
    # turtlesim holds only interfaces) must not hide the catalog's turtlesim.
    front = [str(p) for p in overlay()]
    rest = [p for p in base.get(PREFIX_ENV, "").split(os.pathsep) if p and p not in front]
    full = with_catalog_prefix({PREFIX_ENV: os.pathsep.join(front + rest)})
    env = {**child_env(base), PREFIX_ENV: full[PREFIX_ENV]}
    # As a sourced shell: the ROS tools launch files call (xacro) are on PATH.
    tools = os.path.dirname(sys.executable)
    path = env.get("PATH") or base.get("PATH", "")
    if tools not in path.split(os.pathsep):
        env["PATH"] = os.pathsep.join(p for p in (path, tools) if p)
    return env


class LaunchFileNotFound(LookupError):
    """``ros2 launch PACKAGE FILE`` found no such file; the message is ros2's."""


def prefixes(env: Mapping[str, str] | None = None) -> list[Path]:
    text = launch_env(env)[PREFIX_ENV]
    return [Path(p) for p in text.split(os.pathsep) if p]


def find_launch_file(package: str, file_name: str, env: Mapping[str, str] | None = None) -> Path:
    """The file as ``ros2 launch`` finds it: the package's share folder, searched recursively."""
    searched = prefixes(env)
    for prefix in searched:
        if (prefix / "share/ament_index/resource_index/packages" / package).is_file():
            share = prefix / "share" / package
            break
    else:
        listed = ", ".join(f"'{p}'" for p in searched)
        raise LaunchFileNotFound(
            f"Package '{package}' not found: \"package '{package}' not found, "
            f'searching: [{listed}]"'
        )
    matches = sorted(
        Path(root) / name for root, _d, files in os.walk(share) for name in files
        if name == file_name
    )  # fmt: skip
    if not matches:
        raise LaunchFileNotFound(
            f"file '{file_name}' was not found in the share directory of package "
            f"'{package}' which is at '{share}'"
        )
    if len(matches) > 1:
        listed = ", ".join(f"'{m}'" for m in matches)
        raise LaunchFileNotFound(
            f"file '{file_name}' was found more than once in the share directory of package "
            f"'{package}': [{listed}]"
        )
    return matches[0]


def is_ours(path: Path) -> bool:
    """A launch file of the catalog prefix (trusted), not a learner's."""
    return path.resolve().is_relative_to(catalog_prefix().resolve())


class LaunchRefused(RuntimeError):
    """A learner's launch file may not run here (the same rule as their other code)."""


def launch_program(
    name: str,
    node_name: str,
    words: list[str],
    cwd: Path,
    policy: RunPolicy | None,
    *,
    trusted: bool,
) -> LearnerProgram:
    """``ros2 launch WORDS`` as one supervised program (its nodes are in its process group).

    A launch file is Python code: one of ours (``trusted``) runs as is, a learner's
    runs exactly as their exercise code does (refused, or contained).
    """
    env = launch_env()
    if policy is None and not trusted:
        raise LaunchRefused(
            f"{words[0]} is a learner's launch file, and no rule for learner code was given here"
        )
    if trusted or (policy is not None and policy.allowed and not policy.contained):
        argv = [sys.executable, str(ROS2LAUNCH_MAIN), *words]
        return LearnerProgram(name, node_name, tuple(argv), cwd, env=env)
    assert policy is not None
    if not policy.allowed:
        raise LaunchRefused(policy.refusal())
    sandbox.require_sandbox("learner code", LaunchRefused)
    argv = sandbox.contained_argv(ROS2LAUNCH_MAIN, cwd, policy.hidden) + words
    return LearnerProgram(
        name, node_name, tuple(argv), cwd, after_exit=sandbox.kill_leftovers, env=env
    )

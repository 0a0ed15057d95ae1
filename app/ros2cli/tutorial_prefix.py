"""An ament prefix for the tutorials' package names the catalog plays (demo_nodes_py, ...).

``ros2 run demo_nodes_py talker`` and ``Node(package='demo_nodes_py',
executable='talker')`` find programs through the ament index:
``<prefix>/share/ament_index/resource_index/packages/<pkg>`` marks the
package and ``<prefix>/lib/<pkg>/<exe>`` is the program. This prefix holds
every ``(package, executable)`` of ``run.UPSTREAM`` whose package the
catalog prefix of ``app.launch_prefix`` (turtlesim, tutorial_nodes, ...)
does not already hold, so the two never split one package. Each program is
a two-line shell script that execs ``python -m nodes.<module>`` with the
catalog entry's fixed arguments; the browser still starts only catalog code.

Written on first use (and whenever its content changes) to
``var/ament/tutorial_packages-<hash>`` in the project; ``python -m
app.ros2cli.tutorial_prefix`` writes it and prints the path.
"""

from __future__ import annotations

import hashlib
import shlex
import sys
from pathlib import Path

from app import PROJECT_ROOT
from app.ament_prefix import write_prefix
from app.catalog import lookup
from app.ros2cli.run import UPSTREAM

PARENT = PROJECT_ROOT / "var" / "ament"
INDEX = "share/ament_index/resource_index/packages"


def _script(module: str, words: list[str]) -> str:
    command = " ".join(shlex.quote(w) for w in [sys.executable, "-m", f"nodes.{module}", *words])
    return (
        "#!/bin/sh\n"
        f"# ROS 2 Classroom: the tutorials' program, played by the catalog's nodes.{module}\n"
        f'exec {command} "$@"\n'
    )


def _taken_packages() -> set[str]:
    """Packages the launch prefix already holds (its lib/<pkg>/ folders)."""
    try:
        from app.launch_prefix import catalog_prefix
    except ImportError:
        return set()
    lib = catalog_prefix() / "lib"
    return {p.name for p in lib.iterdir() if p.is_dir()} if lib.is_dir() else set()


def files() -> dict[str, str]:
    """Relative path -> content of every file of the prefix."""
    taken = _taken_packages()
    out: dict[str, str] = {}
    for (package, executable), name in sorted(UPSTREAM.items()):
        if package in taken:
            continue
        entry = lookup(name)
        out[f"lib/{package}/{executable}"] = _script(entry.module, entry.argv_tail())
        out[f"{INDEX}/{package}"] = ""
        out[f"share/{package}/package.xml"] = (
            f'<?xml version="1.0"?>\n<package format="3">\n  <name>{package}</name>\n'
            "  <version>0.0.0</version>\n  <description>The tutorials' package, played by "
            'ROS 2 Classroom\'s catalog</description>\n  <maintainer email="classroom@localhost">'
            "ROS 2 Classroom</maintainer>\n  <license>Apache-2.0</license>\n</package>\n"
        )
    return out


def tutorial_prefix(parent: Path = PARENT) -> Path:
    """The prefix for the current catalog, written if missing (atomic rename)."""
    content = files()
    digest = hashlib.sha256(repr(sorted(content.items())).encode()).hexdigest()[:12]
    return write_prefix(parent / f"tutorial_packages-{digest}", content)


if __name__ == "__main__":
    print(tutorial_prefix())

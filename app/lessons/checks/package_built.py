"""Check ``package_built``: colcon installed the package (and an executable of it)."""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

from app.lessons.checks._own_workspace import building, installed_prefix, package_name, workspace
from app.lessons.registry import FAIL, PASS, WAITING, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_check(
    "package_built",
    required="package",
    optional="executable without",
    words=(
        "colcon installed the package into your workspace's install folder (with its ament "
        "index marker), with the executable `ros2 run` will look for, or without one"
    ),
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    """``executable``: must be installed; ``without``: must not be (a mistake's symptom)."""
    ws = workspace()
    package = package_name(c["package"])
    if building(rt):
        return CheckResult(WAITING, "colcon is still building")
    prefix = installed_prefix(ws, package)
    if prefix is None:
        return CheckResult(
            FAIL, f"{package} is not in {ws.shown(ws.root / 'install')} yet (colcon build it)"
        )
    folder = prefix / "lib" / package

    def installed(name: str) -> bool:
        path = folder / name
        return path.is_file() and os.access(path, os.X_OK)

    executable, without = c.get("executable"), c.get("without")
    if executable and not installed(executable):
        return CheckResult(
            FAIL,
            f"{package} is built, but {ws.shown(folder)} has no executable {executable}: "
            "is it in setup.py's console_scripts, and did you build again?",
        )
    if without and installed(without):
        return CheckResult(FAIL, f"{package} already has the executable {without}")
    what = f" with {executable}" if executable else ""
    what += f", without {without}" if without else ""
    return CheckResult(PASS, f"{package} is installed in {ws.shown(prefix)}{what}")

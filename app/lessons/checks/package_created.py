"""Check ``package_created``: a package of that name (and build type) is in the workspace's src."""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

from app.lessons.checks._own_workspace import package_name, workspace
from app.lessons.registry import FAIL, PASS, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec

_NAME = re.compile(r"<name>\s*([^<\s]+)\s*</name>")
_BUILD_TYPE = re.compile(r"<build_type>\s*([^<\s]+)\s*</build_type>")


@register_check(
    "package_created",
    required="package",
    optional="build_type",
    words="your workspace's src folder holds a package of that name (and build type)",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    ws = workspace()
    package = package_name(c["package"])
    # colcon finds packages at any depth of src/; the tutorials put them one or two deep.
    for manifest in [*ws.src.glob("*/package.xml"), *ws.src.glob("*/*/package.xml")]:
        text = manifest.read_text(encoding="utf-8", errors="replace")
        name = _NAME.search(text)
        if name is None or name.group(1) != package:
            continue
        where = ws.shown(manifest.parent)
        wanted = c.get("build_type")
        found = _BUILD_TYPE.search(text)
        build_type = found.group(1) if found else "(none given)"
        if wanted and build_type != wanted:
            return CheckResult(FAIL, f"{where} has build type {build_type}, not {wanted}")
        return CheckResult(PASS, f"{where} is the package {package} ({build_type})")
    return CheckResult(
        FAIL, f"no package.xml naming {package} under {ws.shown(ws.src)} (ros2 pkg create it there)"
    )

"""Check ``package_sourced``: the Console's sourced workspace provides the package."""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.learner_ws import overlay
from app.lessons.checks._own_workspace import installed_prefix, package_name, workspace
from app.lessons.registry import FAIL, PASS, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec


@register_check(
    "package_sourced",
    required="package",
    words="the Console has sourced install/setup.bash since the package was built",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    ws = workspace()
    package = package_name(c["package"])
    prefix = overlay.package_prefix(package)
    if prefix is not None and prefix in overlay.overlay():
        return CheckResult(PASS, f"the Console finds {package} in {ws.shown(prefix)}")
    if installed_prefix(ws, package) is not None:
        return CheckResult(
            FAIL, f"{package} is built, but the Console has not sourced it since: "
            "source install/setup.bash"
        )  # fmt: skip
    return CheckResult(FAIL, f"{package} is neither built nor sourced")

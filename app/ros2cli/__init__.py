"""ros2-like verbs (node, topic, service, action, param, lifecycle, interface).

One implementation behind three faces: ``ros2-classroom <verb> ...`` on the
command line, the Console panel in the browser, and the other panels, which
call the same functions. ros2cli itself is not installable from PyPI.
"""

from app.ros2cli.common import (
    CLI_LIMITS,
    CONSOLE_LIMITS,
    Cancelled,
    Limits,
    Ros2Error,
    VerbContext,
)
from app.ros2cli.parser import GROUPS, run_argv, run_text, split_command

__all__ = [
    "CLI_LIMITS",
    "CONSOLE_LIMITS",
    "GROUPS",
    "Cancelled",
    "Limits",
    "Ros2Error",
    "VerbContext",
    "run_argv",
    "run_text",
    "split_command",
]

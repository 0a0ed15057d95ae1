"""ros2-like verbs (node, topic, service, action, param, lifecycle, interface).

One implementation behind two faces: ``ros2-classroom <verb> ...`` on the
command line and the Console tab in the browser (``console_panel``). The ROS
work itself is done by app.ros, which the other front ends share.
ros2cli itself is not installable from PyPI.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:  # their types, for the type checker; imported on first use below
    from app.ros2cli.parser import GROUPS, UsageError, run_argv, run_text, split_command

__all__ = ["GROUPS", "UsageError", "run_argv", "run_text", "split_command"]


def __getattr__(name: str) -> object:
    """The parser's names, imported on first use: ``app.ros2cli.groups`` stays cheap."""
    if name in __all__:
        from app.ros2cli import parser

        return getattr(parser, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

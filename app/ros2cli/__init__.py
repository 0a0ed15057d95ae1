"""ros2-like verbs (node, topic, service, action, param, lifecycle, interface).

One implementation behind two faces: ``ros2-classroom <verb> ...`` on the
command line and the Console tab in the browser (``console_panel``). The ROS
work itself is done by app.ros, which the other front ends share.
ros2cli itself is not installable from PyPI.
"""

from app.ros2cli.parser import GROUPS, UsageError, run_argv, run_text, split_command

__all__ = ["GROUPS", "UsageError", "run_argv", "run_text", "split_command"]

"""The ros2 command groups we answer: the one list the Console's parser and the command
line (``ros2-classroom topic ...``, ``ros2 topic ...``) both read.

Its own module, with no imports, so the command line learns the names without paying
for the parser (rclpy and every verb) before it knows a verb was asked for.
"""

from __future__ import annotations

GROUPS = ("node", "topic", "service", "action", "param", "lifecycle", "interface", "bag", "pkg")

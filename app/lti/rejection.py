"""The one error a refused LTI login or launch raises.

Its message is a whole sentence meant for the page the learner sees and the
log line the administrator reads; nothing is created when it is raised.
"""

from __future__ import annotations


class LaunchRejected(Exception):
    """A login or launch the tool refuses; ``str(error)`` says what was wrong."""

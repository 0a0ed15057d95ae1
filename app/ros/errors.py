"""The two exceptions every ROS-layer call may raise, and every front end catches
(``NoAnswer`` is a ``Ros2Error``)."""

from __future__ import annotations


class Ros2Error(Exception):
    """A problem the learner can fix; shown as one line, never a traceback."""


class NoAnswer(Ros2Error):
    """A request (or goal) went out and its answer did not come back in time."""


class Cancelled(Exception):
    """The learner pressed Stop (or Ctrl+C) while a call was running."""

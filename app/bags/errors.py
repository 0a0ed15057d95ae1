"""What every bag call raises for a problem the learner can fix."""

from __future__ import annotations

from app.ros.errors import Ros2Error


class BagError(Ros2Error):
    """A bag that cannot be read, written or played; shown as one line."""

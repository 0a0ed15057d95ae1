"""The "Using URDF with robot_state_publisher (Python)" tutorial's package.

``urdf/r2d2.urdf.xml`` (our own shapes) and the ``state_publisher`` node.
"""

from __future__ import annotations

from pathlib import Path


def share_directory() -> Path:
    """Where ``urdf/`` lives (``get_package_share_directory('urdf_tutorial_r2d2')``)."""
    return Path(__file__).resolve().parent

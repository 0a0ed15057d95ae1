"""The URDF tutorials' models (``urdf/``): an R2-D2-like robot built up step by step.

Our own shapes and numbers, in the order of the Jazzy "Building a visual robot
model with URDF from scratch" tutorial: one shape, several, origins,
materials, the full visual model, movable joints, and a xacro version.
``share_directory()`` stands in for ``get_package_share_directory('urdf_tutorial')``.
"""

from __future__ import annotations

from pathlib import Path


def share_directory() -> Path:
    """Where ``urdf/`` lives, as an installed package's share directory would hold it."""
    return Path(__file__).resolve().parent

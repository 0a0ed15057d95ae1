"""nav2_util for Python: what Nav2's servers share (a lifecycle node, occupancy values).

Upstream's nav2_util is a C++ library; its names here are the ones the
Python versions of Nav2's servers (``nav2_map_server``) need.
"""

from nav2_util.lifecycle_node import LifecycleNode
from nav2_util.occ_grid_values import OCC_GRID_FREE, OCC_GRID_OCCUPIED, OCC_GRID_UNKNOWN

__all__ = ["OCC_GRID_FREE", "OCC_GRID_OCCUPIED", "OCC_GRID_UNKNOWN", "LifecycleNode"]

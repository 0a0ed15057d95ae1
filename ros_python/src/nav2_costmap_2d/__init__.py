"""nav2_costmap_2d: a 2D costmap (static, obstacle and inflation layers) as Nav2 computes one.

Pure numpy in :mod:`nav2_costmap_2d.costmap_2d` and :mod:`nav2_costmap_2d.obstacle_layer`;
the ROS wrapper (``Costmap2DROS``: the ``global_costmap`` / ``local_costmap``
node that publishes ``<name>/costmap`` and answers ``clear_entirely_<name>``
and ``get_costmap``) in :mod:`nav2_costmap_2d.costmap_2d_ros`.
"""

from nav2_costmap_2d.cost_values import (
    FREE_SPACE,
    INSCRIBED_INFLATED_OBSTACLE,
    LETHAL_OBSTACLE,
    MAX_NON_OBSTACLE,
    NO_INFORMATION,
)

__all__ = [
    "FREE_SPACE",
    "INSCRIBED_INFLATED_OBSTACLE",
    "LETHAL_OBSTACLE",
    "MAX_NON_OBSTACLE",
    "NO_INFORMATION",
]

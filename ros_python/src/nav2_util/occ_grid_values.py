"""The values of a nav_msgs/OccupancyGrid cell, as Nav2 names them."""

OCC_GRID_UNKNOWN = -1
OCC_GRID_FREE = 0
OCC_GRID_OCCUPIED = 100

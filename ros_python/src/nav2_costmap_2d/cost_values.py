"""The cost of a costmap cell, as Nav2 names the values (``nav2_costmap_2d/cost_values.hpp``)."""

FREE_SPACE = 0
MAX_NON_OBSTACLE = 252
INSCRIBED_INFLATED_OBSTACLE = 253  # the robot's centre here puts its body in an obstacle
LETHAL_OBSTACLE = 254  # an obstacle itself
NO_INFORMATION = 255  # unknown space

"""nav2_amcl for Python: Nav2 Jazzy's Adaptive Monte Carlo Localization, the ``amcl`` node.

The same node name, parameters (names and defaults), topics, services and
log lines as Nav2's amcl, so a learner's params file and rviz setup work on
both. Written from Nav2's documentation and the textbook it follows (Thrun,
Burgard and Fox, *Probabilistic Robotics*: the odometry motion model, the
likelihood field sensor model, KLD-sampling and augmented MCL), in Python
with numpy: every particle is a row of one array, each model one vectorised
step.

- ``nav2_amcl.map``: the map as amcl sees it (free, occupied, unknown) and the
  distance to the nearest obstacle from each cell;
- ``nav2_amcl.motion_model``: the differential and omnidirectional odometry
  models (``alpha1`` .. ``alpha5``);
- ``nav2_amcl.sensor_model``: the likelihood field laser model;
- ``nav2_amcl.particle_filter``: the filter (initialisation, resampling,
  the adaptive particle count, recovery, the pose estimate);
- ``nav2_amcl.cloud``: /particle_cloud written from the filter's arrays as CDR bytes;
- ``nav2_amcl.amcl_node``: the lifecycle node ``amcl``.
"""

from nav2_amcl.map import AmclMap
from nav2_amcl.motion_model import DifferentialMotionModel, OmniMotionModel
from nav2_amcl.particle_filter import FilterParameters, ParticleFilter, PoseEstimate
from nav2_amcl.sensor_model import LikelihoodFieldModel, ScanBeams

__all__ = [
    "AmclMap",
    "DifferentialMotionModel",
    "FilterParameters",
    "LikelihoodFieldModel",
    "OmniMotionModel",
    "ParticleFilter",
    "PoseEstimate",
    "ScanBeams",
]

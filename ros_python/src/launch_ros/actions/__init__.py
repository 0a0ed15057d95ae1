"""ROS actions (upstream's ``launch_ros.actions``)."""

from .node import Node
from .scoped import PushRosNamespace, SetParameter, SetRemap, SetUseSimTime

__all__ = ["Node", "PushRosNamespace", "SetParameter", "SetRemap", "SetUseSimTime"]

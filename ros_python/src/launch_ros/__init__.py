"""ROS 2 Classroom's ``launch_ros``: ROS-specific launch actions as the Jazzy tutorials use them.

Same module layout and names as upstream's ``launch_ros`` (not on PyPI),
written here from its documented behaviour. Executables and share
folders are found through the ament index (``ament_index_python``).
"""

from . import actions, parameter_descriptions, substitutions

__all__ = ["actions", "parameter_descriptions", "substitutions"]

"""The learner's own ROS 2 workspace: its folder, colcon builds in it, and `source`.

One workspace per learner, beside their progress (``<progress dir>/<learner>.ros2_ws``
with ``src/``), as ``~/ros2_ws`` is in the tutorials. Front ends (the Console's
``ros2 pkg create``, ``colcon build``, ``source install/setup.bash``,
``ros2 run``) use it; it imports no front end.
"""

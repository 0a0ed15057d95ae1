"""nav2_simple_commander for Python: Nav2 Jazzy's "Simple Commander" API, pip-only.

``from nav2_simple_commander.robot_navigator import BasicNavigator, TaskResult``
works as with the real Nav2: the same class, method names, arguments, return
values and log lines, speaking to the navigation servers over the same
action and service names with the same ``nav2_msgs`` interfaces. So a
learner's script written for Nav2 runs unchanged against ROS 2 Classroom's
Python Nav2, and later against the real one on a robot. Written here from
Nav2's documentation and behaviour, never copied.
"""

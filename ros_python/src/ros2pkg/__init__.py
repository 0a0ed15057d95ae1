"""ros2pkg: `ros2 pkg create/list/executables/prefix`, a Python version of upstream's verbs.

Run it as ``python -m ros2pkg create --build-type ament_python my_package``.
"""

"""ROS 2 Classroom's ``ros2 launch`` (upstream's ros2launch package), runnable as
``python -m ros2launch PACKAGE FILE [name:=value ...]``."""

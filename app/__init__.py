"""ROS 2 Classroom: a browser-based teaching dashboard for ROS 2 Jazzy."""

from pathlib import Path

PROJECT_ROOT = Path(__file__).resolve().parent.parent

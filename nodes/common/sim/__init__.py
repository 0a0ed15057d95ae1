"""The physics behind nodes/sim_world.py: MuJoCo model loading, the differential drive,
odometry, lidar, camera, arm trajectories. Plain Python and numpy, no ROS: testable alone.

Importing the package picks MuJoCo's headless OpenGL (EGL when it makes a
context, else OSMesa) unless MUJOCO_GL is set: ``mujoco`` reads it once, when
first imported. It also sends MuJoCo's warnings to Python's logging: MuJoCo's
own handler would print them and append them to ``MUJOCO_LOG.TXT`` in the
current folder (the project's, under the dashboard).
"""

import logging
from collections.abc import Callable

from nodes.common.sim.camera import choose_gl_backend

GL_BACKEND = choose_gl_backend()

import mujoco  # noqa: E402  (after MUJOCO_GL is set)

log = logging.getLogger("mujoco")


def log_warning(text: str) -> None:
    """MuJoCo's warnings as log lines, never as a MUJOCO_LOG.TXT file."""
    log.warning("MuJoCo: %s", " ".join(text.split()))


def send_warnings_to(handler: Callable[[str], None]) -> None:
    """Hand MuJoCo's warnings to ``handler`` (a node's logger) from now on."""
    mujoco.set_mju_user_warning(handler)


send_warnings_to(log_warning)

"""The physics behind nodes/sim_world.py: MuJoCo model loading, the differential drive,
odometry, lidar, camera, arm trajectories. Plain Python and numpy, no ROS: testable alone.

Importing the package picks MuJoCo's headless OpenGL (EGL, else OSMesa) unless
MUJOCO_GL is set: ``mujoco`` reads it once, when first imported.
"""

from nodes.common.sim.camera import choose_gl_backend

GL_BACKEND = choose_gl_backend()

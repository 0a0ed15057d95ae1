"""state_publisher of urdf_tutorial_r2d2: ``ros2 run urdf_tutorial_r2d2 state_publisher``.

The tutorial's node (``ros_python/src/urdf_tutorial_r2d2/state_publisher.py``)
as a catalog node: R2-D2's joints on /joint_states and odom -> axis on /tf.
"""

from urdf_tutorial_r2d2.state_publisher import main

from nodes.common.run import run_program

if __name__ == "__main__":
    run_program(main)  # Ctrl+C and SIGTERM end it the same quiet way

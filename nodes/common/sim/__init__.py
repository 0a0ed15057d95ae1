"""The physics behind nodes/sim_world.py: MuJoCo model loading, the differential drive,
odometry, lidar, camera, arm trajectories. Plain Python and numpy, no ROS: testable alone."""

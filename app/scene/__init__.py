"""The 3D scene: what live ROS topics look like in viser (rviz's job, in the browser).

One concept per module. Pure math and decoding (``cloud_codec``, ``transforms``,
``marker_plan``, ``image_codec``) never import rclpy or viser, so unit tests run
without a ROS graph. Layers (``pointclouds``, ``markers``, ``frames``, ``arm``,
``images``, ``plots``) own their viser handles and draw from a worker thread,
never from the ROS executor thread.
"""

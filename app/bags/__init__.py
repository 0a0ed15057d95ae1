"""Bags: record, inspect and replay topics in real rosbag2 files (`ros2 bag`).

rosbag2 is not on PyPI; the `rosbags` library reads and writes its files
(Jazzy's metadata version 9, MCAP by default, sqlite3 on request), so the
bags we make open in `ros2 bag info` / `ros2 bag play` on a ROS 2 install.
This package sits on the ROS layer (``app.ros``) and under the front ends
(the ``ros2 bag`` verbs, the panels): it imports none of them.

- ``folder``      where bags live and how names resolve
- ``errors``      the one exception every bag call raises
- ``definitions`` message definitions and type hashes the file format wants
- ``qos``         offered QoS -> bag metadata, and back to a replay profile
- ``bagfile``     opening a bag for reading, with one clear line for bad files
- ``info``        what `ros2 bag info` prints
- ``recorder``    raw subscriptions -> a writer thread -> the bag
- ``player``      the bag -> publishers, on the bag's clock
- ``repair``      making a killed or cut-off recording readable (`ros2 bag reindex`)
"""

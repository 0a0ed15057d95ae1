"""`ros2 run nav2_map_server map_server`: Nav2's map server (ros_python/src/nav2_map_server).

A lifecycle node: set ``yaml_filename``, then configure and activate it
(``ros2 lifecycle set /map_server configure``, ``... activate``, or the
dashboard's lifecycle tool) and the map is on ``/map``.
"""

from nav2_map_server.map_server import main

from nodes.common.run import run_program

if __name__ == "__main__":
    run_program(main)  # Ctrl+C and SIGTERM end it the same quiet way

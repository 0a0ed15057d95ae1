"""`ros2 run nav2_map_server map_saver_cli -f PATH`: saves /map as PATH.pgm + PATH.yaml.

Nav2's map_saver_cli (ros_python/src/nav2_map_server/map_saver.py): it waits
for one map, writes the two files as Nav2 writes them, and exits.
"""

from nav2_map_server.map_saver import main

from nodes.common.run import run_program

if __name__ == "__main__":
    run_program(main)  # Ctrl+C and SIGTERM end it the same quiet way

"""tf2_ros's command-line programs (C++ executables upstream), in Python."""

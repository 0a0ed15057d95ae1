"""tf2_tools: view_frames, as upstream's Python package names it."""

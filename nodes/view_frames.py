"""`ros2 run tf2_tools view_frames`: tf2_tools' program (ros_python/src/tf2_tools/view_frames.py).

Started by the dashboard, a program's working directory is the project; the
files then go to a folder of their own (printed), not among the sources.
"""

import os
import sys
import tempfile
from pathlib import Path

from tf2_tools.view_frames import main

PROJECT_ROOT = Path(__file__).resolve().parent.parent


def output_dir() -> Path:
    """Where frames_<date>.gv goes: the working directory, unless that is the project."""
    if Path.cwd().resolve() != PROJECT_ROOT:
        return Path.cwd()
    folder = Path(tempfile.gettempdir()) / "ros2_classroom_view_frames"
    folder.mkdir(parents=True, exist_ok=True)
    return folder


if __name__ == "__main__":
    folder = output_dir()
    if folder != Path.cwd():
        print(f"view_frames: writing into {folder}", flush=True)
        os.chdir(folder)
    sys.exit(main())

"""`ros2 run tf2_tools view_frames`: tf2_tools' program (ros_python/src/tf2_tools/view_frames.py).

Started by the dashboard, a program's working directory is the project; the
files then go to a folder of their own (printed), not among the sources.
At the end it prints where its picture is (an SVG; with graphviz installed,
upstream's PDF and an SVG beside it), so the TF panel can show the tree.
"""

import os
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

from tf2_tools.view_frames import main

from nodes.common.run import run_program

PROJECT_ROOT = Path(__file__).resolve().parent.parent


def output_dir() -> Path:
    """Where frames_<date>.gv goes: the working directory, unless that is the project."""
    if Path.cwd().resolve() != PROJECT_ROOT:
        return Path.cwd()
    folder = Path(tempfile.gettempdir()) / "ros2_classroom_view_frames"
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def newest_picture(folder: Path, since: float) -> Path | None:
    """The SVG of the run that started at ``since`` (made from its .gv when dot drew a PDF)."""
    sources = [p for p in folder.glob("frames_*.gv") if p.stat().st_mtime >= since - 1.0]
    if not sources:
        return None
    gv = max(sources, key=lambda p: p.stat().st_mtime)
    svg = gv.with_suffix(".svg")
    dot = shutil.which("dot")
    if not svg.exists() and dot:
        subprocess.run([dot, "-Tsvg", str(gv), "-o", str(svg)], check=False, timeout=30)
    return svg if svg.exists() else None


if __name__ == "__main__":
    folder = output_dir()
    if folder != Path.cwd():
        print(f"view_frames: writing into {folder}", flush=True)
        os.chdir(folder)
    started = time.time()

    def listen_and_draw() -> int:
        code = main()
        picture = newest_picture(Path.cwd(), started) if code == 0 else None
        if picture is not None:
            print(f"view_frames: the picture is {picture.resolve()}", flush=True)
        return code

    run_program(listen_and_draw)  # Ctrl+C and SIGTERM end it the same quiet way

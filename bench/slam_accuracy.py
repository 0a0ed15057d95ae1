"""Benchmark: monocular SLAM accuracy and speed on the synthetic loop.

Renders the built-in sequence (a textured room, 640x480, known camera loop),
runs the same odometry the ``slam_node`` runs, and reports:

- absolute trajectory error (ATE): RMSE of the estimated camera positions
  after the best similarity alignment (Umeyama: rotation, translation and
  scale, since one camera cannot know scale), as a percentage of the length
  of the true path;
- frames per second of the SLAM pipeline alone (rendering is timed apart).

No ROS is involved. Usage: ``python -m bench.slam_accuracy [--frames N]``.
The last line printed is one JSON object.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from nodes.common.slam import MonocularVO, absolute_trajectory_error
from nodes.common.synthetic_world import SyntheticSequence


def run(frames: int, width: int, height: int, loops: float) -> dict[str, float]:
    sequence = SyntheticSequence(length=int(frames / loops), width=width, height=height)
    vo = MonocularVO(sequence.intrinsics.matrix())
    render_time = slam_time = 0.0
    states: dict[str, int] = {}
    for index in range(frames):
        start = time.perf_counter()
        image = sequence.frame(index)
        render_time += time.perf_counter() - start
        start = time.perf_counter()
        result = vo.process(image)
        slam_time += time.perf_counter() - start
        states[result.state] = states.get(result.state, 0) + 1
    indices = sorted(i for i in vo.poses if i < frames)
    estimated = np.array([vo.poses[i][:3, 3] for i in indices])
    truth = np.array([sequence.pose(i)[:3, 3] for i in indices])
    report = absolute_trajectory_error(estimated, truth)
    return {
        "ate_percent": round(report["ate_percent"], 3),
        "fps": round(frames / slam_time, 1),
        "ate_rmse_m": round(report["ate_rmse"], 4),
        "ate_max_m": round(report["ate_max"], 4),
        "path_length_m": round(report["path_length"], 3),
        "frames": frames,
        "frames_with_pose": len(indices),
        "lost_frames": states.get("lost", 0),
        "map_points": len(vo.points),
        "render_fps": round(frames / render_time, 1),
        "resolution": f"{width}x{height}",
    }


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=300)
    parser.add_argument("--loops", type=float, default=1.0, help="laps of the loop to cover")
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=480)
    args = parser.parse_args(argv)
    result = run(args.frames, args.width, args.height, args.loops)
    print(
        f"SLAM on the synthetic loop ({result['resolution']}, {result['frames']} frames, "
        f"path {result['path_length_m']} m)"
    )
    print(f"  frames located      {result['frames_with_pose']} (lost {result['lost_frames']})")
    print(f"  map points          {result['map_points']}")
    print(
        f"  ATE after Sim3      {result['ate_rmse_m']} m RMSE = {result['ate_percent']} % of path"
    )
    print(f"  SLAM speed          {result['fps']} frames/s (rendering: {result['render_fps']})")
    print(json.dumps(result))


if __name__ == "__main__":
    main()

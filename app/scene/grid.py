"""The floor grid of the 3D view, drawn as thin lines (as rviz's Grid display is).

viser's own grid is a plane whose fragment shader works out, for every
pixel it covers, how near the pixel is to a grid line (with fog and a shadow
mask). Where WebGL runs in software (no GPU: headless browsers, many
classroom VMs and hub servers) that per-pixel work over most of the canvas
was the 3D view's largest cost: with the robot moving it took the frame rate
from that of a bare scene to about 0.6x of it (bench/urdf_draw.py,
README). Lines cost only the pixels they light.

Even so, in software WebGL every long line costs the browser about half a
millisecond a frame, whatever its thickness or how the lines are grouped
into draw calls (measured: 34 lines 58-62 ms a frame, 18 lines 48-53, 10
lines 50, none 40-46). So the cells are half a metre, not a quarter: rviz's
grid has metre cells, and the desk arm's half-metre reach still reads
against them.
"""

from __future__ import annotations

import numpy as np
import viser

GRID_PATH = "/grid"
CELL_COLOR = (205, 205, 205)
SECTION_COLOR = (150, 150, 150)  # every metre, darker, as on viser's grid


def grid_lines(size: float, cell: float) -> tuple[np.ndarray, np.ndarray]:
    """(cell segments, section segments) of a square grid of side ``size`` centred on
    the origin in the xy plane, each an (N, 2, 3) array; sections fall on whole metres."""
    half = size / 2
    Segment = list[tuple[float, float, float]]
    cells: list[Segment] = []
    sections: list[Segment] = []
    for i in range(int(round(size / cell)) + 1):
        v = -half + i * cell
        pair = [[(v, -half, 0.0), (v, half, 0.0)], [(-half, v, 0.0), (half, v, 0.0)]]
        (sections if abs(v - round(v)) < 1e-9 else cells).extend(pair)
    as_array = lambda segments: np.asarray(segments, dtype=np.float32).reshape(-1, 2, 3)  # noqa: E731
    return as_array(cells), as_array(sections)


def add_floor_grid(scene: viser.SceneApi, size: float = 4.0, cell: float = 0.5) -> None:
    """A ``size`` x ``size`` metre grid with ``cell`` metre cells on the z = 0 plane."""
    cells, sections = grid_lines(size, cell)
    scene.add_frame(GRID_PATH, show_axes=False)
    for name, segments, color, px in (
        ("cells", cells, CELL_COLOR, 1.0),
        ("sections", sections, SECTION_COLOR, 1.5),
    ):
        if len(segments):
            scene.add_line_segments(
                f"{GRID_PATH}/{name}",
                segments,
                np.broadcast_to(np.asarray(color, dtype=np.uint8), (*segments.shape[:2], 3)),
                thickness=px,
                thickness_units="screen",
            )

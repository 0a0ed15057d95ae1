"""Keep the browser's point-cloud shader compiled while clouds change colour.

viser 1.1.1's page makes a new material for a point cloud whenever the
cloud's colours change (its ``PointCloud`` memoises the material on the
colour array), and disposes of the old one. three.js shares one compiled
shader program among all materials of the same kind and deletes it when the
last one goes, so a cloud that gets new colours on every message (the laser
scan, coloured by range) had its shader compiled and linked again on every
frame. Where WebGL runs in software that was about 30 ms of each 110 ms
frame with ``sim_drive`` running (measured: 9.2 frames a second, one link a
frame; without the recompiles 12.6, no link).

A second cloud with per-point colours that never changes holds the program,
so every new material finds it already made. It is two points at the
origin, each a pixel wide and the colour of the grid's metre lines that
cross there: nothing a learner can see.
"""

from __future__ import annotations

import numpy as np
import viser

from app.scene.grid import GRID_PATH, SECTION_COLOR

KEEPER_PATH = f"{GRID_PATH}/point_shader"


def keep_point_shader(scene: viser.SceneApi) -> None:
    """Add the cloud that keeps the point shader of per-point coloured clouds alive."""
    scene.add_point_cloud(
        KEEPER_PATH,
        points=np.zeros((2, 3), dtype=np.float32),
        # Two points, so the colours are per point (one would be a single colour: another
        # shader). Both the grid's metre-line grey.
        colors=np.tile(np.asarray(SECTION_COLOR, dtype=np.uint8), (2, 1)),
        point_size=1e-4,  # below a pixel: drawn one pixel wide
        point_shape="circle",  # as the clouds it keeps company (a uniform, not the shader)
    )

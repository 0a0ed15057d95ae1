"""The shipped office map is what the generator makes from the world file now, and it loads."""

from __future__ import annotations

import numpy as np
from nav2_map_server.map_io import load_map_from_yaml

from app.lessons.checks._world_map import load_world_map
from nodes.common.occupancy_grid import cell_centres, map_agreement, plan_distance
from nodes.common.office_map import FOLDER, write_office_map


def test_the_shipped_office_map_equals_what_the_generator_makes_now(tmp_path):
    made = write_office_map(tmp_path)
    for name in ("map.yaml", "map.pgm"):
        shipped = (FOLDER / name).read_bytes()
        fresh = (made.parent / name).read_bytes()
        assert shipped == fresh, (
            f"nodes/worlds/office/{name} is stale: run python -m nodes.common.office_map"
        )


def test_the_office_map_loads_as_nav2_would_and_agrees_with_the_floor_plan():
    loaded = load_map_from_yaml(str(FOLDER / "map.yaml"))
    assert loaded.ok, loaded.reason
    grid = loaded.map
    assert grid is not None and grid.header.frame_id == "map"
    info = grid.info
    assert info.resolution == 0.05 and (info.width, info.height) == (220, 180)
    data = np.array(grid.data, np.int8)
    assert set(np.unique(data).tolist()) == {-1, 0, 100}
    origin = (info.origin.position.x, info.origin.position.y)
    xs, ys = cell_centres(origin, info.resolution, info.width, info.height)
    distance = plan_distance(load_world_map("office").obstacles, xs, ys)
    result = map_agreement(data, distance, info.resolution)
    assert result.percent == 100.0, result.text()
    # The robot's start (the corridor's middle) is free; the corridor's walls are occupied.
    cells = data.reshape(info.height, info.width)

    def at(x: float, y: float) -> int:
        return int(cells[int((y - origin[1]) / 0.05), int((x - origin[0]) / 0.05)])

    assert at(0.0, 0.0) == 0 and at(0.0, 0.8) == 100 and at(0.0, -0.8) == 100
    assert at(-5.4, 0.0) == -1  # outside the building: unknown

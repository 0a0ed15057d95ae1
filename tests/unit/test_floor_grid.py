"""The 3D view's floor grid: lines every cell, darker ones on whole metres."""

import inspect

import numpy as np

from app.scene.grid import add_floor_grid, grid_lines


def test_a_4m_grid_of_quarter_metre_cells_has_17_lines_each_way() -> None:
    cells, sections = grid_lines(4.0, 0.25)
    assert cells.shape == (2 * 12, 2, 3)  # 17 positions, of which 5 are whole metres
    assert sections.shape == (2 * 5, 2, 3)
    xs = sorted({round(float(x), 6) for x in sections[::2, 0, 0]})
    assert xs == [-2.0, -1.0, 0.0, 1.0, 2.0]


def test_every_line_spans_the_grid_on_the_floor() -> None:
    cells, sections = grid_lines(4.0, 0.25)
    lines = np.concatenate([cells, sections])
    assert np.all(lines[:, :, 2] == 0.0)
    lengths = np.linalg.norm(lines[:, 1] - lines[:, 0], axis=1)
    assert np.allclose(lengths, 4.0)
    assert np.abs(lines).max() == 2.0


def test_the_dashboard_grid_has_half_metre_cells_and_18_lines() -> None:
    """Each line costs a software-WebGL browser every frame (app/scene/grid.py); the
    dashboard draws add_floor_grid's defaults."""
    defaults = inspect.signature(add_floor_grid).parameters
    cells, sections = grid_lines(defaults["size"].default, defaults["cell"].default)
    assert len(cells) + len(sections) == 18
    assert sorted({round(float(x), 6) for x in cells[::2, 0, 0]}) == [-1.5, -0.5, 0.5, 1.5]

"""The object's cross-section at a height, from the height map, against exact boxes."""

import numpy as np
import pytest

from contourgrasp.errors import PerceptionError
from contourgrasp.perception import HeightMap, cross_section

CELL = 0.002


def heights_of(grid, obj):
    shape = grid.shape
    return HeightMap(grid, CELL, np.zeros(2), obj, np.zeros(shape, bool), float(np.nanmax(grid)), np.ones(shape, bool),
                     np.array([0.0, 0.0, -1.0]), 0.7, np.zeros(2), 0.7)


def stepped():
    """A 6 x 4 cm base 2 cm tall with a 2 x 2 cm tower 8 cm tall on it, at cells [10:30, 10:40]."""
    grid = np.zeros((60, 60))
    grid[10:30, 10:40] = 0.02
    grid[15:25, 25:35] = 0.08
    return heights_of(grid, grid > 0.01)


def test_below_the_base_the_section_is_the_whole_object():
    outline = cross_section(stepped(), 0.01)
    lo, hi = outline.min(axis=0), outline.max(axis=0)
    np.testing.assert_allclose(lo, [10.5 * CELL, 10.5 * CELL])
    np.testing.assert_allclose(hi, [39.5 * CELL, 29.5 * CELL])


def test_above_the_base_only_the_tower_and_above_everything_none():
    outline = cross_section(stepped(), 0.05)
    np.testing.assert_allclose(outline.min(axis=0), [25.5 * CELL, 15.5 * CELL])
    np.testing.assert_allclose(outline.max(axis=0), [34.5 * CELL, 24.5 * CELL])
    assert cross_section(stepped(), 0.09) is None


def test_unseen_cells_and_other_objects_do_not_count():
    heights = stepped()
    grid = heights.heights.copy()
    grid[10:30, 10:20] = np.nan  # the base's left third unseen
    obj = heights.object.copy()
    grid[40:50, 40:50] = 0.08  # an obstacle, not the object
    outline = cross_section(heights_of(grid, obj), 0.01)
    np.testing.assert_allclose(outline.min(axis=0), [20.5 * CELL, 10.5 * CELL])
    assert outline.max(axis=0)[1] < 30 * CELL


def test_bad_arguments():
    with pytest.raises(PerceptionError, match="HeightMap"):
        cross_section(np.zeros((3, 3)), 0.01)
    for bad in (np.nan, -0.01, 1e9, "1"):
        with pytest.raises(PerceptionError, match="height"):
            cross_section(stepped(), bad)

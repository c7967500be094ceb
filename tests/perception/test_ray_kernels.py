import math

import numpy as np

from contourgrasp.perception._ray_kernels import ray_bounds, shadow_bounds


def walk_every_step_away(heights, start, unit, r, steps, origin, cell, camera_height, diagonal):
    """The free-space bound by its definition: the lowest line of sight to every seen cell beyond, to the map's edge."""
    ny, nx = heights.shape
    out = np.full(len(start), np.inf)
    for i in range(len(start)):
        for s in steps:
            col = math.floor((start[i, 0] + s * unit[i, 0] - origin[0]) / cell)
            row = math.floor((start[i, 1] + s * unit[i, 1] - origin[1]) / cell)
            if not (0 <= col < nx and 0 <= row < ny):
                break
            if np.isfinite(heights[row, col]):
                h = heights[row, col]
                far = r[i] + s + 0.5 * diagonal
                out[i] = min(out[i], h + (camera_height - h) * (s + diagonal) / far)
    return out


def test_the_walks_away_from_the_camera_stopped_early_give_the_bounds_of_every_step():
    rng = np.random.default_rng(1)
    cell, camera_height = 0.002, 0.65
    heights = np.where(rng.random((60, 80)) < 0.4, np.nan, rng.uniform(-0.002, 0.2, (60, 80)))
    heights[:, 50:] = np.nan  # a wide hole: some walks leave the map without a seen cell
    origin = np.array([-0.08, -0.06])
    start = origin + rng.uniform(0.0, 1.0, (400, 2)) * [0.16, 0.12]
    away = start - np.array([0.3, -0.2])  # the camera's foot, outside the map
    r = np.hypot(*away.T)
    unit = away / r[:, None]
    diagonal = math.sqrt(2.0) * cell
    steps = np.arange(1, int(math.ceil(2 * math.hypot(60, 80))) + 1) * (0.5 * cell)
    got = ray_bounds(heights, start, unit, r, steps, origin, cell, camera_height, diagonal,
                     float(np.nanmin(heights)))
    want = walk_every_step_away(heights, start, unit, r, steps, origin, cell, camera_height, diagonal)
    np.testing.assert_array_equal(got, want)
    assert np.isposinf(got).any() and (got < 0.05).mean() > 0.3  # some walks see nothing; many pass just over a cell


def walk_every_step_toward(heights, start, unit, r, reach, steps, origin, cell, camera_height, diagonal):
    """The bound by its definition: the highest line of sight over every step of every walk, no early stop."""
    ny, nx = heights.shape
    out = np.full(len(start), -np.inf)
    for i in range(len(start)):
        for step in steps:
            s = min(step, reach[i])
            if s >= r[i]:
                continue
            col = math.floor((start[i, 0] + s * unit[i, 0] - origin[0]) / cell)
            row = math.floor((start[i, 1] + s * unit[i, 1] - origin[1]) / cell)
            if 0 <= col < nx and 0 <= row < ny and np.isfinite(heights[row, col]):
                h = heights[row, col]
                out[i] = max(out[i], h - (camera_height - h) * max(s - diagonal, 0.0) / (r[i] - s + 0.5 * diagonal))
    return out


def test_the_walks_toward_the_camera_stopped_early_give_the_bounds_of_every_step():
    rng = np.random.default_rng(0)
    cell, camera_height = 0.002, 0.65
    heights = np.where(rng.random((60, 80)) < 0.3, np.nan, rng.uniform(0.0, 0.2, (60, 80)))
    heights[20:30, 30:40] = 0.21  # a tall block among the noise
    origin = np.array([-0.08, -0.06])
    start = origin + rng.uniform(0.0, 1.0, (400, 2)) * [0.16, 0.12]
    foot = np.array([0.3, -0.2])  # the camera's foot, outside the map
    toward = foot - start
    r = np.hypot(*toward.T)
    unit = toward / r[:, None]
    top = float(np.nanmax(heights))
    diagonal = math.sqrt(2.0) * cell
    reach = np.minimum(r, top * r / camera_height + 2 * diagonal)
    steps = np.arange(1, int(math.ceil(2 * reach.max() / cell)) + 1) * (0.5 * cell)
    got = shadow_bounds(heights, start, unit, r, reach, steps, origin, cell, camera_height, diagonal, top,
                        np.full(len(start), np.inf))
    want = walk_every_step_toward(heights, start, unit, r, reach, steps, origin, cell, camera_height, diagonal)
    np.testing.assert_array_equal(got, want)
    assert np.isfinite(got).mean() > 0.5 and (got > 0.1).any()  # the walks do cross seen cells, the block among them
    # Capped (by the bound away from the camera, which the cell takes when smaller): the smaller of the two is exact.
    cap = rng.uniform(0.0, 0.2, len(start))
    capped = shadow_bounds(heights, start, unit, r, reach, steps, origin, cell, camera_height, diagonal, top, cap)
    np.testing.assert_array_equal(np.minimum(capped, cap), np.minimum(want, cap))
    assert (capped < want).any()  # some walks did stop at their cap

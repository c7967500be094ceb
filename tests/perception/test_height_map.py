"""The height map against analytic truth: ray-cast boxes and cylinders, top-down and tilted."""

from __future__ import annotations

import math

import numpy as np
import pytest

from contourgrasp.errors import PerceptionError
from contourgrasp.perception import HeightMap, Plane, contour_to_metric, height_map, segment_depth
from contourgrasp.perception.table import table_points
from contourgrasp.tolerances import HEIGHT_MAP_CELL, MAX_HEIGHT_MAP_CELLS
from perception_scenes import CAMERA, render

CELL = HEIGHT_MAP_CELL


def scene(*, kind="box", tilt_deg=0.0, radius=0.03, height=0.05, centre=(0.02, -0.03), margin=0.12):
    """Depth, the exact table plane, the metric contour and the height map of one ray-cast object."""
    depth, _, _, normal = render(kind=kind, tilt_deg=tilt_deg, radius=radius, height=height, centre=centre)
    seg = segment_depth(depth, CAMERA)
    metric = contour_to_metric(seg.contour_px, depth, CAMERA, plane=seg.plane, on_table=seg.on_table)
    table = Plane(normal=normal, offset=0.7)  # the renderer's table: 0.7 m from the camera along its normal
    return depth, table, seg, metric, height_map(depth, CAMERA, table, metric, seg.mask, margin=margin)


def cell_xy(hm: HeightMap):
    xs, ys = hm.centres()
    return np.meshgrid(xs, ys)


@pytest.mark.parametrize("tilt_deg", [0.0, 12.7])
def test_box_heights_in_the_table_frame(tilt_deg):
    # A 5 cm box: its top's cells hold 5 cm, the table's 0, whatever the camera's tilt (the heights are
    # along the table's normal, not the optical axis: at 12.7 deg the table's depth spans 15 cm over the map).
    side, height, centre = 0.03, 0.05, np.array([0.02, -0.03])
    _, _, _, metric, hm = scene(tilt_deg=tilt_deg, radius=side, height=height, centre=tuple(centre))
    assert metric.frame == ("table" if tilt_deg else "camera")
    x, y = cell_xy(hm)
    inside = (np.abs(x - centre[0]) < side - CELL) & (np.abs(y - centre[1]) < side - CELL)
    np.testing.assert_allclose(hm.heights[inside], height, atol=1e-3)
    assert hm.max_height == pytest.approx(height, abs=1e-3)
    far = np.maximum(np.abs(x - centre[0]), np.abs(y - centre[1])) > side + 0.03
    table = hm.heights[far & hm.seen]
    assert table.size > 0.8 * far.sum() and np.abs(table).max() < 1e-3
    # The box's footprint is the object; nothing else stands on the table.
    assert hm.object[inside].all() and not hm.object[far].any()
    assert not hm.obstacles.any() and hm.obstacle_max_height == 0.0
    # The grid is in the contour's frame: the object's cells are centred where the planner places the box.
    np.testing.assert_allclose([x[hm.object].mean(), y[hm.object].mean()], centre, atol=2e-3)


@pytest.mark.parametrize("tilt_deg", [0.0, 12.7])
def test_cylinder_of_height_h_and_radius_r(tilt_deg):
    radius, height, centre = 0.035, 0.12, np.array([-0.02, 0.01])
    _, _, _, _, hm = scene(kind="cylinder", tilt_deg=tilt_deg, radius=radius, height=height, centre=tuple(centre))
    x, y = cell_xy(hm)
    r = np.hypot(x - centre[0], y - centre[1])
    np.testing.assert_allclose(hm.heights[r < radius - 1.5 * CELL], height, atol=1e-3)
    assert hm.max_height == pytest.approx(height, abs=1e-3)
    assert hm.object[r < radius - CELL].all()
    outside = (r > radius + 1.5 * CELL) & hm.seen
    assert np.abs(hm.heights[outside]).max() < 1e-3  # what is seen beyond the wall is the table


def test_unseen_cells_are_nan_and_bounded_by_the_line_of_sight():
    # A 12 cm cylinder off the optical axis hides the table behind it (away from the camera's foot): those
    # cells are NaN, not 0. Their conservative bound lies between the truth (the table) and the occluder's height.
    radius, height, centre = 0.03, 0.12, np.array([0.0, -0.12])
    _, _, _, _, hm = scene(kind="cylinder", radius=radius, height=height, centre=tuple(centre), margin=0.08)
    x, y = cell_xy(hm)
    shadow = ~hm.seen & hm.in_view
    assert shadow.sum() > 100
    # Behind the cylinder (farther from the camera's foot at (0, 0)) and outside it.
    assert np.all(np.hypot(x[shadow], y[shadow]) > np.hypot(*centre) - radius)
    assert np.all(np.hypot(x[shadow] - centre[0], y[shadow] - centre[1]) > radius - CELL)
    bound = hm.conservative()
    assert np.isfinite(bound[hm.in_view]).all()
    # Above the rim by at most the slack of a seen point and a surface anywhere in their cells: H 2 diagonals / r.
    r = np.hypot(x[shadow], y[shadow])
    assert bound[shadow].min() >= 0.0 and bound[shadow].max() <= height + 0.7 * 2 * math.sqrt(2) * CELL / r.min()
    # The line of sight over the rim falls as the shadow leaves the wall: the farthest shadow cells are bounded
    # well below the wall's height (the shadow is h r / (H - h) long; its far end is at the table).
    assert bound[shadow][r > np.percentile(r, 90)].max() < 0.5 * height
    np.testing.assert_array_equal(bound[hm.seen], hm.heights[hm.seen])


def test_missing_readings_are_nan_and_outside_the_view_is_unbounded():
    depth, table, seg, metric, _ = scene(tilt_deg=0.0, margin=0.3)
    holed = depth.copy()
    holed[:, :60] = 0.0  # a wide strip without readings, at the image's left
    hm = height_map(holed, CAMERA, table, metric, seg.mask, margin=0.3)
    x, _ = cell_xy(hm)
    left = -(CAMERA.cx - 50) * 0.7 / CAMERA.fx  # x of the strip's inner part on the table
    assert np.isnan(hm.heights[(x < left) & hm.in_view]).all()
    # 0.3 m around a 6 cm box reaches beyond the 0.53 x 0.4 m the camera sees of the table.
    assert not hm.in_view.all()
    bound = hm.conservative()
    assert np.isposinf(bound[~hm.in_view]).all()
    # No ray passes over the strip (it is the view's edge): it is bounded by the map's highest seen height.
    np.testing.assert_allclose(bound[(x < left) & hm.in_view], np.nanmax(hm.heights))


def test_a_wide_hole_in_the_table_is_bounded_by_the_rays_on_either_side():
    # 8 cm of table without readings beside a 5 cm box, seen 40 deg tilted. Its near edge is bounded by the
    # line of sight over the seen table toward the camera (about 0); its far edge, beyond the reach of any
    # occluder, by the rays that reached the table just beyond it -- at most H (gap + 2 cell diagonals) / r --
    # not by the tallest thing in view.
    depth, table, seg, metric, _ = scene(tilt_deg=40.0, centre=(0.0, 0.0))
    v, u = np.indices(depth.shape)
    xy = (table_points(CAMERA, table, v, u) - metric.origin) @ metric.R_camera_plane[:, :2]
    hole = (xy[..., 0] > 0.04) & (xy[..., 0] < 0.10) & (xy[..., 1] > -0.14) & (xy[..., 1] < -0.06)
    hm = height_map(np.where(hole, 0.0, depth), CAMERA, table, metric, seg.mask, margin=0.2)
    assert hm.camera_xy[1] > 0.5  # the camera's foot: beyond the hole's near edge (y = -0.06)
    x, y = cell_xy(hm)
    inner = (x > 0.045) & (x < 0.095) & ~hm.seen
    near, far = inner & (y > -0.065) & (y < -0.06), inner & (y > -0.14) & (y < -0.135)
    assert near.sum() > 10 and far.sum() > 10
    bound = hm.conservative()
    assert bound[near].max() < 1e-3
    r = np.hypot(x[far] - hm.camera_xy[0], y[far] - hm.camera_xy[1]).min()
    assert bound[far].max() <= 0.7 * (0.005 + 2 * math.sqrt(2) * CELL) / r < 0.4 * hm.max_height


def test_lookups_and_the_heights_of_points():
    _, _, _, metric, hm = scene(tilt_deg=12.7, radius=0.03, height=0.05, centre=(0.02, -0.03))
    assert hm.at([[0.02, -0.03], [5.0, 5.0]])[0] == pytest.approx(0.05, abs=1e-3)
    assert np.isnan(hm.at([[5.0, 5.0]])[0])
    x0, x1, y0, y1 = hm.extent
    assert (x1 - x0, y1 - y0) == pytest.approx((hm.shape[1] * CELL, hm.shape[0] * CELL))
    assert metric.contour_xy.min(axis=0) - 0.12 == pytest.approx(hm.origin)
    # A planning-frame point on the table has height 0, and 1 cm up the approach axis (toward the camera) 1 cm.
    tz = -(hm.table_offset + hm.table_normal[:2] @ [0.02, -0.03]) / hm.table_normal[2]
    assert hm.height_of([[0.02, -0.03, tz], [0.02, -0.03, tz - 0.01]]) == pytest.approx([0.0, 0.01], abs=1e-9)
    assert hm.camera_height == pytest.approx(0.7)


def test_a_mask_of_the_wrong_size_or_type_is_refused():
    depth, table, seg, metric, _ = scene()
    with pytest.raises(PerceptionError, match="mask"):
        height_map(depth, CAMERA, table, metric, seg.mask[:-1])
    with pytest.raises(PerceptionError, match="depth image"):
        height_map(depth[:, :-1], CAMERA, table, metric, seg.mask)
    with pytest.raises(PerceptionError, match="plane must be"):
        height_map(depth, CAMERA, None, metric, seg.mask)
    with pytest.raises(PerceptionError, match="metric must be"):
        height_map(depth, CAMERA, table, seg, seg.mask)


def test_a_depth_image_without_readings_is_refused():
    depth, table, seg, metric, _ = scene()
    with pytest.raises(PerceptionError, match="no valid reading"):
        height_map(np.full_like(depth, np.nan), CAMERA, table, metric, seg.mask)


@pytest.mark.parametrize("cell, message", [(1e3, "cell must be at most"), (0.0, "cell must be positive"),
                                           (-0.002, "cell must be positive"), (math.nan, "cell must be a finite"),
                                           ("2mm", "cell must be a finite")])
def test_absurd_cells_are_refused_by_name(cell, message):
    depth, table, seg, metric, _ = scene()
    with pytest.raises(PerceptionError, match=message):
        height_map(depth, CAMERA, table, metric, seg.mask, cell=cell)


def test_a_grid_of_too_many_cells_is_refused_naming_the_limit():
    depth, table, seg, metric, _ = scene()
    for cell in (1e-9, 1e-4):  # 1e-4 m: 3,000 x 3,000 cells, just over the limit
        with pytest.raises(PerceptionError, match=f"MAX_HEIGHT_MAP_CELLS = {MAX_HEIGHT_MAP_CELLS:,}"):
            height_map(depth, CAMERA, table, metric, seg.mask, cell=cell)
    with pytest.raises(PerceptionError, match="margin"):
        height_map(depth, CAMERA, table, metric, seg.mask, margin=-0.1)


def test_a_coarse_cell_keeps_the_highest_point():
    # 1 cm cells: every cell holding a bit of the box's top (here the last millimetre before its edge)
    # holds the top's height, whatever share of table it holds beside it: not a mean of top and table.
    side, height = 0.03, 0.05
    depth, table, seg, metric, _ = scene(radius=side, height=height, centre=(0.0, 0.0))
    hm = height_map(depth, CAMERA, table, metric, seg.mask, cell=0.01, margin=0.05)
    along = np.linspace(-side + 0.002, side - 0.002, 25)
    for edge in ([side - 0.001, 0.0], [-side + 0.001, 0.0], [0.0, side - 0.001], [0.0, -side + 0.001]):
        points = np.where(np.array(edge) == 0.0, along[:, None], np.array(edge))
        np.testing.assert_allclose(hm.at(points), height, atol=1e-3)


@pytest.mark.parametrize("name, tilted", [("can", False), ("case", True)])
def test_the_object_height_matches_the_simulation_exactly(name, tilted):
    # A rendered scene (MuJoCo ray casting, exact depth) against the object's true top: within 5 mm (measured:
    # 0.1 mm or less exact, +1-3 mm with the sensor's noise, `benchmarks/height_map.py`).
    sim = pytest.importorskip("contourgrasp.sim")
    from contourgrasp import pipeline

    scene = sim.build_scene(name, seed=1, camera=sim.Camera(height=0.7))
    view = sim.tilted_view(math.radians(12.7), 0.7) if tilted else None
    rgb, depth = sim.render(scene, view=view)
    seg, metric, _ = pipeline.perceive(rgb, depth, scene.camera.intrinsics)
    hm = pipeline.scene_heights(perception_depth(depth), scene.camera.intrinsics, seg, metric)
    truth = scene.object_points()[:, 2].max()
    assert hm.max_height == pytest.approx(truth, abs=5e-3)
    assert np.nanmax(hm.heights[hm.object]) == pytest.approx(truth, abs=5e-3)
    assert not hm.obstacles.any()  # nothing but the object stands on the table
    seen = hm.heights[hm.seen & ~hm.object]
    assert np.percentile(np.abs(seen), 99) < 2e-3


def perception_depth(depth):
    from contourgrasp.perception import fill_depth_holes

    return fill_depth_holes(depth)[0]


def test_the_tables_own_cells_read_its_plane_not_their_noise():
    # Noise of +-4 mm on every reading: a table cell keeps its highest reading unless it is the table's own cell.
    depth, table, seg, metric, _ = scene(height=0.05)
    noisy = depth + np.random.default_rng(0).uniform(-0.004, 0.004, depth.shape)
    hm = height_map(noisy, CAMERA, table, metric, seg.mask, margin=0.12)
    own = hm.seen & ~hm.object & ~hm.obstacles
    assert own.sum() > 1000 and np.nanmax(hm.heights[own]) <= 0.0
    assert np.nanmin(hm.heights[own]) < -0.002  # readings below the plane keep their height
    x, y = cell_xy(hm)
    top = (np.abs(x - 0.02) < 0.02) & (np.abs(y + 0.03) < 0.02)
    assert hm.heights[top].min() > 0.045 and hm.heights[top].max() > 0.0505  # the object's cells keep their highest


def test_a_neighbour_keeps_its_height_and_a_sheet_lower_than_min_height_is_table():
    depth, table, seg, metric, _ = scene(height=0.05, centre=(0.02, -0.03))
    neighbour, _, _, _ = render(kind="box", radius=0.015, height=0.03, centre=(-0.08, 0.05))
    sheet, _, _, _ = render(kind="box", radius=0.015, height=0.006, centre=(0.09, 0.06))
    both = np.minimum(np.minimum(depth, neighbour), sheet)
    hm = height_map(both, CAMERA, table, metric, seg.mask, margin=0.12)
    np.testing.assert_allclose(hm.at([[-0.08, 0.05]]), 0.03, atol=1e-3)
    assert hm.obstacles[hm.cell_index([[-0.08, 0.05]])[:2]].all()
    assert hm.at([[0.09, 0.06]])[0] == 0.0  # 6 mm: below the segmentation's MIN_HEIGHT, read as the table



def pixel_cells(hm, table, metric, v, u):
    """(rows, cols, inside) of the map's cells under pixels (v, u) of the table."""
    xy = (table_points(CAMERA, table, np.asarray(v), np.asarray(u)) - metric.origin) @ metric.R_camera_plane[:, :2]
    return hm.cell_index(xy)


def test_a_lone_noisy_reading_is_no_obstacle_and_a_patch_as_high_is_one():
    # One reading 2 cm up on the bare table (a noise spike): the table; 5 x 5 readings as high (a small thing): an
    # obstacle at its height.
    depth, table, seg, metric, _ = scene(height=0.05, centre=(0.02, -0.03))
    cv, cu = (int(c) for c in np.argwhere(seg.mask).mean(axis=0))
    spiked = depth.copy()
    spiked[cv - 60, cu] -= 0.02
    spiked[cv + 58:cv + 63, cu - 62:cu - 57] -= 0.02
    hm = height_map(spiked, CAMERA, table, metric, seg.mask, margin=0.12)
    r, c, inside = pixel_cells(hm, table, metric, [cv - 60, cv + 60], [cu, cu - 60])
    assert inside.all()
    assert hm.heights[r[0], c[0]] <= 0.0 and not hm.obstacles[r[0], c[0]]
    assert hm.heights[r[1], c[1]] == pytest.approx(0.02, abs=2e-3) and hm.obstacles[r[1], c[1]]


def test_a_dropout_beside_a_low_object_is_bounded_by_it_not_by_a_tall_thing_elsewhere():
    # A 3 px ring of missing readings round a 5 cm box (a sensor's edge dropouts), and a 25 cm post 10 cm from it: the
    # ring is no higher than the box (it was the post's height), while the inside of a wide hole is not the table.
    depth, table, seg, metric, _ = scene(height=0.05, centre=(0.02, -0.03))
    post, _, _, _ = render(kind="box", radius=0.01, height=0.25, centre=(-0.1, -0.03))
    ring = np.zeros(depth.shape, bool)
    rows, cols = np.nonzero(seg.mask)
    ring[rows.min() - 3:rows.max() + 4, cols.min() - 3:cols.max() + 4] = True
    ring &= ~seg.mask
    cv, cu = int(rows.mean()), int(cols.mean())
    wide = np.zeros(depth.shape, bool)
    wide[cv + 50:cv + 110, cu - 30:cu + 30] = True  # 8 cm of table without readings
    hm = height_map(np.where(ring | wide, 0.0, np.minimum(depth, post)), CAMERA, table, metric, seg.mask, margin=0.2)
    bound = hm.conservative()

    def unseen(mask):
        r, c, inside = pixel_cells(hm, table, metric, *np.nonzero(mask))
        keep = inside & ~hm.seen[r, c]
        assert keep.sum() > 20
        return r[keep], c[keep]

    assert bound[unseen(ring)].max() <= 0.05 + 1e-3
    inner = np.zeros(depth.shape, bool)
    inner[cv + 65:cv + 95, cu - 15:cu + 15] = True
    # 15-45 px (2-6 cm) inside the wide hole: not the table beside it, but the post's height or the rays over it
    assert bound[unseen(inner)].min() > 0.1 and np.nanmax(hm.heights) > 0.2

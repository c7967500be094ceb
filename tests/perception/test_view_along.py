"""The scene seen along an approach against analytic truth: ray-cast boxes and cylinders seen from the side."""

from __future__ import annotations

import math

import numpy as np
import pytest

from contourgrasp.errors import PerceptionError
from contourgrasp.perception import Plane, contour_to_metric, height_map, segment_depth
from contourgrasp.perception.view_along import BLOCKED, Approach, column_points, view_along, view_axes
from contourgrasp.tolerances import HEIGHT_MAP_CELL, MIN_HEIGHT, VIEW_CELL
from perception_scenes import CAMERA, render

CELL = HEIGHT_MAP_CELL * VIEW_CELL


def heights_of(*, kind="box", radius=0.03, height=0.08, centre=(0.02, -0.03)):
    """The top-down height map of one ray-cast object (the table 0.7 m below the camera)."""
    depth, _, _, normal = render(kind=kind, radius=radius, height=height, centre=centre)
    seg = segment_depth(depth, CAMERA)
    metric = contour_to_metric(seg.contour_px, depth, CAMERA, plane=seg.plane, on_table=seg.on_table)
    return height_map(depth, CAMERA, Plane(normal=normal, offset=0.7), metric, seg.mask)


@pytest.fixture(scope="module")
def box():
    return heights_of()


def test_the_approach_frame_is_right_handed_with_x_along_the_table():
    normal = np.array([0.0, 0.0, -1.0])
    for approach in (Approach(0.0, 0.3), Approach(math.pi / 4, 2.0), Approach(0.2, 5.0)):
        R = view_axes(approach, normal)
        np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
        assert np.linalg.det(R) == pytest.approx(1.0)
        np.testing.assert_allclose(R[:, 2], approach.direction(normal))
        assert R[:, 0] @ normal == pytest.approx(0.0, abs=1e-12)
        assert R[:, 2] @ normal == pytest.approx(-math.sin(approach.elevation))  # down into the table by the elevation
    np.testing.assert_allclose(Approach(math.pi / 2).direction(normal), [0.0, 0.0, 1.0])


def test_a_box_seen_from_the_side_is_its_side_standing_on_a_blocked_table(box):
    # A 6 x 6 x 8 cm box seen horizontally along x: a 6 cm wide, 8 cm tall outline; the reference plane
    # at its back, so its front stands its 6 cm depth in front; below the table's line the hand cannot go.
    view = view_along(box, Approach(0.0, 0.0))
    np.testing.assert_allclose(np.ptp(view.contour_xy, axis=0), [0.06, 0.08], atol=2 * CELL)
    assert view.heights.max_height == pytest.approx(0.06, abs=CELL)
    xs, ys = view.heights.centres()
    x, y = np.meshgrid(xs, ys)
    table_line = ys[np.nonzero(view.heights.object.any(axis=1))[0].max()]
    below = y > table_line + CELL
    assert np.all(view.heights.heights[below] == BLOCKED) and view.heights.obstacles[below].all()
    above = (y < view.contour_xy[:, 1].min() - CELL)
    assert np.all(view.heights.heights[above] == 0.0) and not view.heights.obstacles[above].any()
    front = view.heights.heights[view.heights.object]
    assert np.median(front) == pytest.approx(0.06, abs=CELL)  # the box's flat front face
    # The frame: y points down the table's normal, the origin is the box's back at its mid-height.
    np.testing.assert_allclose(view.R_plane_view[:, 1], box.table_normal / -np.linalg.norm(box.table_normal),
                               atol=1e-9)
    back = view.to_plane([[0.0, 0.0, 0.0]])[0]
    assert back[0] == pytest.approx(0.02 + 0.03, abs=CELL)  # the box's far face along x
    assert box.height_of(back[None])[0] == pytest.approx(0.04, abs=CELL)


def test_a_box_seen_at_45_degrees_shows_its_top_and_side(box):
    view = view_along(box, Approach(math.pi / 4, math.pi / 2))
    s = math.sqrt(0.5)
    np.testing.assert_allclose(np.ptp(view.contour_xy, axis=0), [0.06, (0.08 + 0.06) * s], atol=2 * CELL)
    # The table is in front of the reference plane only below the box: obstacles there, none above it.
    assert view.heights.obstacles.any()
    assert view.heights.max_height == pytest.approx((0.08 + 0.06) * s, abs=2 * CELL)


@pytest.mark.parametrize("azimuth", [0.0, 0.7, 2.5, 4.0])
def test_a_cylinder_is_as_wide_as_its_diameter_from_every_side(azimuth):
    radius, height = 0.035, 0.12
    view = view_along(heights_of(kind="cylinder", radius=radius, height=height), Approach(0.0, azimuth))
    np.testing.assert_allclose(np.ptp(view.contour_xy, axis=0), [2 * radius, height], atol=2 * CELL)
    assert view.heights.max_height == pytest.approx(2 * radius, abs=2 * CELL)


def test_columns_fill_the_target_down_to_the_table_and_leave_the_table_out(box):
    columns = column_points(box)
    points, target = columns.points, columns.target
    assert target.all()  # one object on a bare table: every column is the target's
    heights = box.height_of(points)
    assert heights.min() == pytest.approx(0.0, abs=1e-9) and heights.max() == pytest.approx(0.08, abs=2e-3)
    assert np.all(heights >= -1e-9)


def test_a_neighbour_in_front_is_an_obstacle_that_hides_what_is_behind_it(box):
    # A 4 cm wall in front of the box's lower half (added to the map as a neighbour's cells).
    xs, ys = box.centres()
    x, y = np.meshgrid(xs, ys)
    wall = (np.abs(x + 0.04) < 0.005) & (np.abs(y + 0.03) < 0.05)
    heights = box.heights.copy()
    heights[wall] = 0.04
    scene = type(box)(**{**box.__dict__, "heights": heights, "obstacles": box.obstacles | wall})
    view = view_along(scene, Approach(0.0, 0.0))
    assert view.heights.obstacles.any()
    assert view.heights.heights[view.heights.obstacles].max() == BLOCKED  # the table
    wall_cells = view.heights.obstacles & (view.heights.heights < BLOCKED)
    assert view.heights.heights[wall_cells].max() == pytest.approx(0.06 + 0.04 - 0.005, abs=2 * CELL)
    assert np.ptp(view.contour_xy[:, 1]) == pytest.approx(0.04, abs=2 * CELL)  # only its upper half is seen
    assert np.all(view.heights.heights[wall_cells] >= MIN_HEIGHT)


@pytest.mark.parametrize("approach, message", [
    (lambda: Approach(math.pi / 2), "top-down"),
])
def test_a_top_down_view_is_refused(box, approach, message):
    with pytest.raises(PerceptionError, match=message):
        view_along(box, approach())


@pytest.mark.parametrize("kwargs, message", [
    ({"elevation": 2.0}, r"elevation must be in \[0, pi/2\]"),
    ({"elevation": -0.1}, "elevation"),
    ({"elevation": float("nan")}, "finite"),
    ({"elevation": 0.0, "azimuth": "north"}, "azimuth"),
    ({"elevation": True}, "elevation"),
    ({"elevation": 0.0, "azimuth": 10**400}, "azimuth must be a finite number"),
])
def test_bad_approaches_are_refused_by_name(kwargs, message):
    with pytest.raises(PerceptionError, match=message):
        Approach(**kwargs)


def test_approaches_describe_themselves():
    assert Approach(math.pi / 2).describe() == "top-down"
    assert Approach(0.0, math.pi / 2).describe() == "side (elevation 0 deg, azimuth 90 deg)"
    assert Approach(math.pi / 4, -math.pi / 2).describe() == "tilted (elevation 45 deg, azimuth 270 deg)"

"""One frame's derived images computed once (perception._frame, perception.one_frame)."""

import numpy as np
import pytest

from contourgrasp.perception import Intrinsics, Plane, one_frame, valid_depth
from contourgrasp.perception.segment_depth import raised_pixels
from contourgrasp.perception.table import heights

CAMERA = Intrinsics(fx=500.0, fy=500.0, cx=15.5, cy=11.5, width=32, height=24)
TABLE = Plane(normal=np.array([0.0, 0.0, -1.0]), offset=0.7)


def _depth():
    depth = np.full((24, 32), 0.7)
    depth[8:16, 10:20] = 0.65  # a box 5 cm tall
    depth[0, :3] = 0.0  # missing at the border
    return depth


def test_inside_a_frame_each_image_is_computed_once_and_read_only():
    depth = _depth()
    with one_frame():
        valid, h = valid_depth(depth), heights(depth, CAMERA, TABLE)
        assert valid_depth(depth) is valid and heights(depth, CAMERA, TABLE) is h
        assert raised_pixels(depth, CAMERA, TABLE)[0] is raised_pixels(depth, CAMERA, TABLE)[0]
        with pytest.raises(ValueError, match="read-only"):
            valid[0, 0] = False
    np.testing.assert_array_equal(valid, valid_depth(depth))
    np.testing.assert_allclose(h[8:16, 10:20], 0.05)
    assert valid_depth(depth) is not valid_depth(depth) and valid_depth(depth).flags.writeable


def test_other_planes_ranges_and_arrays_are_computed_anew():
    depth = _depth()
    with one_frame():
        lower = Plane(normal=TABLE.normal, offset=0.72)
        assert heights(depth, CAMERA, lower) is not heights(depth, CAMERA, TABLE)
        np.testing.assert_allclose(heights(depth, CAMERA, lower) - heights(depth, CAMERA, TABLE), 0.02)
        near = valid_depth(depth, (0.2, 0.68))
        assert near[12, 15] and not near[20, 20]  # the box at 0.65 m in range, the table at 0.7 m not
        assert valid_depth(depth)[20, 20]
        moved = depth.copy()
        moved[8:16, 10:20] = 0.6
        np.testing.assert_allclose(heights(moved, CAMERA, TABLE)[12, 15], 0.1)


def test_the_frame_ends_with_its_block_even_on_an_error():
    depth = _depth()
    with pytest.raises(RuntimeError), one_frame():
        valid_depth(depth)
        raise RuntimeError
    assert valid_depth(depth) is not valid_depth(depth)


def test_what_perception_hands_out_is_the_callers_to_change():
    # The frame's kept images are read-only; nothing built on them and returned may be.
    from perception_scenes import CAMERA as SCENE_CAMERA
    from perception_scenes import render

    from contourgrasp import pipeline

    depth, rgb, _, _ = render(tilt_deg=10.0)
    seg, metric, _ = pipeline.perceive(rgb, depth, SCENE_CAMERA)
    support = pipeline.find_objects(depth, SCENE_CAMERA)
    arrays = [seg.mask, seg.contour_px, seg.plane.inliers, metric.contour_xy, support.plane.inliers,
              *(c.mask for c in support.candidates)]
    assert all(a.flags.writeable for a in arrays)

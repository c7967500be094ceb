"""The inner problem (synthesis.inner): first touch, its compiled form, closest approach."""

import math

import numpy as np
import pytest
from matplotlib.path import Path as MplPath

import contourgrasp as cg
from contourgrasp import contour, synthesis
from contourgrasp.hand import to_image
from contourgrasp.synthesis import _derived, _touch_kernels
from conftest import disc


def test_centred_three_finger_grasp_on_a_disc_is_symmetric():
    hand = cg.load_hand("three-finger")
    model = contour.fit(disc(0.03))
    result = synthesis.evaluate_poses(model, hand, [[0.0, 0.0, 0.3]])
    assert result.touching.all() and result.feasible[0]
    np.testing.assert_allclose(result.lam[0], np.linalg.norm(hand.starts, axis=1) - 0.03, atol=1e-4)
    np.testing.assert_allclose(result.curvature[0], result.curvature[0, 0], rtol=1e-3)
    assert np.ptp(result.distance[0]) < 3e-4  # Table A.2 rounds the start radius to 0.0798-0.08
    angles = np.arctan2(result.grasp_point[0, :, 1], result.grasp_point[0, :, 0])
    gaps = np.sort(np.diff(np.sort(angles)))
    np.testing.assert_allclose(gaps, 2 * math.pi / 3, atol=1e-2)


@pytest.mark.parametrize("chords", [1, 64])
def test_closest_approach_of_a_finger_passing_beside_a_disc(chords):
    # The index's ray passes 3 cm from the centre of a 2 cm disc, nearest at its middle: 1 cm gap
    # there, the nearest contour point on the circle, and that point the caller's own.
    finger = cg.load_hand("five-finger-linear").fingers[1]
    model = contour.fit(disc(0.02))
    a, b = to_image(finger.points(np.array([0.0, finger.travel])), np.zeros(3))
    direction = (b - a) / np.linalg.norm(b - a)
    pose = np.r_[0.03 * np.array([-direction[1], direction[0]]) - (a + b) / 2, 0.0]
    t, lam, point, gap = synthesis.closest_approach(model, finger, pose, chords=chords)
    assert gap == pytest.approx(0.01, abs=1e-5)
    assert lam == pytest.approx(finger.travel / 2, abs=1e-3)
    assert np.linalg.norm(point) == pytest.approx(0.02, abs=1e-5)
    before = point.copy()
    point += 1.0
    np.testing.assert_array_equal(synthesis.closest_approach(model, finger, pose, chords=chords)[2], before)


def test_first_touch_matches_brute_force_marching():
    hand = cg.load_hand("five-finger-linear")
    model = contour.fit(cg.example_contour("peanut"))
    _, polygon = contour.sample(model, 8192)  # the curve itself, for practical purposes
    inside = MplPath(polygon)
    rng = np.random.default_rng(0)
    poses = np.c_[rng.uniform(-0.15, 0.15, (40, 2)), rng.uniform(0, 2 * math.pi, 40)]
    result = synthesis.evaluate_poses(model, hand, poses)
    lam = np.linspace(0, 1, 4001)
    for p, pose in enumerate(poses):
        for f, finger in enumerate(hand.fingers):
            if result.start_inside[p, f]:
                continue
            path = cg.hand.to_image(finger.points(lam * finger.travel), pose)
            hits = np.flatnonzero(inside.contains_points(path))
            if hits.size == 0:
                assert not result.touching[p, f]
            else:
                assert result.touching[p, f]
                assert result.lam[p, f] == pytest.approx(lam[hits[0]] * finger.travel, abs=finger.travel / 2000)


def test_compiled_pose_list_matches_the_numpy_inner_problem():
    """evaluate_poses's polygon stage (every chord against every edge, compiled) is first_touch's answer."""
    for hand in map(cg.load_hand, cg.preset_names()):
        model = contour.fit(cg.example_contour("peanut"))
        t, polygon = contour.sample(model)
        rng = np.random.default_rng(2)
        poses = np.c_[rng.uniform(-0.12, 0.12, (300, 2)), rng.uniform(0, 2 * math.pi, 300)]
        seg = hand.segments()
        lam, t_hit, point, inside = _touch_kernels.pose_first_touch(
            polygon, t, model.T, poses, seg.start, seg.end - seg.start, seg.finger, seg.lam0,
            _derived.first_chords(seg, len(hand.fingers)), len(hand.fingers), cg.tolerances.PARALLEL)
        ref_lam, ref_t, ref_point, ref_inside = synthesis.first_touch(polygon, t, model.T, seg, len(hand.fingers), poses)
        touching = np.isfinite(ref_lam)
        assert touching.any() and ref_inside.any()
        np.testing.assert_array_equal(inside, ref_inside)
        np.testing.assert_array_equal(np.isfinite(lam), touching)
        np.testing.assert_allclose(lam[touching], ref_lam[touching], atol=1e-12)
        np.testing.assert_allclose(t_hit[touching], ref_t[touching], atol=1e-12)
        np.testing.assert_allclose(point[touching], ref_point[touching], atol=1e-12)


@pytest.mark.parametrize("seed", [4, 7, 8])
def test_nearest_point_segment_matches_numpy(seed):
    rng = np.random.default_rng(seed)
    points, starts, vectors = rng.normal(size=(30, 2)), rng.normal(size=(20, 2)), rng.normal(size=(20, 2))
    w = points[:, None] - starts[None]
    s = np.clip(np.einsum("nsi,si->ns", w, vectors) / np.sum(vectors**2, axis=1), 0, 1)
    gap = np.linalg.norm(w - s[..., None] * vectors[None], axis=2)
    i, k = np.unravel_index(np.argmin(gap), gap.shape)
    got = _touch_kernels.nearest_point_segment(points, starts, vectors)
    assert got[:2] == (i, k)
    assert got[2:] == pytest.approx((s[i, k], gap[i, k]), abs=1e-14)


def test_start_inside_matches_point_in_polygon():
    hand = cg.load_hand("five-finger-linear")
    model = contour.fit(cg.example_contour("case") * 2.5)
    _, polygon = contour.sample(model)
    rng = np.random.default_rng(1)
    poses = np.c_[rng.uniform(-0.2, 0.2, (300, 2)), rng.uniform(0, 2 * math.pi, 300)]
    result = synthesis.evaluate_poses(model, hand, poses)
    starts = np.stack([cg.hand.to_image(hand.starts, pose) for pose in poses])
    expected = MplPath(polygon).contains_points(starts.reshape(-1, 2)).reshape(len(poses), -1)
    assert expected.any() and (~expected).any()
    np.testing.assert_array_equal(result.start_inside, expected)

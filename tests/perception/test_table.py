"""The table plane: RANSAC fit, tilt, near ties (contourgrasp.perception.table)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from contourgrasp.perception import PerceptionError, Plane, SegmentationError, fit_plane, fit_table_plane
from perception_scenes import H, W, CAMERA, render


@pytest.mark.parametrize("tilt_deg", [0.0, 3.7, 12.7, 25.0])
def test_table_tilt_is_recovered(tilt_deg):
    depth, _, _, normal = render(tilt_deg=tilt_deg)
    plane = fit_table_plane(depth, CAMERA)
    assert math.degrees(plane.tilt) == pytest.approx(tilt_deg, abs=0.5)
    assert plane.normal[2] < 0
    assert plane.normal @ normal == pytest.approx(1.0, abs=1e-4)
    assert plane.offset == pytest.approx(0.7, abs=1e-3)
    assert plane.inliers.shape == (H, W)


def test_plane_fit_is_deterministic_and_ignores_outliers():
    rng = np.random.default_rng(1)
    table = np.c_[rng.uniform(-0.3, 0.3, (2000, 2)), np.full(2000, 0.8)]
    clutter = rng.uniform([-0.3, -0.3, 0.4], [0.3, 0.3, 0.7], (800, 3))
    points = np.vstack([table, clutter])
    first, second = fit_plane(points, seed=3), fit_plane(points, seed=3)
    np.testing.assert_array_equal(first.normal, second.normal)
    assert first.normal == pytest.approx([0, 0, -1], abs=1e-9)
    assert first.offset == pytest.approx(0.8)
    assert first.inliers[:2000].all() and first.inliers[2000:].mean() < 0.05


def test_plane_scored_on_a_sample_is_refitted_on_all_points():
    # 30,000 points, 40 % clutter above a tilted table; candidates are scored on 300 of them only.
    rng = np.random.default_rng(2)
    normal = np.array([0.0, -math.sin(0.3), -math.cos(0.3)])
    along = np.array([[1.0, 0.0, 0.0], np.cross(normal, [1.0, 0.0, 0.0])])
    table = -0.7 * normal + rng.uniform(-0.3, 0.3, (18000, 2)) @ along + rng.uniform(-1e-3, 1e-3, (18000, 1)) * normal
    clutter = -0.7 * normal + rng.uniform(-0.3, 0.3, (12000, 2)) @ along + rng.uniform(0.02, 0.3, (12000, 1)) * normal
    points = np.vstack([table, clutter])
    sampled, scored_on_all = fit_plane(points, sample=300), fit_plane(points, sample=len(points))
    assert sampled.normal @ normal == pytest.approx(1.0, abs=1e-6)
    assert sampled.offset == pytest.approx(0.7, abs=1e-4)
    np.testing.assert_array_equal(sampled.inliers, np.arange(len(points)) < len(table))
    np.testing.assert_allclose(sampled.normal, scored_on_all.normal, atol=1e-12)


def test_plane_holding_the_most_points_wins_over_a_near_tie():
    # A table and a platter 2 cm above it with 2 % fewer points: a 300-point sample cannot tell them apart.
    rng = np.random.default_rng(4)
    table = np.c_[rng.uniform(-0.3, 0.3, (10200, 2)), np.full(10200, 0.8)]
    platter = np.c_[rng.uniform(-0.3, 0.3, (9800, 2)), np.full(9800, 0.78)]
    points = np.vstack([table, platter])
    for seed in range(8):
        assert fit_plane(points, sample=300, seed=seed).offset == pytest.approx(0.8)


def test_no_table_plane_in_noise():
    rng = np.random.default_rng(0)
    depth = rng.uniform(0.3, 1.4, (H, W))
    with pytest.raises(SegmentationError, match="no table plane") as err:
        fit_table_plane(depth, CAMERA)
    assert err.value.kind == "no-plane"


@pytest.mark.parametrize("fields, message", [
    ({"normal": np.array([np.nan, 0.0, -1.0]), "offset": 0.5}, r"plane: normal\[0\] is not finite"),
    ({"normal": np.zeros(3), "offset": 0.5}, "plane: normal must be a unit vector, got length 0"),
    ({"normal": "up", "offset": 0.5}, "plane: normal must be an array of real numbers"),
    ({"normal": np.array([0.0, 0.0, -1.0, 0.0]), "offset": 0.5}, r"plane: normal must be a \(3,\) array"),
    ({"normal": np.array([0.0, 0.0, -1.0]), "offset": 10**400}, "plane: offset must be a finite number"),
    ({"normal": np.array([0.0, 0.0, -1.0]), "offset": 0.5, "inliers": np.zeros(3)}, "plane: inliers must be a bool"),
])
def test_a_malformed_plane_is_refused_where_it_is_made(fields, message):
    with pytest.raises(PerceptionError, match=message):
        Plane(**fields)

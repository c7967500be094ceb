"""Adaptive harmonics (contour.choose_harmonics, thesis 4.2.1 and 6.1 item 3)."""

import warnings

import numpy as np
import pytest
from contour_fuzz import polygons
from hypothesis import given, settings

from contourgrasp import ContourError, InputError, UnitWarning, contour, example_contour
from contourgrasp import tolerances as tol
from contourgrasp.perception import mask_contour
from conftest import rotate

LOWER, UPPER = 3, 12


def _camera_outline(points, rng, pixel=0.0015):
    """The polygon as a camera mask outlines it: rasterised at ``pixel`` m, random sub-pixel offset."""
    import cv2

    q = (points - points.min(axis=0)) / pixel + 4.0 + rng.uniform(0.0, 1.0, 2)
    height, width = (np.ceil(q.max(axis=0)) + 5).astype(int)[::-1]
    mask = np.zeros((height, width), np.uint8)
    cv2.fillPoly(mask, [np.round(q * 16).astype(np.int32)], 1, shift=4)
    return mask_contour(mask) * pixel


def _normal_noise(points, sigma, rng, spacing=0.003):
    """The polygon resampled every ``spacing`` m, each point moved along the normal by N(0, sigma)."""
    closed = np.vstack([points, points[:1]])
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(closed, axis=0), axis=1))])
    u = np.linspace(0.0, s[-1], int(s[-1] / spacing), endpoint=False)
    q = np.c_[np.interp(u, s, closed[:, 0]), np.interp(u, s, closed[:, 1])]
    tangent = np.roll(q, -1, axis=0) - np.roll(q, 1, axis=0)
    normal = np.c_[tangent[:, 1], -tangent[:, 0]] / np.linalg.norm(tangent, axis=1)[:, None]
    while True:
        noisy = q + normal * rng.normal(0.0, sigma, (len(q), 1))
        if contour.first_self_intersection(noisy) is None:
            return noisy


def _concave_angles(model, samples=2048):
    """Polar angles (degrees, about the locus) of the concave samples of the curve."""
    t = np.linspace(0, model.T, samples, endpoint=False)
    points = contour.evaluate(model, t)[contour.concave(model, t)] - model.locus
    return np.degrees(np.arctan2(points[:, 1], points[:, 0])) % 360


def _covers(angles, centre, within=5.0):
    return angles.size > 0 and np.min(np.abs((angles - centre + 180) % 360 - 180)) <= within


def test_ellipse_and_circle_need_no_more_than_the_lower_bound(circle):
    assert contour.choose_harmonics(example_contour("ellipse")) == LOWER
    assert contour.choose_harmonics(circle, bounds=(1, 12)) == 1
    assert contour.choose_harmonics(circle, rule="power", bounds=(1, 12)) == 1


@pytest.mark.parametrize("lobes", [5, 7])
def test_fine_concavities_need_more_harmonics(lobes):
    theta = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    gear = np.c_[np.cos(theta), np.sin(theta)] * (0.04 * (1 + 0.08 * np.cos(lobes * theta)))[:, None]
    n = contour.choose_harmonics(gear)
    assert n > LOWER and n >= lobes
    model = contour.fit(gear, n)
    t = np.linspace(0, model.T, 2048, endpoint=False)
    concave = contour.concave(model, t)
    assert np.sum(concave & ~np.roll(concave, 1)) == lobes  # one concave stretch between every two teeth
    assert contour.choose_harmonics(example_contour("stone2")) > LOWER


@pytest.mark.parametrize("name", ["stone1", "stone2", "can", "bottle", "peanut"])
@pytest.mark.parametrize("rule", ["rms", "power"])
def test_choice_is_invariant_to_pose_scale_start_and_direction(name, rule):
    points = example_contour(name)
    n = contour.choose_harmonics(points, rule=rule)
    variants = [
        rotate(points, 0.7) + [0.3, -0.1],
        points * 2.5,
        points * 0.2,
        np.roll(points, 37, axis=0),
        points[::-1],
    ]
    assert [contour.choose_harmonics(v, rule=rule) for v in variants] == [n] * len(variants)


@pytest.mark.parametrize("rule, tolerances", [("rms", np.geomspace(0.05, 1e-4, 25)),
                                              ("power", np.geomspace(0.5, 1e-8, 25))])
def test_smaller_tolerance_never_gives_fewer_harmonics(rule, tolerances):
    for name in ["stone1", "stone2", "can", "case", "bottle", "peanut", "ellipse"]:
        points = example_contour(name)
        counts = [contour.choose_harmonics(points, rule=rule, tolerance=t) for t in tolerances]
        assert counts == sorted(counts), name
        assert counts[0] == LOWER and counts[-1] >= counts[0]


@pytest.mark.parametrize("bounds", [(1, 1), (1, 2), (3, 5), (5, 5), (6, 20), (10, 12), (2, 30)])
def test_bounds_are_respected(bounds):
    for name in ["stone2", "bottle", "ellipse"]:
        n = contour.choose_harmonics(example_contour(name), bounds=bounds, tolerance=1e-6)
        if name != "ellipse":  # (the ellipse is that exact with fewer: its high harmonics are ~0)
            assert n == bounds[1]  # nothing is that exact: the upper bound
        n = contour.choose_harmonics(example_contour(name), bounds=bounds, tolerance=0.5)
        assert n == bounds[0]  # anything is that close: the lower bound
        assert bounds[0] <= contour.choose_harmonics(example_contour(name), bounds=bounds) <= bounds[1]


@pytest.mark.parametrize(
    "options, name",
    [
        ({"rule": "max"}, "rule"),
        ({"rule": None}, "rule"),
        ({"tolerance": 0}, "tolerance"),
        ({"tolerance": -0.01}, "tolerance"),
        ({"tolerance": float("nan")}, "tolerance"),
        ({"tolerance": float("inf")}, "tolerance"),
        ({"tolerance": "0.01"}, "tolerance"),
        ({"tolerance": True}, "tolerance"),
        ({"rule": "power", "tolerance": 1.0}, "tolerance"),
        ({"bounds": (0, 5)}, "bounds"),
        ({"bounds": (6, 5)}, "bounds"),
        ({"bounds": (3,)}, "bounds"),
        ({"bounds": 12}, "bounds"),
        ({"bounds": (3.0, 12)}, "bounds"),
        ({"bounds": (True, 12)}, "bounds"),
        ({"bounds": "3-12"}, "bounds"),
        ({"bounds": (3, tol.MAX_HARMONICS + 1)}, "at most 100"),
    ],
)
def test_bad_options_are_refused_by_name(options, name):
    with pytest.raises(InputError, match=name):
        contour.choose_harmonics(example_contour("stone1"), **options)
    with pytest.raises(InputError, match=name):
        contour.fit_adaptive(example_contour("stone1"), **options)


def test_bad_polygon_is_a_contour_error():
    with pytest.raises(ContourError, match="at least 3"):
        contour.choose_harmonics([[0, 0], [0.1, 0.1]])


def test_fit_adaptive_is_fit_with_the_chosen_count():
    stone = example_contour("stone2")
    model = contour.fit_adaptive(stone, tolerance=0.003)
    n = contour.choose_harmonics(stone, tolerance=0.003)
    assert model.harmonics == n
    np.testing.assert_allclose(model.coefficients, contour.fit(stone, n).coefficients, atol=1e-15)
    assert contour.fit_adaptive(stone).harmonics == 8


def test_left_out_power_is_the_rms_distance_to_the_upper_bound_model():
    stone = example_contour("stone2")
    full, part = contour.fit(stone, 12), contour.fit(stone, 5)
    t = np.linspace(0, full.T, 4096, endpoint=False)
    rms = np.sqrt(np.mean(np.sum((contour.evaluate(full, t) - contour.evaluate(part, t)) ** 2, axis=1)))
    assert rms == pytest.approx(np.sqrt(np.sum(contour.harmonic_power(full)[5:])), rel=1e-9)


@pytest.mark.parametrize("rule", ["rms", "power"])
def test_simple_stone_keeps_its_hollow_flank(rule):
    """Thesis 4.2.1 / Figure 4.5: the simple stone needs few harmonics and its large flank must read concave."""
    stone = example_contour("stone1")  # its hollow flank faces polar angle 270 degrees
    n = contour.choose_harmonics(stone, rule=rule)
    assert LOWER < n <= 5
    angles = _concave_angles(contour.fit(stone, n))
    assert _covers(angles, 270.0)
    assert np.all(np.abs(angles - 270.0) < 30.0)  # and nothing else is concave
    assert _concave_angles(contour.fit(stone, LOWER)).size == 0  # the lower bound alone would lose it


@pytest.mark.parametrize("rule", ["rms", "power"])
def test_complex_stone_keeps_its_concavities(rule):
    """Thesis 4.2.1 / Figure 4.6: four harmonics turn most of the complex stone's concavities convex."""
    stone = example_contour("stone2")
    reference = _concave_angles(contour.fit(stone, 30))
    centres = [c for c in (32.0, 89.0, 188.0, 240.0, 299.0) if _covers(reference, c, 1.0)]
    assert len(centres) == 5
    n = contour.choose_harmonics(stone, rule=rule)
    assert n == 8
    adaptive, thesis = _concave_angles(contour.fit(stone, n)), _concave_angles(contour.fit(stone, 4))
    assert all(_covers(adaptive, c) for c in centres)
    assert sum(_covers(thesis, c) for c in centres) == 1


@pytest.mark.parametrize("name", ["stone1", "stone2", "ellipse", "can", "peanut"])
def test_camera_staircase_does_not_add_harmonics(name):
    """A 1.5 mm pixel staircase (about a pixel at 0.6 m) leaves the choice within one step of the clean one."""
    points = example_contour(name)
    clean = contour.choose_harmonics(points)
    rng = np.random.default_rng(11)
    for _ in range(3):
        n = contour.choose_harmonics(_camera_outline(points, rng))
        assert abs(n - clean) <= 2 and n < UPPER
    if name == "stone2":
        assert n == 8


@pytest.mark.parametrize("name", ["stone1", "stone2", "ellipse", "can", "peanut"])
def test_millimetre_noise_keeps_the_count_moderate(name):
    """1 mm of white noise along the normal every 3 mm: N stays well below the upper bound."""
    points = example_contour(name)
    rng = np.random.default_rng(5)
    counts = [contour.choose_harmonics(_normal_noise(points, 0.001, rng)) for _ in range(3)]
    assert max(counts) <= 9
    if name == "stone2":
        assert counts == [8, 8, 8]
    if name == "stone1":
        assert max(counts) <= 6


# --- fuzz ------------------------------------------------------------------------------------------------

@settings(max_examples=50, deadline=None)
@given(polygons())
def test_fit_adaptive_gives_a_finite_model_or_a_clear_error(points):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UnitWarning)
        try:
            model = contour.fit_adaptive(points)
        except InputError:
            return
    assert tol.HARMONICS_BOUNDS[0] <= model.harmonics <= tol.HARMONICS_BOUNDS[1]
    assert np.isfinite(model.coefficients).all() and np.isfinite(contour.curvature(model, [0.0, model.T / 3])).all()

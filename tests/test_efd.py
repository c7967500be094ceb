import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from contourgrasp import ContourError, UnitWarning, efd, example_contour
from contourgrasp import tolerances as tol
from conftest import disc, rotate


def kuhl_giardina(points: np.ndarray, harmonics: int) -> np.ndarray:
    """Eq 3.9-3.12 transcribed term by term, as an independent reference."""
    closed = np.vstack([points, points[:1]])
    coeffs = np.zeros((harmonics, 4))
    dxy = np.diff(closed, axis=0)
    dt = np.hypot(dxy[:, 0], dxy[:, 1])
    t = np.concatenate([[0.0], np.cumsum(dt)])
    T = t[-1]
    for n in range(1, harmonics + 1):
        k = T / (2 * n**2 * np.pi**2)
        for i in range(len(dt)):
            dc = np.cos(2 * n * np.pi * t[i + 1] / T) - np.cos(2 * n * np.pi * t[i] / T)
            ds = np.sin(2 * n * np.pi * t[i + 1] / T) - np.sin(2 * n * np.pi * t[i] / T)
            coeffs[n - 1] += k * np.array([dxy[i, 0] / dt[i] * dc, dxy[i, 0] / dt[i] * ds,
                                           dxy[i, 1] / dt[i] * dc, dxy[i, 1] / dt[i] * ds])
    return coeffs


def test_coefficients_match_the_equations():
    rng = np.random.default_rng(3)
    theta = np.sort(rng.uniform(0, 2 * np.pi, 40))
    polygon = np.c_[np.cos(theta), np.sin(theta)] * rng.uniform(0.03, 0.06, (40, 1))
    model = efd.fit(polygon, harmonics=6)
    np.testing.assert_allclose(model.coefficients, kuhl_giardina(polygon, 6), atol=1e-9)


def test_dc_terms_are_the_arc_length_centroid():
    square = np.array([[0.0, 0.0], [0.1, 0.0], [0.1, 0.1], [0.0, 0.1]]) + [0.2, -0.3]
    model = efd.fit(square)
    assert model.A0 == pytest.approx(0.25, abs=1e-12)
    assert model.C0 == pytest.approx(-0.25, abs=1e-12)
    assert model.T == pytest.approx(0.4)


def test_circle_is_one_harmonic(circle):
    model = efd.fit(circle, harmonics=4)
    np.testing.assert_allclose(model.coefficients[0], [0.04, 0, 0, 0.04], atol=1e-5)
    np.testing.assert_allclose(model.coefficients[1:], 0, atol=1e-5)


def test_many_harmonics_reproduce_the_polygon():
    can = example_contour("can")
    model = efd.fit(can, harmonics=40)
    t, points = efd.sample(model, 2000)
    gap = np.min(np.linalg.norm(points[:, None] - can[None], axis=2), axis=0)
    assert gap.max() < 1e-3


@pytest.mark.parametrize("k", [1, 2, 3])
def test_derivatives_match_finite_differences(k):
    model = efd.fit(example_contour("stone2"), harmonics=8)
    t = np.linspace(0, model.T, 50, endpoint=False)
    h = 1e-5
    numeric = (efd.evaluate(model, t + h, k - 1) - efd.evaluate(model, t - h, k - 1)) / (2 * h)
    np.testing.assert_allclose(efd.evaluate(model, t, k), numeric, rtol=1e-4, atol=1e-6)


def test_derivatives_together_are_evaluate_to_the_last_bit():
    model = efd.fit(example_contour("peanut"), harmonics=7)
    t = np.random.default_rng(5).uniform(-0.1, 2 * model.T, 300)
    together = efd.evaluate_derivatives(model, t, (2, 0, 1))
    for order, values in zip((2, 0, 1), together):
        np.testing.assert_array_equal(values, efd.evaluate(model, t, order))
    for mode in efd.CURVATURE_MODES:
        np.testing.assert_array_equal(efd.curvature_from_derivatives(together[2], together[0], model.T, mode),
                                      efd.curvature(model, t, mode))


def test_circle_curvature(circle):
    model = efd.fit(circle)
    t = np.linspace(0, model.T, 100, endpoint=False)
    np.testing.assert_allclose(efd.curvature(model, t, "geometric"), 1 / 0.04, rtol=1e-4)
    np.testing.assert_allclose(efd.curvature(model, t, "paper"), (2 * np.pi) ** 2 * 0.04, rtol=1e-4)


@pytest.mark.parametrize("mode", ["paper", "geometric"])
def test_ellipse_has_no_concave_point(mode):
    model = efd.fit(example_contour("ellipse"))
    t = np.linspace(0, model.T, 2000, endpoint=False)
    assert not efd.concave(model, t, mode).any()


@pytest.mark.parametrize("mode", ["paper", "geometric"])
@pytest.mark.parametrize("reverse", [False, True])
def test_peanut_is_concave_at_its_two_waists(mode, reverse):
    peanut = example_contour("peanut")  # lobes along x, waists at x = 0
    model = efd.fit(peanut[::-1] if reverse else peanut)
    t = np.linspace(0, model.T, 2000, endpoint=False)
    points = efd.evaluate(model, t)
    concave = efd.concave(model, t, mode)
    assert np.all(np.abs(points[concave, 0]) < 0.025)
    assert (points[concave, 1] > 0).any() and (points[concave, 1] < 0).any()
    near_waist = np.abs(points[:, 0]) < 0.005
    assert concave[near_waist].all()


def test_orientation_does_not_change_the_model():
    stone = example_contour("stone2")
    reversed_from_same_start = np.vstack([stone[:1], stone[:0:-1]])
    forward, backward = efd.fit(stone), efd.fit(reversed_from_same_start)
    t = np.linspace(0, forward.T, 300, endpoint=False)
    np.testing.assert_allclose(efd.evaluate(forward, t), efd.evaluate(backward, t), atol=1e-12)
    assert efd.signed_area(efd.sample(backward)[1]) > 0


@pytest.mark.parametrize("mode", ["paper", "geometric"])
def test_curvature_is_invariant_to_rigid_motion(mode):
    stone = example_contour("stone1")
    moved = rotate(stone, 0.7) + [0.3, -0.1]
    a, b = efd.fit(stone), efd.fit(moved)
    t = np.linspace(0, a.T, 200, endpoint=False)
    np.testing.assert_allclose(efd.curvature(a, t, mode), efd.curvature(b, t, mode), rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(rotate(efd.evaluate(a, t), 0.7) + [0.3, -0.1], efd.evaluate(b, t), atol=1e-12)


@pytest.mark.parametrize(
    "points, message",
    [
        ([[0, 0], [0.1, 0.1]], "at least 3"),
        ([[0, 0], [0.1, np.nan], [0.1, 0]], "not finite"),
        ([[0, 0], [0.05, 0.05], [0.1, 0.1]], "no area"),
        ([[0, 0], [0.1, 0.1], [0.1, 0], [0, 0.1]], "self-intersecting"),
        ([0.1, 0.2, 0.3], "(n, 2)"),
    ],
)
def test_bad_polygons_are_refused(points, message):
    with pytest.raises(ContourError, match=message.replace("(", r"\(").replace(")", r"\)")):
        efd.clean_polygon(points)


def test_closing_point_and_duplicates_are_dropped():
    square = [[0, 0], [0.1, 0], [0.1, 0], [0.1, 0.1], [0, 0.1], [0, 0]]
    assert len(efd.clean_polygon(square)) == 4


def test_millimetres_are_warned_about():
    with pytest.warns(UnitWarning, match="millimetres"):
        efd.clean_polygon(example_contour("can") * 1000)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        efd.clean_polygon(example_contour("can"))


def test_bad_harmonics_and_mode():
    with pytest.raises(ContourError, match="harmonics"):
        efd.fit(disc(0.05), harmonics=0)
    with pytest.raises(ValueError, match="curvature mode"):
        efd.curvature(efd.fit(disc(0.05)), [0.0], "gaussian")


# --- adaptive harmonics (efd.choose_harmonics, thesis 4.2.1 and 6.1 item 3) ---------------------

from contourgrasp import InputError  # noqa: E402
from contourgrasp.perception import mask_contour  # noqa: E402

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
        if efd.first_self_intersection(noisy) is None:
            return noisy


def _concave_angles(model, samples=2048):
    """Polar angles (degrees, about the locus) of the concave samples of the curve."""
    t = np.linspace(0, model.T, samples, endpoint=False)
    points = efd.evaluate(model, t)[efd.concave(model, t)] - model.locus
    return np.degrees(np.arctan2(points[:, 1], points[:, 0])) % 360


def _covers(angles, centre, within=5.0):
    return angles.size > 0 and np.min(np.abs((angles - centre + 180) % 360 - 180)) <= within


def test_ellipse_and_circle_need_no_more_than_the_lower_bound(circle):
    assert efd.choose_harmonics(example_contour("ellipse")) == LOWER
    assert efd.choose_harmonics(circle, bounds=(1, 12)) == 1
    assert efd.choose_harmonics(circle, rule="power", bounds=(1, 12)) == 1


@pytest.mark.parametrize("lobes", [5, 7])
def test_fine_concavities_need_more_harmonics(lobes):
    theta = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    gear = np.c_[np.cos(theta), np.sin(theta)] * (0.04 * (1 + 0.08 * np.cos(lobes * theta)))[:, None]
    n = efd.choose_harmonics(gear)
    assert n > LOWER and n >= lobes
    model = efd.fit(gear, n)
    t = np.linspace(0, model.T, 2048, endpoint=False)
    concave = efd.concave(model, t)
    assert np.sum(concave & ~np.roll(concave, 1)) == lobes  # one concave stretch between every two teeth
    assert efd.choose_harmonics(example_contour("stone2")) > LOWER


@pytest.mark.parametrize("name", ["stone1", "stone2", "can", "bottle", "peanut"])
@pytest.mark.parametrize("rule", ["rms", "power"])
def test_choice_is_invariant_to_pose_scale_start_and_direction(name, rule):
    points = example_contour(name)
    n = efd.choose_harmonics(points, rule=rule)
    variants = [
        rotate(points, 0.7) + [0.3, -0.1],
        points * 2.5,
        points * 0.2,
        np.roll(points, 37, axis=0),
        points[::-1],
    ]
    assert [efd.choose_harmonics(v, rule=rule) for v in variants] == [n] * len(variants)


@pytest.mark.parametrize("rule, tolerances", [("rms", np.geomspace(0.05, 1e-4, 25)),
                                              ("power", np.geomspace(0.5, 1e-8, 25))])
def test_smaller_tolerance_never_gives_fewer_harmonics(rule, tolerances):
    for name in ["stone1", "stone2", "can", "case", "bottle", "peanut", "ellipse"]:
        points = example_contour(name)
        counts = [efd.choose_harmonics(points, rule=rule, tolerance=t) for t in tolerances]
        assert counts == sorted(counts), name
        assert counts[0] == LOWER and counts[-1] >= counts[0]


@pytest.mark.parametrize("bounds", [(1, 1), (1, 2), (3, 5), (5, 5), (6, 20), (10, 12), (2, 30)])
def test_bounds_are_respected(bounds):
    for name in ["stone2", "bottle", "ellipse"]:
        n = efd.choose_harmonics(example_contour(name), bounds=bounds, tolerance=1e-6)
        if name != "ellipse":  # (the ellipse is that exact with fewer: its high harmonics are ~0)
            assert n == bounds[1]  # nothing is that exact: the upper bound
        n = efd.choose_harmonics(example_contour(name), bounds=bounds, tolerance=0.5)
        assert n == bounds[0]  # anything is that close: the lower bound
        assert bounds[0] <= efd.choose_harmonics(example_contour(name), bounds=bounds) <= bounds[1]


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
    ],
)
def test_bad_options_are_refused_by_name(options, name):
    with pytest.raises(InputError, match=name):
        efd.choose_harmonics(example_contour("stone1"), **options)
    with pytest.raises(InputError, match=name):
        efd.fit_adaptive(example_contour("stone1"), **options)


def test_bad_polygon_is_a_contour_error():
    with pytest.raises(ContourError, match="at least 3"):
        efd.choose_harmonics([[0, 0], [0.1, 0.1]])


def test_fit_adaptive_is_fit_with_the_chosen_count():
    stone = example_contour("stone2")
    model = efd.fit_adaptive(stone, tolerance=0.003)
    n = efd.choose_harmonics(stone, tolerance=0.003)
    assert model.harmonics == n
    np.testing.assert_allclose(model.coefficients, efd.fit(stone, n).coefficients, atol=1e-15)
    assert efd.fit_adaptive(stone).harmonics == 8


def test_left_out_power_is_the_rms_distance_to_the_upper_bound_model():
    stone = example_contour("stone2")
    full, part = efd.fit(stone, 12), efd.fit(stone, 5)
    t = np.linspace(0, full.T, 4096, endpoint=False)
    rms = np.sqrt(np.mean(np.sum((efd.evaluate(full, t) - efd.evaluate(part, t)) ** 2, axis=1)))
    assert rms == pytest.approx(np.sqrt(np.sum(efd.harmonic_power(full)[5:])), rel=1e-9)


@pytest.mark.parametrize("rule", ["rms", "power"])
def test_simple_stone_keeps_its_hollow_flank(rule):
    """Thesis 4.2.1 / Figure 4.5: the simple stone needs few harmonics and its large flank must read concave."""
    stone = example_contour("stone1")  # its hollow flank faces polar angle 270 degrees
    n = efd.choose_harmonics(stone, rule=rule)
    assert LOWER < n <= 5
    angles = _concave_angles(efd.fit(stone, n))
    assert _covers(angles, 270.0)
    assert np.all(np.abs(angles - 270.0) < 30.0)  # and nothing else is concave
    assert _concave_angles(efd.fit(stone, LOWER)).size == 0  # the lower bound alone would lose it


@pytest.mark.parametrize("rule", ["rms", "power"])
def test_complex_stone_keeps_its_concavities(rule):
    """Thesis 4.2.1 / Figure 4.6: four harmonics turn most of the complex stone's concavities convex."""
    stone = example_contour("stone2")
    reference = _concave_angles(efd.fit(stone, 30))
    centres = [c for c in (32.0, 89.0, 188.0, 240.0, 299.0) if _covers(reference, c, 1.0)]
    assert len(centres) == 5
    n = efd.choose_harmonics(stone, rule=rule)
    assert n == 8
    adaptive, thesis = _concave_angles(efd.fit(stone, n)), _concave_angles(efd.fit(stone, 4))
    assert all(_covers(adaptive, c) for c in centres)
    assert sum(_covers(thesis, c) for c in centres) == 1


@pytest.mark.parametrize("name", ["stone1", "stone2", "ellipse", "can", "peanut"])
def test_camera_staircase_does_not_add_harmonics(name):
    """A 1.5 mm pixel staircase (about a pixel at 0.6 m) leaves the choice within one step of the clean one."""
    points = example_contour(name)
    clean = efd.choose_harmonics(points)
    rng = np.random.default_rng(11)
    for _ in range(3):
        n = efd.choose_harmonics(_camera_outline(points, rng))
        assert abs(n - clean) <= 2 and n < UPPER
    if name == "stone2":
        assert n == 8


@pytest.mark.parametrize("name", ["stone1", "stone2", "ellipse", "can", "peanut"])
def test_millimetre_noise_keeps_the_count_moderate(name):
    """1 mm of white noise along the normal every 3 mm: N stays well below the upper bound."""
    points = example_contour(name)
    rng = np.random.default_rng(5)
    counts = [efd.choose_harmonics(_normal_noise(points, 0.001, rng)) for _ in range(3)]
    assert max(counts) <= 9
    if name == "stone2":
        assert counts == [8, 8, 8]
    if name == "stone1":
        assert max(counts) <= 6


def _crossings_numpy(p):
    """All crossing pairs (i < j, non-adjacent) by the (n, n) orientation arrays: the oracle of the compiled test."""
    n, (a, b) = len(p), (p, np.roll(p, -1, axis=0))
    d = b - a
    o1 = d[:, None, 0] * (a[None, :, 1] - a[:, None, 1]) - d[:, None, 1] * (a[None, :, 0] - a[:, None, 0])
    o2 = d[:, None, 0] * (b[None, :, 1] - a[:, None, 1]) - d[:, None, 1] * (b[None, :, 0] - a[:, None, 0])
    eps = tol.COLLINEAR * float(np.max(np.ptp(p, axis=0))) ** 2
    straddles = ((o1 > eps) & (o2 < -eps)) | ((o1 < -eps) & (o2 > eps))
    i, j = np.nonzero(np.triu(straddles & straddles.T, k=2))
    keep = ~((i == 0) & (j == n - 1))
    return list(zip(i[keep].tolist(), j[keep].tolist()))


@settings(max_examples=60, deadline=None)
@given(st.integers(4, 40), st.integers(0, 2**32 - 1))
def test_first_self_intersection_matches_the_full_pairwise_test(n, seed):
    points = np.random.default_rng(seed).uniform(-0.05, 0.05, size=(n, 2))  # random polygons mostly cross
    pairs = _crossings_numpy(points)
    assert efd.first_self_intersection(points) == (pairs[0] if pairs else None)

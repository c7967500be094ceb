import math
import time
import warnings

import numpy as np
import pytest
from contour_fuzz import polygons, wrong_types
from hypothesis import given, settings
from hypothesis import strategies as st

from contourgrasp import ContourError, InputError, UnitWarning, contour, example_contour
from contourgrasp import tolerances as tol
from conftest import disc


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
        contour.clean_polygon(points)


def test_closing_point_and_duplicates_are_dropped():
    square = [[0, 0], [0.1, 0], [0.1, 0], [0.1, 0.1], [0, 0.1], [0, 0]]
    assert len(contour.clean_polygon(square)) == 4


def test_millimetres_are_warned_about():
    with pytest.warns(UnitWarning, match="millimetres"):
        contour.clean_polygon(example_contour("can") * 1000)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        contour.clean_polygon(example_contour("can"))


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
    assert contour.first_self_intersection(points) == (pairs[0] if pairs else None)


# --- size bounds: overflow, tiny contours -----------------------------------------------

@pytest.mark.parametrize("scale", [1e5, 1e155, 1e200, 1e307, 1e308])
def test_a_contour_beyond_the_size_bound_is_refused(scale):
    with pytest.raises(ContourError, match=r"m across: too large to model \(at most 10000 m"):
        contour.clean_polygon(example_contour("can") * scale)
    with pytest.raises(ContourError, match="too large"):
        contour.fit(example_contour("can") * scale)


def test_an_overflowing_extent_is_named_without_inf():
    points = np.array([[-1e308, 0.0], [1e308, 0.0], [0.0, 1e308]])
    with pytest.raises(ContourError, match="more than 1e308 m across"):
        contour.clean_polygon(points)


def test_a_tiny_contour_is_too_small_not_collinear():
    can = example_contour("can")
    tiny = can / np.ptp(can, axis=0).max() * 1e-7  # 0.1 µm across
    with pytest.raises(ContourError, match=r"^the contour is 1e-07 m across: too small to model \(at least 0.0001 m\)$"):
        contour.clean_polygon(tiny)
    contour.fit(can / np.ptp(can, axis=0).max() * 2 * tol.MIN_CONTOUR_SIZE)  # just above the bound: modelled


def test_bounds_leave_the_example_contours_alone():
    for name in ["bottle", "can", "case", "ellipse", "peanut", "stone1", "stone2"]:
        points = example_contour(name)
        np.testing.assert_array_equal(contour.clean_polygon(points), contour.clean_polygon(points, check_units=False))
        assert tol.MIN_CONTOUR_SIZE < np.ptp(points, axis=0).max() < tol.MAX_PLAUSIBLE_SIZE
        assert len(points) < tol.MAX_CONTOUR_POINTS


def test_complex_and_object_contours_are_refused():
    with pytest.raises(ContourError, match="complex"):
        contour.clean_polygon(disc(0.05) + 1e-3j)
    with pytest.raises(ContourError, match="real numbers"):
        contour.clean_polygon(np.array([["0", "0"], ["1", "0"], ["0", "1"]]))


# --- figure-8s and touching outlines ----------------------------------------------------------------

def lemniscate(n=200, size=0.05):
    """A figure-8 whose crossing (the origin) is sample 50 and sample 150: the passes cross at a vertex."""
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return size * np.c_[np.cos(t), np.sin(t) * np.cos(t)] / (1 + np.sin(t)[:, None] ** 2)


@pytest.mark.parametrize("n", [200, 201])  # through a vertex / between vertices
def test_a_figure_8_is_self_intersecting_not_collinear(n):
    with pytest.raises(ContourError, match=r"contour is self-intersecting: edges \d+ and \d+ cross"):
        contour.clean_polygon(lemniscate(n))
    assert contour.first_self_intersection(lemniscate(200)) == (50, 150)


def test_an_outline_touching_itself_without_crossing_is_accepted():
    # Two squares meeting at a corner (1, 1), traced as one outline through it twice.
    outline = np.array([[0, 0], [1, 0], [1, 1], [2, 1], [2, 2], [1, 2], [1, 1], [0, 1]]) * 0.05
    assert contour.first_self_intersection(outline) is None
    assert len(contour.clean_polygon(outline)) == 8
    neck = np.array([[0, 0], [1, 0], [1, 1], [2, 1], [3, 1], [3, 2], [2, 2], [2, 1], [1, 1], [0, 1]]) * 0.05
    assert contour.first_self_intersection(neck) is None  # out and back along the edge (1, 1)-(2, 1)


# --- a contour traced more than once ----------------------------------------------------------------

@pytest.mark.parametrize("times", [2, 3])
@pytest.mark.parametrize("closed", [False, True])
def test_a_circle_traced_twice_gives_the_efd_of_one_loop(times, closed):
    once = disc(0.04)
    loop = np.vstack([once, once[:1]]) if closed else once
    traced = np.vstack([loop] * times)
    np.testing.assert_array_equal(contour.clean_polygon(traced), contour.clean_polygon(once))
    a, b = contour.fit(traced), contour.fit(once)
    np.testing.assert_array_equal(a.coefficients, b.coefficients)
    assert a.T == b.T == pytest.approx(2 * np.pi * 0.04, rel=1e-4)


def test_a_contour_returning_to_its_start_once_is_not_cut():
    # A start point visited again half-way is a figure-8 through it, not a repeated loop.
    eight = np.roll(lemniscate(200), -50, axis=0)  # samples 0 and 100 at the crossing
    with pytest.raises(ContourError, match="self-intersecting"):
        contour.clean_polygon(eight)


# --- huge contours are resampled --------------------------------------------------------------------

def test_a_million_point_contour_is_resampled_by_arc_length():
    theta = np.linspace(0, 2 * np.pi, 1_000_000, endpoint=False)
    circle = 0.04 * np.c_[np.cos(theta), np.sin(theta)]
    start = time.perf_counter()
    cleaned = contour.clean_polygon(circle)
    assert time.perf_counter() - start < 5.0
    assert cleaned.shape == (tol.MAX_CONTOUR_POINTS, 2)
    np.testing.assert_allclose(np.linalg.norm(cleaned, axis=1), 0.04, rtol=1e-8)
    steps = np.linalg.norm(np.diff(cleaned, axis=0, append=cleaned[:1]), axis=1)
    np.testing.assert_allclose(steps, 2 * np.pi * 0.04 / tol.MAX_CONTOUR_POINTS, rtol=1e-6)
    np.testing.assert_allclose(contour.fit(circle).coefficients, contour.fit(disc(0.04)).coefficients, atol=2e-6)


def test_a_contour_at_the_point_bound_is_kept_as_given():
    points = disc(0.04, n=tol.MAX_CONTOUR_POINTS)
    np.testing.assert_array_equal(contour.clean_polygon(points), points)


# --- repair of traced outlines (perception's staircases) ---------------------------------------------

def test_repair_keeps_the_larger_lobe_of_a_figure_8():
    eight = lemniscate(201) * [1.0, 1.0]
    eight[eight[:, 0] > 0] *= 1.5  # right lobe larger
    repaired = contour.repair_self_intersections(eight)
    assert contour.first_self_intersection(repaired) is None
    assert repaired[:, 0].min() > -1e-6  # the left lobe is gone
    right = eight[eight[:, 0] > 0]
    assert abs(contour.signed_area(repaired)) == pytest.approx(abs(contour.signed_area(right)), rel=0.05)
    contour.clean_polygon(repaired)


def test_repair_of_a_figure_8_through_a_vertex():
    eight = lemniscate(200)
    eight[eight[:, 0] < 0] *= 0.5
    repaired = contour.repair_self_intersections(eight)
    assert contour.first_self_intersection(repaired) is None
    assert repaired[:, 0].min() > -1e-9
    contour.clean_polygon(repaired)


def staircase_with_a_loop():
    """A pixel staircase outline (1 mm steps) of a 6 cm square whose traced edge doubles back over itself once."""
    side = np.arange(60) * 0.001
    square = np.vstack([np.c_[side, 0 * side], np.c_[0 * side + 0.06, side],
                        np.c_[0.06 - side, 0 * side + 0.06], np.c_[0 * side, 0.06 - side]])
    loop = np.array([[0.0305, -0.0005], [0.0305, 0.0005], [0.0295, 0.0005], [0.0295, -0.0005], [0.031, -0.0005]])
    return np.vstack([square[:31], loop, square[31:]])


def test_repair_removes_a_staircase_loop_and_keeps_the_area():
    outline = staircase_with_a_loop()
    assert contour.first_self_intersection(outline) is not None
    with pytest.raises(ContourError, match="self-intersecting"):
        contour.clean_polygon(outline)  # a given contour that crosses is still refused
    repaired = contour.repair_self_intersections(outline)
    assert contour.first_self_intersection(repaired) is None
    assert len(repaired) < len(outline)
    area = abs(contour.signed_area(repaired))
    assert abs(area - abs(contour.signed_area(outline))) < 0.01 * area
    assert area == pytest.approx(0.06**2, rel=0.01)


def test_repair_leaves_a_simple_polygon_alone():
    stone = example_contour("stone2")
    np.testing.assert_array_equal(contour.repair_self_intersections(stone), contour.clean_polygon(stone))
    with pytest.raises(ContourError, match="not finite"):
        contour.repair_self_intersections([[0, 0], [1, np.nan], [1, 1]])


@settings(max_examples=60, deadline=None)
@given(st.integers(4, 40), st.integers(0, 2**32 - 1))
def test_repair_always_ends_without_a_crossing(n, seed):
    points = np.random.default_rng(seed).uniform(-0.05, 0.05, size=(n, 2))
    repaired = contour.repair_self_intersections(points)
    assert len(repaired) <= n + 1
    assert contour.first_self_intersection(repaired) is None


# --- fuzz --------------------------------------------------------------------------------------------

@settings(max_examples=100, deadline=None)
@given(st.one_of(polygons(), wrong_types()))
def test_clean_polygon_returns_a_finite_polygon_or_a_contour_error(points):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UnitWarning)
        try:
            cleaned = contour.clean_polygon(points)
        except ContourError:
            return
    assert cleaned.ndim == 2 and cleaned.shape[1] == 2 and 3 <= len(cleaned) <= tol.MAX_CONTOUR_POINTS
    assert np.isfinite(cleaned).all()
    assert tol.MIN_CONTOUR_SIZE <= np.ptp(cleaned, axis=0).max() <= tol.MAX_CONTOUR_SIZE
    assert abs(contour.signed_area(cleaned)) >= tol.MIN_AREA


@settings(max_examples=50, deadline=None)
@given(st.one_of(polygons(), wrong_types()))
def test_repair_returns_points_or_a_contour_error(points):
    try:
        repaired = contour.repair_self_intersections(points)
    except InputError:
        return
    assert np.isfinite(repaired).all()


def test_a_grown_square_has_the_minkowski_area_and_every_vertex_at_the_distance():
    side, r = 0.1, 0.01
    square = np.array([[0, 0], [side, 0], [side, side], [0, side]], dtype=float)
    grown = contour.grow_polygon(square, r)
    n = 4 * tol.GROWTH_ARC_SEGMENTS  # the four quarter discs' chords make one regular n-gon inscribed in a circle
    exact = side**2 + 4 * side * r + n / 2 * r**2 * math.sin(2 * math.pi / n)  # the square, four strips, the n-gon
    assert contour.signed_area(grown) == pytest.approx(exact, rel=1e-12)
    inside = np.clip(grown, 0, side)  # the nearest point of the square
    assert np.linalg.norm(grown - inside, axis=1) == pytest.approx(r, abs=1e-12)


def test_growth_keeps_the_orientation_and_a_disc_grows_by_the_distance():
    circle = disc(0.02, n=400)
    for points in (circle, circle[::-1]):
        grown = contour.grow_polygon(points, 0.009)
        assert np.sign(contour.signed_area(grown)) == np.sign(contour.signed_area(points))
        assert np.linalg.norm(grown, axis=1) == pytest.approx(0.029, abs=2e-5)
    assert np.array_equal(contour.grow_polygon(circle, 0.0), circle)


@pytest.mark.parametrize("distance", [-0.001, math.nan, "1", tol.MAX_SEARCH_LENGTH * 2])
def test_a_bad_growth_distance_is_refused_by_name(distance):
    with pytest.raises(ContourError, match="distance"):
        contour.grow_polygon(disc(0.02, n=50), distance)


def test_growing_a_jagged_outline_of_the_most_points_allowed_is_bounded():
    """Shapely's buffer of a 2,000-point star took 11 s: the growth resamples to MAX_GROWTH_POINTS first."""
    theta = np.linspace(0, 2 * np.pi, tol.MAX_CONTOUR_POINTS, endpoint=False)
    radius = 0.003 * (1 + 0.5 * (np.arange(len(theta)) % 2))  # 10,000 points zigzagging between 3 and 4.5 mm
    star = contour.clean_polygon(np.c_[radius * np.cos(theta), radius * np.sin(theta)])
    started = time.perf_counter()
    grown = contour.grow_polygon(star, 0.006)
    assert time.perf_counter() - started < 10.0  # an order of magnitude; a second or less here
    reach = np.linalg.norm(grown, axis=1)  # resampled points lie on the star: no farther out than its tips grown,
    assert reach.max() <= 0.0105 + 1e-9 and reach.min() >= 0.009 - 1e-4  # and its 3 mm core is grown by 6 mm

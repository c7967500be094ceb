import warnings

import numpy as np
import pytest

from contourgrasp import ContourError, UnitWarning, efd, example_contour
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

import re

import numpy as np
import pytest
from contour_fuzz import polygons
from hypothesis import given, settings
from hypothesis import strategies as st

import contourgrasp
from contourgrasp import ContourError, InputError, contour, example_contour
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
    model = contour.fit(polygon, harmonics=6)
    np.testing.assert_allclose(model.coefficients, kuhl_giardina(polygon, 6), atol=1e-9)


def test_dc_terms_are_the_arc_length_centroid():
    square = np.array([[0.0, 0.0], [0.1, 0.0], [0.1, 0.1], [0.0, 0.1]]) + [0.2, -0.3]
    model = contour.fit(square)
    assert model.A0 == pytest.approx(0.25, abs=1e-12)
    assert model.C0 == pytest.approx(-0.25, abs=1e-12)
    assert model.T == pytest.approx(0.4)


def test_circle_is_one_harmonic(circle):
    model = contour.fit(circle, harmonics=4)
    np.testing.assert_allclose(model.coefficients[0], [0.04, 0, 0, 0.04], atol=1e-5)
    np.testing.assert_allclose(model.coefficients[1:], 0, atol=1e-5)


def test_many_harmonics_reproduce_the_polygon():
    can = example_contour("can")
    model = contour.fit(can, harmonics=40)
    t, points = contour.sample(model, 2000)
    gap = np.min(np.linalg.norm(points[:, None] - can[None], axis=2), axis=0)
    assert gap.max() < 1e-3


@pytest.mark.parametrize("k", [1, 2, 3])
def test_derivatives_match_finite_differences(k):
    model = contour.fit(example_contour("stone2"), harmonics=8)
    t = np.linspace(0, model.T, 50, endpoint=False)
    h = 1e-5
    numeric = (contour.evaluate(model, t + h, k - 1) - contour.evaluate(model, t - h, k - 1)) / (2 * h)
    np.testing.assert_allclose(contour.evaluate(model, t, k), numeric, rtol=1e-4, atol=1e-6)


def test_derivatives_together_are_evaluate_to_the_last_bit():
    model = contour.fit(example_contour("peanut"), harmonics=7)
    t = np.random.default_rng(5).uniform(-0.1, 2 * model.T, 300)
    together = contour.evaluate_derivatives(model, t, (2, 0, 1))
    for order, values in zip((2, 0, 1), together):
        np.testing.assert_array_equal(values, contour.evaluate(model, t, order))
    for mode in contour.CURVATURE_MODES:
        np.testing.assert_array_equal(contour.curvature_from_derivatives(together[2], together[0], model.T, mode),
                                      contour.curvature(model, t, mode))


def test_circle_curvature(circle):
    model = contour.fit(circle)
    t = np.linspace(0, model.T, 100, endpoint=False)
    np.testing.assert_allclose(contour.curvature(model, t, "geometric"), 1 / 0.04, rtol=1e-4)
    np.testing.assert_allclose(contour.curvature(model, t, "paper"), (2 * np.pi) ** 2 * 0.04, rtol=1e-4)


@pytest.mark.parametrize("mode", ["paper", "geometric"])
def test_ellipse_has_no_concave_point(mode):
    model = contour.fit(example_contour("ellipse"))
    t = np.linspace(0, model.T, 2000, endpoint=False)
    assert not contour.concave(model, t, mode).any()


@pytest.mark.parametrize("mode", ["paper", "geometric"])
@pytest.mark.parametrize("reverse", [False, True])
def test_peanut_is_concave_at_its_two_waists(mode, reverse):
    peanut = example_contour("peanut")  # lobes along x, waists at x = 0
    model = contour.fit(peanut[::-1] if reverse else peanut)
    t = np.linspace(0, model.T, 2000, endpoint=False)
    points = contour.evaluate(model, t)
    concave = contour.concave(model, t, mode)
    assert np.all(np.abs(points[concave, 0]) < 0.025)
    assert (points[concave, 1] > 0).any() and (points[concave, 1] < 0).any()
    near_waist = np.abs(points[:, 0]) < 0.005
    assert concave[near_waist].all()


def test_orientation_does_not_change_the_model():
    stone = example_contour("stone2")
    reversed_from_same_start = np.vstack([stone[:1], stone[:0:-1]])
    forward, backward = contour.fit(stone), contour.fit(reversed_from_same_start)
    t = np.linspace(0, forward.T, 300, endpoint=False)
    np.testing.assert_allclose(contour.evaluate(forward, t), contour.evaluate(backward, t), atol=1e-12)
    assert contour.signed_area(contour.sample(backward)[1]) > 0


@pytest.mark.parametrize("mode", ["paper", "geometric"])
def test_curvature_is_invariant_to_rigid_motion(mode):
    stone = example_contour("stone1")
    moved = rotate(stone, 0.7) + [0.3, -0.1]
    a, b = contour.fit(stone), contour.fit(moved)
    t = np.linspace(0, a.T, 200, endpoint=False)
    np.testing.assert_allclose(contour.curvature(a, t, mode), contour.curvature(b, t, mode), rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(rotate(contour.evaluate(a, t), 0.7) + [0.3, -0.1], contour.evaluate(b, t), atol=1e-12)


def test_bad_harmonics_and_mode():
    with pytest.raises(ContourError, match="harmonics"):
        contour.fit(disc(0.05), harmonics=0)
    with pytest.raises(ValueError, match="curvature mode"):
        contour.curvature(contour.fit(disc(0.05)), [0.0], "gaussian")



# --- bad options --------------------------------------------------------------------------

@pytest.mark.parametrize("harmonics, message", [
    (0, "harmonics must be an integer >= 1"),
    (-3, "harmonics must be an integer >= 1"),
    ("4", "harmonics must be an integer"),
    (4.0, "harmonics must be an integer"),
    (True, "harmonics must be an integer"),
    (tol.MAX_HARMONICS + 1, f"harmonics must be at most {tol.MAX_HARMONICS}, got {tol.MAX_HARMONICS + 1}"),
    (1_000_000, f"harmonics must be at most {tol.MAX_HARMONICS}, got 1000000"),
])
def test_harmonics_are_an_integer_up_to_the_bound(harmonics, message):
    with pytest.raises(ContourError, match=re.escape(message)):
        contour.fit(disc(0.05), harmonics)


def test_the_harmonics_bound_is_fitted():
    assert contour.fit(disc(0.05), tol.MAX_HARMONICS).harmonics == tol.MAX_HARMONICS


@pytest.mark.parametrize("derivative", ["1", 1.0, -1, None, True])
def test_a_bad_derivative_is_an_input_error_naming_it(derivative):
    model = contour.fit(disc(0.05))
    with pytest.raises(InputError, match="derivative must be an integer"):
        contour.evaluate(model, [0.0], derivative=derivative)
    with pytest.raises(InputError, match="derivative"):
        contour.evaluate_derivatives(model, [0.0], (0, derivative))


def test_bad_models_and_parameters_are_input_errors():
    model = contour.fit(disc(0.05))
    with pytest.raises(InputError, match="model must be an EFD"):
        contour.evaluate(None, [0.0])
    with pytest.raises(InputError, match="model must be an EFD"):
        contour.curvature("model", [0.0])
    with pytest.raises(InputError, match="t must be an array of real numbers"):
        contour.evaluate(model, ["a"])
    with pytest.raises(InputError, match="complex"):
        contour.curvature(model, [1j])
    with pytest.raises(InputError, match="1-D"):
        contour.evaluate(model, np.zeros((2, 2)))
    with pytest.raises(InputError, match="count"):
        contour.sample(model, 0)
    with pytest.raises(InputError, match="curvature mode"):
        contour.curvature_from_derivatives(np.ones((1, 2)), np.ones((1, 2)), 1.0, "Paper")


def test_an_unchecked_overflowing_polygon_is_a_contour_error_not_nan():
    with pytest.raises(ContourError, match="not finite|cannot be computed"):
        contour.fit(example_contour("can") * 1e200, validate=False)
    with pytest.raises(ContourError, match="not finite|cannot be computed"):
        contour.fit(example_contour("can") * 1e155, validate=False)


# --- the package's one public name ------------------------------------------------------------------

def test_the_contour_model_has_one_public_name():
    assert contourgrasp.contour is contour
    assert contourgrasp.contour.choose_harmonics(example_contour("stone2")) == 8
    with pytest.raises(AttributeError):
        contourgrasp.efd  # noqa: B018


@settings(max_examples=80, deadline=None)
@given(polygons(), st.integers(-2, 120), st.sampled_from(contour.CURVATURE_MODES))
def test_fit_and_curvature_give_finite_numbers_or_a_clear_error(points, harmonics, mode):
    try:
        model = contour.fit(points, harmonics)
    except InputError:
        return
    assert np.isfinite(model.coefficients).all() and np.isfinite([model.A0, model.C0, model.T]).all()
    t = np.linspace(-model.T, 2 * model.T, 50)
    assert np.isfinite(contour.evaluate(model, t)).all()
    assert np.isfinite(contour.curvature(model, t, mode)).all()
    assert contour.concave(model, t, mode).dtype == bool

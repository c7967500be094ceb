"""Grasp quality against analytic truth and independent computations.

Independent references used here: closed forms derived by hand (in the test
docstrings), a linear program for force closure (a strictly positive
combination of the wrenches that sums to zero), and the support function
min_u max_i w_i . u sampled on the sphere and polished locally, which equals
the Ferrari-Canny ball radius whenever the origin is inside the hull.
"""

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog, minimize

from contourgrasp import InputError, contour
from contourgrasp import tolerances as cg_tol
from contourgrasp.errors import QualityError
from contourgrasp.quality import wrench_space as q
from conftest import disc, rotate

A = 0.03  # half-width of the box, m


def polar(radius, degrees, centre=(0.0, 0.0)):
    """Points on a circle and their inward normals."""
    th = np.radians(degrees)
    out = np.c_[np.cos(th), np.sin(th)]
    return np.asarray(centre) + radius * out, -out


def antipodal():
    return np.array([[-A, 0.0], [A, 0.0]]), np.array([[1.0, 0.0], [-1.0, 0.0]])


# ---------------------------------------------------------------- references


def lp_closure(w):
    """Force closure by LP: max s with sum l_i w_i = 0, sum l_i = 1, l_i >= s.

    Closure iff s > 0 (a strictly positive combination vanishes) and the wrenches span R^3."""
    m = len(w)
    if m < 4 or np.linalg.matrix_rank(w, tol=1e-9) < 3:
        return False
    c = np.r_[np.zeros(m), -1.0]
    a_eq = np.r_[np.c_[w.T, np.zeros(3)], [np.r_[np.ones(m), 0.0]]]
    a_ub = np.c_[-np.eye(m), np.ones(m)]
    res = linprog(c, A_ub=a_ub, b_ub=np.zeros(m), A_eq=a_eq, b_eq=np.r_[0, 0, 0, 1.0],
                  bounds=[(0, None)] * m + [(None, 1)])
    return res.status == 0 and -res.fun > 1e-9


def support_radius(w):
    """min over unit u of max_i w_i . u: sampled on a Fibonacci sphere, then polished."""
    k = 20000
    z = 1 - 2 * (np.arange(k) + 0.5) / k
    phi = np.arange(k) * math.pi * (3 - math.sqrt(5))
    u = np.c_[np.sqrt(1 - z**2) * np.cos(phi), np.sqrt(1 - z**2) * np.sin(phi), z]
    h = (u @ w.T).max(axis=1)

    def support(x):
        d = x / np.linalg.norm(x)
        return float(np.max(w @ d))

    best = min(minimize(support, u[i], method="Nelder-Mead",
                        options={"xatol": 1e-12, "fatol": 1e-14, "maxiter": 4000}).fun
               for i in np.argsort(h)[:5])
    return max(best, 0.0)


# ------------------------------------------------------------ two contacts


def test_antipodal_box_matches_hand_computation():
    """Wrenches (about the midpoint, rho = A) are (1, m, -m), (1, -m, m), (-1, m, m), (-1, -m, -m):
    the tetrahedron of a box's vertices with negative coordinate product. Its facet through the
    first three is x + y/m + z/m = 1, at distance m / sqrt(m^2 + 2) from the origin, as are the others."""
    p, n = antipodal()
    for mu in (1e-4, 0.05, 0.5, 1.0, 3.0):  # 1e-4: thin facets, still exact
        expected = mu / math.sqrt(mu**2 + 2)
        assert q.epsilon(p, n, mu=mu) == pytest.approx(expected, rel=1e-9)
        assert q.epsilon_many(p[None], n[None], mu=mu)[0] == pytest.approx(expected, rel=1e-9)
        assert q.force_closure(p, n, mu=mu)
    np.testing.assert_allclose(np.abs(q.contact_wrenches(p, n, mu=0.5)), [[1, 0.5, 0.5]] * 4)


def test_frictionless_antipodal_has_no_closure():
    p, n = antipodal()
    assert q.epsilon(p, n, mu=0.0) == 0.0
    assert not q.force_closure(p, n, mu=0.0)


@pytest.mark.parametrize("h, closes", [(0.029, True), (0.031, False)])
def test_offset_contacts_close_iff_the_joining_line_is_inside_the_cones(h, closes):
    """Contacts (-A, 0) and (A, h) on the two faces of a box: the joining line makes the angle
    atan(h / 2A) with both normals; with mu = 0.5 and A = 0.03, closure iff h < 0.03."""
    p = np.array([[-A, 0.0], [A, h]])
    n = np.array([[1.0, 0.0], [-1.0, 0.0]])
    assert q.force_closure(p, n, mu=0.5) is closes
    assert (q.epsilon(p, n, mu=0.5) > 0) is closes


@pytest.mark.parametrize("beta, closes", [(26.0, True), (27.0, False)])
def test_tilted_normal_flips_closure_at_the_cone_half_angle(beta, closes):
    """The second normal tilted by beta from the joining line; atan(0.5) = 26.57 deg."""
    b = math.radians(beta)
    p, _ = antipodal()
    n = np.array([[1.0, 0.0], [-math.cos(b), math.sin(b)]])
    assert q.force_closure(p, n, mu=0.5) is closes
    assert lp_closure(q.contact_wrenches(p, n, mu=0.5)) is closes


def test_contacts_at_right_angles_do_not_close_with_little_friction():
    """Adjacent faces of a box: every force has f_x + f_y >= 1 - mu > 0."""
    p = np.array([[-A, 0.0], [0.0, -A]])
    n = np.array([[1.0, 0.0], [0.0, 1.0]])
    assert not q.force_closure(p, n, mu=0.3)
    assert q.epsilon(p, n, mu=0.3, metric="Linf") == 0.0


@pytest.mark.parametrize("mu", [0.1, 0.5, 2.0, 10.0])
def test_all_contacts_on_one_face_never_close(mu):
    """Thesis chapter 5, failure 2: every force pushes +y, nothing pulls back."""
    p = np.c_[np.linspace(-0.05, 0.05, 5), np.full(5, -0.02)]
    n = np.tile([0.0, 1.0], (5, 1))
    assert q.grasp_quality(p, n, mu=mu) == q.GraspQuality(False, 0.0, "L1", mu, 1.0)


def test_thumb_opposite_the_fingers_closes_the_glasses_case():
    """A 0.16 x 0.06 case: four fingers on one long side, the thumb on the other."""
    fingers = np.c_[np.linspace(-0.06, 0.06, 4), np.full(4, 0.03)]
    p = np.vstack([fingers, [[0.0, -0.03]]])
    n = np.vstack([np.tile([0.0, -1.0], (4, 1)), [[0.0, 1.0]]])
    assert q.force_closure(p, n, mu=0.5, centre=(0, 0), rho=0.08)
    assert not q.force_closure(p[:4], n[:4], mu=0.5, centre=(0, 0), rho=0.08)


# ------------------------------------------------------------------- disc


def test_frictionless_contacts_on_a_disc_cannot_resist_torque():
    p, n = polar(0.05, [90, 210, 330])
    assert q.epsilon(p, n, mu=0.0) == 0.0
    assert q.epsilon(p, n, mu=0.0, centre=(0.01, -0.02), rho=0.1) == 0.0  # whatever the centre
    assert q.epsilon_many(p[None], n[None], mu=0.0)[0] == 0.0


@pytest.mark.parametrize("count", [3, 4, 6])
@pytest.mark.parametrize("mu", [0.1, 0.3])
def test_evenly_spaced_disc_grasp_has_epsilon_mu(count, mu):
    """On a disc (rho = r) every '+' edge has torque / rho = mu: they span the facet z = mu,
    the closest one while mu is small, so epsilon = mu for any number of contacts."""
    p, n = polar(0.05, np.arange(count) * 360 / count + 10)
    assert q.epsilon(p, n, mu=mu) == pytest.approx(mu, rel=1e-9)
    assert support_radius(q.contact_wrenches(p, n, mu=mu)) == pytest.approx(mu, rel=1e-6)


@given(angle=st.floats(-math.pi, math.pi), shift=st.tuples(st.floats(-1, 1), st.floats(-1, 1)),
       mu=st.floats(0.05, 1.5))
@settings(max_examples=40, deadline=None)
def test_epsilon_is_invariant_under_rigid_motion(angle, shift, mu):
    p, n = polar(0.05, [90, 200, 330])
    centre = np.array([0.004, -0.003])
    ref = q.epsilon(p, n, mu=mu, centre=centre)
    assert ref > 0
    p2, n2, c2 = rotate(p, angle) + shift, rotate(n, angle), rotate(centre, angle) + shift
    assert q.epsilon(p2, n2, mu=mu, centre=c2) == pytest.approx(ref, rel=1e-9)
    assert q.epsilon(rotate(p, angle), n2, mu=mu) == pytest.approx(q.epsilon(p, n, mu=mu), rel=1e-9)


# --------------------------------------------------------- random grasps


@st.composite
def grasps(draw, max_contacts=5):
    """Contacts on an ellipse with normals tilted up to 40 deg from the inward normal."""
    k = draw(st.integers(2, max_contacts))
    ang = np.array(draw(st.lists(st.floats(0, 2 * math.pi), min_size=k, max_size=k)))
    tilt = np.array(draw(st.lists(st.floats(-0.7, 0.7), min_size=k, max_size=k)))
    ax, ay = draw(st.floats(0.02, 0.08)), draw(st.floats(0.02, 0.08))
    p = np.c_[ax * np.cos(ang), ay * np.sin(ang)]
    inward = -np.c_[np.cos(ang) / ax, np.sin(ang) / ay]
    n = np.array([rotate(v, t) for v, t in zip(inward, tilt)])  # unnormalised on purpose
    return p, n, draw(st.floats(0.0, 1.5))


@given(grasps())
@settings(max_examples=150, deadline=None)
def test_qhull_and_plane_enumeration_agree(grasp):
    p, n, mu = grasp
    assert q.epsilon_many(p[None], n[None], mu=mu)[0] == pytest.approx(q.epsilon(p, n, mu=mu), abs=1e-9)


def test_plane_enumeration_of_wrenches_on_one_line_is_zero():
    """Two contacts one ulp apart and a third, frictionless: the wrenches lie on one line (no
    closure), and every triple's plane is rounding noise that passes the one-side test."""
    p = np.array([[0.033768894116758735, 0.026295968275246766], [0.0625, -7.654042494670958e-18], [0.0625, 0.0]])
    n = np.array([[-8.644836893890236, -26.927071513852688], [-16.0, 7.83773951454306e-15], [-16.0, 0.0]])
    assert q.epsilon(p, n, mu=0.0) == 0.0
    assert q.epsilon_many(p[None], n[None], mu=0.0)[0] == 0.0


@given(grasps())
@settings(max_examples=150, deadline=None)
def test_force_closure_agrees_with_the_lp(grasp):
    p, n, mu = grasp
    eps = q.epsilon(p, n, mu=mu)
    if 0 < eps < 1e-6:
        return  # at the boundary the two tolerances may disagree
    assert (eps > 0) == lp_closure(q.contact_wrenches(p, n, mu=mu))


@given(grasps(max_contacts=4))
@settings(max_examples=25, deadline=None)
def test_epsilon_is_the_minimum_of_the_support_function(grasp):
    p, n, mu = grasp
    eps = q.epsilon(p, n, mu=mu)
    if eps > 0:  # the reference's Nelder-Mead polish of a non-smooth max stalls within a few 1e-6 (one found: 2e-6)
        assert support_radius(q.contact_wrenches(p, n, mu=mu)) == pytest.approx(eps, abs=1e-5)


@given(grasps(), st.floats(0.0, 1.0))
@settings(max_examples=100, deadline=None)
def test_epsilon_never_decreases_with_friction(grasp, extra):
    p, n, mu = grasp
    assert q.epsilon(p, n, mu=mu + extra) >= q.epsilon(p, n, mu=mu) - 1e-12


def test_epsilon_grows_with_friction():
    p, n = antipodal()
    eps = [q.epsilon(p, n, mu=mu) for mu in (0.1, 0.2, 0.4, 0.8)]
    assert all(a < b for a, b in zip(eps, eps[1:]))


@given(grasps(), st.tuples(st.floats(-0.05, 0.05), st.floats(-0.05, 0.05)), st.floats(0.01, 1.0))
@settings(max_examples=100, deadline=None)
def test_force_closure_does_not_depend_on_centre_or_rho(grasp, centre, rho):
    p, n, mu = grasp
    if 0 < q.epsilon(p, n, mu=mu) < 1e-6:
        return
    assert q.force_closure(p, n, mu=mu) == q.force_closure(p, n, mu=mu, centre=centre, rho=rho)


@given(grasps())
@settings(max_examples=60, deadline=None)
def test_linf_brackets_l1(grasp):
    """W_L1 is inside W_Linf, which is inside n W_L1 (module docstring)."""
    p, n, mu = grasp
    l1, linf = q.epsilon(p, n, mu=mu), q.epsilon(p, n, mu=mu, metric="Linf")
    assert l1 - 1e-9 <= linf <= len(p) * l1 + 1e-9
    assert (l1 > 0) == (linf > 0) or min(l1, linf) < 1e-6


# ------------------------------------------------------------ many grasps


def test_epsilon_many_matches_one_by_one_with_missing_contacts():
    rng = np.random.default_rng(7)
    p = rng.normal(0, 0.04, (30, 5, 2))
    n = -p + rng.normal(0, 0.01, p.shape)
    valid = rng.random((30, 5)) < 0.8
    p[~valid] = np.nan  # missing fingers may carry anything
    for metric in q.METRICS:
        many = q.epsilon_many(p, n, valid, mu=0.4, metric=metric, centre=(0.001, 0), rho=0.05)
        one = [q.epsilon(p[k][valid[k]], n[k][valid[k]], mu=0.4, metric=metric, centre=(0.001, 0), rho=0.05)
               for k in range(30)]
        np.testing.assert_allclose(many, one, atol=1e-9)
        assert np.count_nonzero(many) > 5


def test_epsilon_many_takes_a_centre_and_rho_per_grasp():
    """rho = 2A halves the torques: the facet x + y/m + z/(m/2) = 1 is at 1 / sqrt(1 + 4 + 16)."""
    p, n = antipodal()
    shift = np.array([[0.0, 0.0], [0.2, -0.1]])
    eps = q.epsilon_many(p[None] + shift[:, None], np.stack([n, n]), centre=shift, rho=[A, 2 * A])
    np.testing.assert_allclose(eps, [1 / 3, 1 / math.sqrt(21)], rtol=1e-12)


def test_epsilon_many_of_no_contacts_is_zero():
    eps = q.epsilon_many(np.zeros((3, 4, 2)), np.ones((3, 4, 2)), np.zeros((3, 4), bool))
    assert eps.tolist() == [0.0] * 3


# ------------------------------------------------------------ the record


def test_grasp_quality_is_a_frozen_plain_record():
    p, n = antipodal()
    result = q.grasp_quality(p, n, mu=0.5, metric="Linf")
    assert result.force_closure is True and type(result.epsilon) is float
    assert result.metric == "Linf" and result.mu == 0.5 and result.imbalance == 0.0
    assert dataclasses.asdict(result)["epsilon"] == pytest.approx(1 / math.sqrt(3))
    with pytest.raises(dataclasses.FrozenInstanceError):
        result.epsilon = 1.0


# ------------------------------------------------------------ bad input


def test_non_unit_normals_are_normalised():
    p, n = antipodal()
    assert q.epsilon(p, 7.5 * n) == q.epsilon(p, n)


@pytest.mark.parametrize(
    "kwargs, word",
    [
        (dict(points=np.zeros((3, 2)), normals=np.ones((2, 2))), "normals"),
        (dict(points=np.zeros((3, 3)), normals=np.ones((3, 3))), "points"),
        (dict(normals=[[1.0, 0.0], [0.0, 0.0]]), "normals"),
        (dict(points=[[np.nan, 0.0], [0.0, 0.0]]), "points"),
        (dict(normals=[["a", 0.0], [1.0, 0.0]]), "normals"),
        (dict(mu=-0.1), "mu"),
        (dict(mu=float("nan")), "mu"),
        (dict(mu="lots"), "mu"),
        (dict(metric="L2"), "metric"),
        (dict(rho=0.0), "rho"),
        (dict(rho=[1.0, 2.0]), "rho"),
        (dict(centre=(1.0, 2.0, 3.0)), "centre"),
    ],
)
def test_bad_input_names_the_argument(kwargs, word):
    p, n = antipodal()
    args = dict(points=p, normals=n) | kwargs
    with pytest.raises(InputError, match=word):
        q.epsilon(args.pop("points"), args.pop("normals"), **args)


def test_bad_batches_name_the_argument():
    p, n = np.zeros((4, 3, 2)), np.ones((4, 3, 2))
    with pytest.raises(InputError, match="valid"):
        q.epsilon_many(p, n, np.ones((4, 2), bool))
    with pytest.raises(InputError, match="points"):
        q.epsilon_many(p[0], n[0])
    with pytest.raises(InputError, match="Linf"):
        q.epsilon(np.zeros((9, 2)), np.ones((9, 2)), metric="Linf")


def test_input_error_is_a_value_error():
    with pytest.raises(ValueError):
        q.force_closure([[0.0, 0.0]], [[1.0, 0.0]], mu=-1)


# -------------------------------------------------------- contour normals


@pytest.mark.parametrize("clockwise", [False, True])
def test_contour_normals_of_a_circle_point_to_its_centre(clockwise):
    polygon = disc(0.04, centre=(0.1, -0.2))
    model = contour.fit(polygon[::-1] if clockwise else polygon, harmonics=4)
    t = np.linspace(0, model.T, 37)
    towards = np.array([0.1, -0.2]) - contour.evaluate(model, t)
    towards /= np.linalg.norm(towards, axis=1, keepdims=True)
    np.testing.assert_allclose(q.contour_normals(model, t), towards, atol=1e-6)


def test_contour_normals_keep_the_shape_of_t_and_are_unit():
    model = contour.fit(disc(0.04) * [1.5, 1.0], harmonics=6)
    t = np.linspace(0, model.T, 12).reshape(3, 4)
    normals = q.contour_normals(model, t)
    assert normals.shape == (3, 4, 2) and q.contour_normals(model, 0.0).shape == (2,)
    np.testing.assert_allclose(np.linalg.norm(normals, axis=-1), 1.0)
    # A step along the normal moves into the ellipse (x / 0.06)^2 + (y / 0.04)^2 < 1.
    inside = contour.evaluate(model, t.ravel()) + 1e-3 * normals.reshape(-1, 2)
    assert np.all(np.sum((inside / [0.06, 0.04]) ** 2, axis=1) < 1)


def test_normals_of_a_fitted_disc_give_a_closing_three_finger_grasp():
    model = contour.fit(disc(0.04), harmonics=4)
    t = model.T * np.array([0.0, 1 / 3, 2 / 3])
    p, n = contour.evaluate(model, t), q.contour_normals(model, t)
    assert q.epsilon(p, n, mu=0.3, centre=model.locus) == pytest.approx(0.3, rel=1e-3)


@pytest.mark.parametrize("mu", [1e300, 10.5, float("inf"), -0.1, "0.5", None])
def test_friction_beyond_the_physical_bound_is_a_quality_error_naming_it(mu):
    """mu = 1e300 once crashed (segfault) inside Qhull."""
    p, n = [[-0.03, 0.0], [0.03, 0.0], [0.0, 0.03]], [[1.0, 0.0], [-1.0, 0.0], [0.0, -1.0]]
    for metric in ("L1", "Linf"):
        with pytest.raises(QualityError, match="mu"):
            q.epsilon(p, n, mu=mu, metric=metric)
    with pytest.raises(QualityError, match="at most 10" if isinstance(mu, float) and 10 < mu < math.inf else "mu"):
        q.force_closure(p, n, mu=mu)


def test_friction_at_the_bound_still_works():
    p, n = [[-0.03, 0.0], [0.03, 0.0]], [[1.0, 0.0], [-1.0, 0.0]]
    assert q.epsilon(p, n, mu=cg_tol.MAX_FRICTION) > 0
    assert q.epsilon(p, n, mu=cg_tol.MAX_FRICTION, metric="Linf") > 0


@pytest.mark.parametrize("metric", ["L1", "Linf"])
@pytest.mark.parametrize("n", [0, 3])
def test_epsilon_many_of_no_grasps_is_empty(metric, n):
    empty = np.zeros((0, n, 2))
    out = q.epsilon_many(empty, empty, metric=metric)
    assert out.shape == (0,) and out.dtype == float


def test_contacts_whose_torques_overflow_are_a_quality_error():
    with pytest.raises(QualityError, match="overflow"):
        q.epsilon([[1e308, 0.0], [-1e308, 0.0], [0.0, 1.0]], [[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0]], rho=1e-300)


contact_values = st.one_of(st.floats(-0.1, 0.1), st.floats(allow_nan=True, allow_infinity=True),
                           st.sampled_from([1e-300, 1e300, -1e300, 0.0]))


@settings(max_examples=100, deadline=None)
@given(n=st.integers(0, 5), data=st.data(),
       mu=st.one_of(st.floats(0, 12), st.floats(allow_nan=True, allow_infinity=True), st.sampled_from([1e300, -1]),
                    st.text(max_size=2)),
       metric=st.sampled_from(["L1", "Linf", "L2"]), frame=st.booleans())
def test_fuzz_quality_entry_points_return_or_raise_a_quality_error(n, data, mu, metric, frame):
    points = np.array(data.draw(st.lists(st.tuples(contact_values, contact_values), min_size=n, max_size=n)),
                      dtype=float).reshape(n, 2)
    normals = np.array(data.draw(st.lists(st.tuples(contact_values, contact_values), min_size=n, max_size=n)),
                       dtype=float).reshape(n, 2)
    centre, rho = ((data.draw(contact_values), data.draw(contact_values)), data.draw(contact_values)) if frame else (
        None, None)
    calls = [lambda: q.epsilon(points, normals, mu=mu, centre=centre, rho=rho, metric=metric),
             lambda: q.force_closure(points, normals, mu=mu, centre=centre, rho=rho),
             lambda: q.epsilon_many(points[None], normals[None], mu=mu, centre=centre, rho=rho, metric=metric),
             lambda: q.epsilon_many(np.repeat(points[None], 2, 0), np.repeat(normals[None], 2, 0),
                                    np.ones((2, n), bool), mu=mu, metric=metric)]
    for call in calls:
        try:
            result = call()
        except QualityError:
            continue
        assert np.all(np.isfinite(result)) and np.all(np.asarray(result) >= 0)


# ------------------------------------------------------------ the squeeze's imbalance


@pytest.mark.parametrize("count", [2, 3, 5])
def test_evenly_spaced_pushes_cancel(count):
    angles = np.linspace(0, 2 * np.pi, count, endpoint=False) + 0.3
    normals = np.stack([np.cos(angles), np.sin(angles)], axis=1)[None]
    assert q.imbalance(normals)[0] == pytest.approx(0.0, abs=1e-12)


def test_pushes_one_way_leave_all_their_force():
    normals = np.array([[[0.0, 2.0], [0.0, 0.5], [0.0, 1.0]]])  # lengths do not matter, only directions
    assert q.imbalance(normals)[0] == pytest.approx(1.0)


def test_a_thumb_against_fingers_at_right_angles():
    # thumb along +x, two fingers along -y: |(1, -2)| / 3
    normals = np.array([[[1.0, 0.0], [0.0, -1.0], [0.0, -1.0]]])
    assert q.imbalance(normals)[0] == pytest.approx(math.sqrt(5) / 3)


def test_imbalance_ignores_missing_contacts_and_is_one_without_any():
    normals = np.array([[[1.0, 0.0], [-1.0, 0.0], [np.nan, np.nan]], [[1.0, 0.0], [0.0, 1.0], [0.0, 1.0]]])
    valid = np.array([[True, True, False], [False, False, False]])
    assert q.imbalance(normals, valid).tolist() == [0.0, 1.0]


@given(st.floats(0, 2 * np.pi), st.lists(st.floats(0, 2 * np.pi), min_size=1, max_size=6))
def test_imbalance_is_a_share_invariant_under_rotation(turn, angles):
    normals = np.stack([np.cos(angles), np.sin(angles)], axis=1)[None]
    turned = normals @ np.array([[np.cos(turn), np.sin(turn)], [-np.sin(turn), np.cos(turn)]])
    share = q.imbalance(normals)[0]
    assert 0.0 <= share <= 1.0 + 1e-12
    assert q.imbalance(turned)[0] == pytest.approx(share, abs=1e-9)


def test_imbalance_names_the_normals_of_a_bad_batch():
    with pytest.raises(QualityError, match=r"^normals must be a \(p, n, 2\) array, got shape \(3, 2\)$"):
        q.imbalance(np.ones((3, 2)))


def test_imbalance_refuses_a_zero_normal():
    with pytest.raises(QualityError, match="normals"):
        q.imbalance(np.array([[[1.0, 0.0], [0.0, 0.0]]]))

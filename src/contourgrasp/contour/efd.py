"""Contour model: Elliptic Fourier Descriptors (thesis section 3.2, Kuhl & Giardina 1982).

A closed contour is the truncated Fourier series of eq 3.3-3.4::

    x(t) = A0 + sum_n a_n cos(2 n pi t / T) + b_n sin(2 n pi t / T)
    y(t) = C0 + sum_n c_n cos(2 n pi t / T) + d_n sin(2 n pi t / T)

with t the arc length along the input polygon, t in [0, T), T its perimeter.
The coefficients (eq 3.9-3.13) and DC terms (eq 3.14-3.17) come from
`pyefd <https://pyefd.readthedocs.io>`_; this module adds the derivatives,
the two curvature flavours and the orientation convention. The polygon is
checked first (:func:`contourgrasp.contour.clean_polygon`): within its size
bounds nothing here can overflow.

Equations of section 3.2 and where they are computed: eq 3.3-3.4 (the curve)
and 3.6-3.7 (its second derivative) in :func:`evaluate_derivatives`, eq 3.5
(the curvature's magnitude) and 3.8 (its sign) in
:func:`curvature_from_derivatives`, eq 3.9-3.17 (coefficients, arc length,
DC terms) in :func:`fit`.

Orientation
-----------
:func:`fit` reverses the input polygon when needed so that the model always
runs with *positive* signed area in the (x, y) coordinates it was given
(counter-clockwise with y up; clockwise on screen in the camera's image frame
where y points down). With that convention convex points have positive
curvature and concave points negative, whichever way the input ran.

Curvature flavours
------------------
``"geometric"``
    The signed curvature (x'y'' - y'x'') / |r'|^3 in 1/m: a circle of radius r
    has curvature 1/r everywhere.
``"paper"``
    The thesis's measure (eq 3.5-3.8): the magnitude of the second derivative
    |r''|, signed negative where the point is concave. Two readings are ours:

    * The derivative is taken with respect to the normalised parameter
      s = t / T in [0, 1) (as pyefd reconstructs contours), i.e. eq 3.6-3.7
      with T = 1. It is in meters: a circle of radius r gives (2 pi)^2 r.
      With this scale the gains of Tables 4.3, A.1 and A.2 balance curvature
      and ratio costs the way section 4.2.3 describes; with T in meters the
      curvature term would outweigh the ratio term a hundredfold.
    * Concavity (eq 3.8). Read literally, N(t) x N(t + dt) > 0 compares the
      second derivatives at adjacent parameters; its limit, the sign of
      r'' x r''', flips on the flat sides of an ellipse (r'' is small there and
      dominated by the harmonics of the arc-length parametrisation) and misses
      the waists of a peanut. The text speaks of "the cross product of two
      adjacent points": we take the cross product of the adjacent chords
      r(t) - r(t - dt) and r(t + dt) - r(t), whose limit is the sign of
      x'y'' - y'x''. Both flavours thus agree on *where* the contour is
      concave and differ only in magnitude.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
import pyefd

from .. import tolerances as tol
from .. import validation
from ..errors import ContourError, InputError
from .polygon import clean_polygon, signed_area

CurvatureMode = Literal["paper", "geometric"]
CURVATURE_MODES: tuple[str, ...] = ("paper", "geometric")


@dataclass(frozen=True, eq=False)
class EFD:
    """Elliptic Fourier model of a closed contour.

    Attributes
    ----------
    coefficients : (harmonics, 4) float
        Rows (a_n, b_n, c_n, d_n) for n = 1..harmonics, in meters.
    A0, C0 : float
        DC terms: the contour's locus (arc-length centroid), meters.
    T : float
        Period: the perimeter of the fitted polygon, meters.
    """

    coefficients: np.ndarray
    A0: float
    C0: float
    T: float

    @property
    def harmonics(self) -> int:
        return int(self.coefficients.shape[0])

    @property
    def locus(self) -> np.ndarray:
        """(2,) float: (A0, C0)."""
        return np.array([self.A0, self.C0])


def fit(points, harmonics: int = 4, *, validate: bool = True) -> EFD:
    """Fit the EFD model of a closed polygon.

    Implements eq 3.9, 3.10, 3.11, 3.12, 3.13, 3.14, 3.15, 3.16 and 3.17 (by
    pyefd): the Fourier coefficients a_n, b_n, c_n, d_n of the polygon's
    piecewise-linear x(t), y(t) over its arc length t_i, and the DC terms
    A0, C0. T is the perimeter.

    Parameters
    ----------
    points : (n, 2) float
        Polygon vertices in meters, either orientation, closed or not;
        checked by :func:`clean_polygon` (call it first for the unit warning).
    harmonics : int
        Number of harmonics k (thesis default 4), 1 to ``tolerances.MAX_HARMONICS``.
    validate : bool
        Run :func:`clean_polygon` on ``points``; pass False only for its output.

    Returns
    -------
    EFD
        The model, oriented with positive signed area (see module docstring).

    Raises
    ------
    ContourError
        For a bad ``harmonics``, a polygon :func:`clean_polygon` refuses, or
        coefficients that are not finite (a polygon not cleaned).

    Examples
    --------
    A circle of radius 0.04 m traced from angle 0 is a single harmonic:

    >>> theta = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    >>> model = fit(np.c_[0.04 * np.cos(theta), 0.04 * np.sin(theta)], harmonics=2)
    >>> np.round(model.coefficients, 3) + 0.0
    array([[0.04, 0.  , 0.  , 0.04],
           [0.  , 0.  , 0.  , 0.  ]])
    """
    harmonics = validation.integer("harmonics", harmonics, 1, maximum=tol.MAX_HARMONICS, error=ContourError)
    pts = clean_polygon(points, check_units=False) if validate else np.asarray(points, dtype=float)
    with np.errstate(all="ignore"):  # an unchecked polygon may overflow: refused below, not warned about
        try:
            model = _fit(pts, harmonics)
        except (ArithmeticError, ValueError, IndexError):
            raise ContourError("the EFD of this contour cannot be computed (clean it with clean_polygon)") from None
    if not (np.isfinite(model.coefficients).all() and np.isfinite([model.A0, model.C0]).all() and 0 < model.T < np.inf):
        raise ContourError("the EFD coefficients of this contour are not finite (clean it with clean_polygon)")
    return model


def _fit(pts: np.ndarray, harmonics: int) -> EFD:
    if signed_area(pts) < 0:
        pts = np.concatenate([pts[:1], pts[:0:-1]])
    coefficients = pyefd.elliptic_fourier_descriptors(pts, order=harmonics, normalize=False)
    A0, C0 = pyefd.calculate_dc_coefficients(pts)
    closed = np.vstack([pts, pts[:1]])
    T = float(np.sum(np.linalg.norm(np.diff(closed, axis=0), axis=1)))
    return EFD(coefficients=np.asarray(coefficients, dtype=float), A0=float(A0), C0=float(C0), T=T)


def evaluate(model: EFD, t, derivative: int = 0) -> np.ndarray:
    """Points of the EFD curve or their derivatives with respect to t (see eq 3.3-3.4, 3.6-3.7).

    Parameters
    ----------
    model : EFD
    t : (m,) float
        Curve parameters in [0, T) (any real value works: the curve is periodic;
        a NaN gives NaN).
    derivative : int
        0 for the points, k >= 1 for the k-th derivative d^k r / dt^k.

    Returns
    -------
    (m, 2) float

    Raises
    ------
    InputError
        For a ``model`` that is not an :class:`EFD`, a ``t`` that is not real
        numbers, or a ``derivative`` that is not an integer >= 0.

    Examples
    --------
    >>> theta = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    >>> model = fit(np.c_[0.04 * np.cos(theta), 0.04 * np.sin(theta)], harmonics=2)
    >>> np.round(evaluate(model, [0.0, model.T / 4]), 3) + 0.0
    array([[0.04, 0.  ],
           [0.  , 0.04]])
    """
    return evaluate_derivatives(model, t, (derivative,))[0]


def evaluate_derivatives(model: EFD, t, derivatives) -> list[np.ndarray]:
    """:func:`evaluate` for several derivatives at the same parameters, e.g. ``(0, 1)``: the point and tangent.

    Implements eq 3.3, 3.4, 3.6 and 3.7: the truncated series and its
    derivatives term by term, d^k/dt^k cos(w t) = w^k cos(w t + k pi / 2) with
    w = 2 n pi / T (k = 2 is the thesis's N(t)). Each equals :func:`evaluate`
    of that derivative to the last bit; the harmonics' phases are computed
    once for all (the planner's Newton steps and curvature need pairs).

    Parameters
    ----------
    model : EFD
    t : (m,) float
        Curve parameters, as for :func:`evaluate`.
    derivatives : sequence of int
        Orders, each >= 0.

    Returns
    -------
    list of (m, 2) float
        In the order of ``derivatives``.

    Raises
    ------
    InputError
        As :func:`evaluate`.
    """
    model = _model(model)
    derivatives = [validation.integer("derivative", k, 0) for k in _orders(derivatives)]
    t = np.atleast_1d(validation.float_array("t", t))
    if t.ndim != 1:
        raise InputError(f"t must be a scalar or a 1-D array of curve parameters, got shape {t.shape}")
    w = 2.0 * np.pi * np.arange(1, model.harmonics + 1) / model.T
    wt = t[:, None] * w
    a, b, c, d = model.coefficients.T
    out = []
    for derivative in derivatives:
        phase = wt + derivative * np.pi / 2  # d/dt cos(wt) = w cos(wt + pi/2)
        cos, sin = np.cos(phase), np.sin(phase)
        if derivative:
            scale = w**derivative
            cos *= scale
            sin *= scale
        xy = np.empty((len(t), 2))
        xy[:, 0] = cos @ a + sin @ b
        xy[:, 1] = cos @ c + sin @ d
        if derivative == 0:
            xy += model.locus
        out.append(xy)
    return out


def sample(model: EFD, count: int = tol.EFD_SAMPLES) -> tuple[np.ndarray, np.ndarray]:
    """``count`` evenly spaced parameters and the curve points there.

    Parameters
    ----------
    model : EFD
    count : int
        Number of samples, >= 1.

    Returns
    -------
    t : (count,) float
    points : (count, 2) float
    """
    model = _model(model)
    count = validation.integer("count", count, 1)
    t = np.linspace(0.0, model.T, count, endpoint=False)
    return t, evaluate(model, t)


def curvature(model: EFD, t, mode: CurvatureMode = "paper") -> np.ndarray:
    """Signed curvature at parameters t: positive convex, negative concave.

    Parameters
    ----------
    model : EFD
    t : (m,) float
    mode : {"paper", "geometric"}
        See the module docstring: ``"paper"`` is |d^2 r / ds^2| with s = t / T,
        negative where concave (eq 3.5-3.8); ``"geometric"`` is
        (x'y'' - y'x'') / |r'|^3. Both are negative at the same points.

    Returns
    -------
    (m,) float
        In meters for ``"paper"``, in 1/m for ``"geometric"``.
    """
    validation.choice("curvature mode", mode, CURVATURE_MODES)
    return curvature_from_derivatives(*evaluate_derivatives(model, t, (1, 2)), model.T, mode)


def curvature_from_derivatives(d1: np.ndarray, d2: np.ndarray, period: float, mode: CurvatureMode = "paper"):
    """:func:`curvature` from the first and second derivatives at the parameters, for callers that have them.

    Implements eq 3.5 and 3.8. ``"paper"``: the magnitude |N| of the second
    derivative (eq 3.5) with respect to s = t / T (hence the factor T^2),
    signed by the concavity test of eq 3.8 read as the cross product of
    adjacent chords, whose limit is the sign of x'y'' - y'x'' (module
    docstring). ``"geometric"``: (x'y'' - y'x'') / |r'|^3.

    Parameters
    ----------
    d1, d2 : (m, 2) float
        First and second derivatives d r / dt, d^2 r / dt^2.
    period : float
        The model's T.
    mode : {"paper", "geometric"}

    Returns
    -------
    (m,) float
        As :func:`curvature`.
    """
    validation.choice("curvature mode", mode, CURVATURE_MODES)
    if mode == "geometric":
        speed = np.linalg.norm(d1, axis=1)
        return _cross(d1, d2) / np.maximum(speed, np.finfo(float).tiny) ** 3
    sign = np.where(_cross(d1, d2) < 0, -1.0, 1.0)
    return sign * np.linalg.norm(d2, axis=1) * period**2


def concave(model: EFD, t, mode: CurvatureMode = "paper") -> np.ndarray:
    """(m,) bool: where the curve is concave under the chosen curvature flavour (see eq 3.8).

    Parameters
    ----------
    model : EFD
    t : (m,) float
    mode : {"paper", "geometric"}
        Both flavours are concave at the same points.
    """
    return curvature(model, t, mode) < 0


def _cross(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def _model(model) -> EFD:
    if not isinstance(model, EFD):
        raise InputError(f"model must be an EFD (from fit), got {type(model).__name__}")
    return model


def _orders(derivatives) -> list:
    try:
        return list(derivatives)
    except TypeError:
        raise InputError(f"derivatives must be a sequence of integers, got {derivatives!r}") from None

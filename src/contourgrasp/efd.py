"""Contour model: Elliptic Fourier Descriptors (thesis section 3.2, Kuhl & Giardina 1982).

A closed contour is the truncated Fourier series of eq 3.3-3.4::

    x(t) = A0 + sum_n a_n cos(2 n pi t / T) + b_n sin(2 n pi t / T)
    y(t) = C0 + sum_n c_n cos(2 n pi t / T) + d_n sin(2 n pi t / T)

with t the arc length along the input polygon, t in [0, T), T its perimeter.
The coefficients (eq 3.9-3.12) and DC terms (eq 3.14-3.17) come from
`pyefd <https://pyefd.readthedocs.io>`_; this module adds the derivatives,
the two curvature flavours and the orientation convention.

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

import warnings
from dataclasses import dataclass
from typing import Literal

import numpy as np
import pyefd

from . import tolerances as tol
from .errors import ContourError, UnitWarning

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


def signed_area(points: np.ndarray) -> float:
    """Shoelace signed area of a closed polygon; positive for counter-clockwise with y up.

    Parameters
    ----------
    points : (n, 2) float
        Polygon vertices, not repeating the first point.
    """
    x, y = np.asarray(points, dtype=float).T
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def clean_polygon(points, *, check_units: bool = True) -> np.ndarray:
    """Check a closed polygon and return it ready for fitting.

    Drops a repeated closing point and consecutive duplicates, and checks there
    are at least three distinct points, all finite, enclosing a non-zero area,
    with no edge crossing another. With ``check_units``, warns
    (:class:`UnitWarning`) when the polygon is too large to be a graspable
    object in meters.

    Parameters
    ----------
    points : (n, 2) float
        Polygon vertices in meters, in either orientation.

    Returns
    -------
    (m, 2) float
        The cleaned vertices, orientation unchanged.

    Raises
    ------
    ContourError
        With a message that names what is wrong.
    """
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise ContourError(f"contour must be an (n, 2) array of x, y points, got shape {pts.shape}")
    if not np.all(np.isfinite(pts)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(pts), axis=1))[0])
        raise ContourError(f"contour point {bad} is not finite (NaN or inf)")
    step = np.linalg.norm(np.diff(pts, axis=0, append=pts[:1]), axis=1)
    pts = pts[step > tol.POINT_MERGE]
    if len(pts) < 3:
        raise ContourError(f"contour needs at least 3 distinct points, got {len(pts)}")
    crossing = first_self_intersection(pts)
    if crossing is not None:
        raise ContourError(f"contour is self-intersecting: edges {crossing[0]} and {crossing[1]} cross")
    if abs(signed_area(pts)) < tol.MIN_AREA:
        raise ContourError("contour encloses no area (its points are collinear)")
    size = float(np.max(np.ptp(pts, axis=0)))
    if check_units and size > tol.MAX_PLAUSIBLE_SIZE:
        warnings.warn(
            f"contour is {size:.3g} m across: an object that large is almost certainly "
            f"not in meters (millimetres? divide by 1000)",
            UnitWarning,
            stacklevel=2,
        )
    return pts


def first_self_intersection(points: np.ndarray) -> tuple[int, int] | None:
    """The first pair of non-adjacent edges of a closed polygon that cross, or None.

    Parameters
    ----------
    points : (n, 2) float
        Polygon vertices; edge i runs from point i to point i+1 (mod n).
    """
    p = np.asarray(points, dtype=float)
    n = len(p)
    a, b = p, np.roll(p, -1, axis=0)
    d = b - a

    def cross(u, v):
        return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]

    # Orientation of each edge's end points relative to every other edge.
    o1 = cross(d[:, None], a[None, :] - a[:, None])
    o2 = cross(d[:, None], b[None, :] - a[:, None])
    eps = tol.COLLINEAR * float(np.max(np.ptp(p, axis=0))) ** 2
    straddles = ((o1 > eps) & (o2 < -eps)) | ((o1 < -eps) & (o2 > eps))
    crosses = straddles & straddles.T
    i, j = np.triu_indices(n, k=2)
    keep = ~((i == 0) & (j == n - 1))
    hits = np.flatnonzero(crosses[i[keep], j[keep]])
    if hits.size == 0:
        return None
    return int(i[keep][hits[0]]), int(j[keep][hits[0]])


def fit(points, harmonics: int = 4, *, validate: bool = True) -> EFD:
    """Fit the EFD model of a closed polygon (eq 3.9-3.17).

    Parameters
    ----------
    points : (n, 2) float
        Polygon vertices in meters, either orientation, closed or not;
        checked by :func:`clean_polygon` (call it first for the unit warning).
    harmonics : int
        Number of harmonics k (thesis default 4).
    validate : bool
        Run :func:`clean_polygon` on ``points``; pass False only for its output.

    Returns
    -------
    EFD
        The model, oriented with positive signed area (see module docstring).

    Examples
    --------
    A circle of radius 0.04 m traced from angle 0 is a single harmonic:

    >>> theta = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    >>> model = fit(np.c_[0.04 * np.cos(theta), 0.04 * np.sin(theta)], harmonics=2)
    >>> np.round(model.coefficients, 3) + 0.0
    array([[0.04, 0.  , 0.  , 0.04],
           [0.  , 0.  , 0.  , 0.  ]])
    """
    if not isinstance(harmonics, (int, np.integer)) or harmonics < 1:
        raise ContourError(f"harmonics must be a positive integer, got {harmonics!r}")
    pts = clean_polygon(points, check_units=False) if validate else np.asarray(points, dtype=float)
    if signed_area(pts) < 0:
        pts = np.concatenate([pts[:1], pts[:0:-1]])
    coefficients = pyefd.elliptic_fourier_descriptors(pts, order=int(harmonics), normalize=False)
    A0, C0 = pyefd.calculate_dc_coefficients(pts)
    closed = np.vstack([pts, pts[:1]])
    T = float(np.sum(np.linalg.norm(np.diff(closed, axis=0), axis=1)))
    return EFD(coefficients=np.asarray(coefficients), A0=float(A0), C0=float(C0), T=T)


def evaluate(model: EFD, t, derivative: int = 0) -> np.ndarray:
    """Points of the EFD curve or their derivatives with respect to t (eq 3.3-3.4, 3.6-3.7).

    Parameters
    ----------
    model : EFD
    t : (m,) float
        Curve parameters in [0, T) (any real value works: the curve is periodic).
    derivative : int
        0 for the points, k for the k-th derivative d^k r / dt^k.

    Returns
    -------
    (m, 2) float
    """
    t = np.atleast_1d(np.asarray(t, dtype=float))
    n = np.arange(1, model.harmonics + 1)
    w = 2.0 * np.pi * n / model.T
    phase = np.outer(t, w) + derivative * np.pi / 2  # d/dt cos(wt) = w cos(wt + pi/2)
    scale = w**derivative
    cos, sin = np.cos(phase) * scale, np.sin(phase) * scale
    a, b, c, d = model.coefficients.T
    xy = np.stack([cos @ a + sin @ b, cos @ c + sin @ d], axis=-1)
    if derivative == 0:
        xy += model.locus
    return xy


def sample(model: EFD, count: int = tol.EFD_SAMPLES) -> tuple[np.ndarray, np.ndarray]:
    """``count`` evenly spaced parameters and the curve points there.

    Returns
    -------
    t : (count,) float
    points : (count, 2) float
    """
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
    if mode not in CURVATURE_MODES:
        raise ValueError(f"curvature mode must be one of {CURVATURE_MODES}, got {mode!r}")
    d1 = evaluate(model, t, 1)
    d2 = evaluate(model, t, 2)
    if mode == "geometric":
        speed = np.linalg.norm(d1, axis=1)
        return _cross(d1, d2) / np.maximum(speed, np.finfo(float).tiny) ** 3
    sign = np.where(_cross(d1, d2) < 0, -1.0, 1.0)
    return sign * np.linalg.norm(d2, axis=1) * model.T**2


def concave(model: EFD, t, mode: CurvatureMode = "paper") -> np.ndarray:
    """(m,) bool: where the curve is concave under the chosen curvature flavour."""
    return curvature(model, t, mode) < 0


def _cross(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]

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
from ._kernels import first_crossing
from .errors import ContourError, InputError, UnitWarning

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
    p = np.ascontiguousarray(points, dtype=float)
    eps = tol.COLLINEAR * float(np.max(np.ptp(p, axis=0))) ** 2
    i, j = first_crossing(p, eps)
    return None if i < 0 else (int(i), int(j))


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
    return evaluate_derivatives(model, t, (derivative,))[0]


def evaluate_derivatives(model: EFD, t, derivatives) -> list[np.ndarray]:
    """:func:`evaluate` for several derivatives at the same parameters, e.g. ``(0, 1)``: the point and tangent.

    Each equals :func:`evaluate` of that derivative to the last bit; the harmonics' phases are
    computed once for all (the planner's Newton steps and curvature need pairs).

    Returns
    -------
    list of (m, 2) float
        In the order of ``derivatives``.
    """
    t = np.atleast_1d(np.asarray(t, dtype=float))
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
    return curvature_from_derivatives(*evaluate_derivatives(model, t, (1, 2)), model.T, mode)


def curvature_from_derivatives(d1: np.ndarray, d2: np.ndarray, period: float, mode: CurvatureMode = "paper"):
    """:func:`curvature` from the first and second derivatives (m, 2) at the parameters, for callers that have them.

    ``period`` is the model's T (the ``"paper"`` flavour differentiates with respect to t / T).
    """
    if mode == "geometric":
        speed = np.linalg.norm(d1, axis=1)
        return _cross(d1, d2) / np.maximum(speed, np.finfo(float).tiny) ** 3
    sign = np.where(_cross(d1, d2) < 0, -1.0, 1.0)
    return sign * np.linalg.norm(d2, axis=1) * period**2


def concave(model: EFD, t, mode: CurvatureMode = "paper") -> np.ndarray:
    """(m,) bool: where the curve is concave under the chosen curvature flavour."""
    return curvature(model, t, mode) < 0


def _cross(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


# --- Adaptive number of harmonics (thesis 6.1 item 3) ---------------------------------------

HarmonicsRule = Literal["rms", "power"]
HARMONICS_RULES: tuple[str, ...] = ("rms", "power")


def harmonic_power(model: EFD) -> np.ndarray:
    """Power of each harmonic: (a_n^2 + b_n^2 + c_n^2 + d_n^2) / 2.

    By Parseval's theorem the mean over one period of |r_k(t) - r_m(t)|^2, the
    squared distance between the reconstructions with k < m harmonics at the
    same parameter, is the sum of the powers of harmonics k+1..m. The power of
    a harmonic does not change when the contour is rotated, moved or started
    at another point (these only rotate (a_n, c_n), (b_n, d_n) or the phase).

    Parameters
    ----------
    model : EFD

    Returns
    -------
    (harmonics,) float
        In m^2, harmonic n at index n - 1.
    """
    return 0.5 * np.sum(np.asarray(model.coefficients, dtype=float) ** 2, axis=1)


def choose_harmonics(
    points,
    *,
    rule: HarmonicsRule = "rms",
    tolerance: float | None = None,
    bounds: tuple[int, int] = tol.HARMONICS_BOUNDS,
    validate: bool = True,
) -> int:
    """The number of harmonics for one object: the fewest whose left-out detail is below ``tolerance``.

    The thesis fixes four harmonics (4.2.2) although its own analysis (4.2.1,
    Figures 4.5-4.6) finds that the best count differs per object: four keep
    the simple stone's large flat side concave, the complex stone needs eight
    to keep its concavities. Section 6.1 item 3 proposes adapting the count to
    the object's complexity; this is that rule (details in the Notes).

    Fit ``R = bounds[1]`` harmonics, the richest model allowed. Leaving out
    harmonics N+1..R moves the curve by the RMS distance (Parseval, see
    :func:`harmonic_power`)::

        e(N) = sqrt(mean_t |r_N(t) - r_R(t)|^2) = sqrt(P_{N+1} + ... + P_R)

    with P_n the power of harmonic n. The answer is the smallest N in
    ``bounds`` with

    * ``"rms"`` (default): e(N) <= tolerance * sqrt(A), A the polygon's area:
      the left-out detail is below a fraction of the object's size;
    * ``"power"``: e(N)^2 <= tolerance * (P_1 + ... + P_R): the first N
      harmonics carry at least 1 - tolerance of the power (the "Fourier
      power" criterion of morphometrics).

    e(N) never grows with N and e(R) = 0, so there always is an answer, it
    lies in ``bounds``, and a smaller tolerance never gives fewer harmonics.
    It does not depend on the polygon's position, rotation, scale, start
    point or direction.

    Parameters
    ----------
    points : (n, 2) float
        Polygon vertices in meters, either orientation, closed or not.
    rule : {"rms", "power"}
        See above.
    tolerance : float, optional
        Positive; a fraction of sqrt(area) for ``"rms"``, a fraction (< 1) of
        the power for ``"power"``. Default: ``tolerances.HARMONICS_RMS_TOLERANCE``
        (0.008) or ``tolerances.HARMONICS_POWER_TOLERANCE`` (2e-4).
    bounds : (int, int)
        Fewest and most harmonics, 1 <= lower <= upper (default
        ``tolerances.HARMONICS_BOUNDS``, (3, 12)). The upper bound is also the
        reference model R, so raising it can raise the answer.
    validate : bool
        Run :func:`clean_polygon` on ``points``; pass False only for its output.

    Returns
    -------
    int
        The number of harmonics, ``bounds[0] <= N <= bounds[1]``.

    Raises
    ------
    InputError
        For a bad ``rule``, ``tolerance`` or ``bounds``, naming the option.
    ContourError
        For a polygon that cannot be modelled (see :func:`clean_polygon`).

    Notes
    -----
    Why this rule:

    * The reference is the R-harmonic model, not the polygon. A camera
      contour is a pixel staircase with about a pixel of noise (1.5 mm at
      0.6 m, 1-3 % of the thesis's objects); a rule on the distance to the
      polygon can never get below that and sends every camera contour to the
      upper bound. Noise spreads its power over all harmonics up to the
      polygon's resolution, so only a small share of it lies in N+1..R.
    * RMS rather than the largest distance: one noisy vertex or one sharp
      corner (the bottle's cap) should not decide for the whole outline.
    * sqrt(A) as the size: a length that scales with the object and is
      hardly changed by zero-mean noise (unlike the perimeter, which a
      staircase lengthens). The ``"power"`` rule divides by the total power
      instead, which grows with elongation: for the same detail it gives long
      objects fewer harmonics than round ones.
    * Bounds 3..12: with one or two harmonics the thesis's objects have no
      concave stretch at all (4.2.1, Figure 4.5 a-b), so a grasp cannot
      prefer any; the more harmonics, the more the flat sides of boxes ripple
      (Gibbs) into several small concave dips, while the thesis wants a flat
      side to read as one concave stretch (3.2), as the low harmonics give.

    Default tolerance, from ``python tools/harmonics_figure.py --sweep --sim``.
    N chosen by the ``"rms"`` rule for the example contours: clean; rasterised
    at 1.5 mm per pixel and outlined like a camera mask
    (:func:`contourgrasp.perception.mask_contour`); with 1 mm and 2 mm of
    Gaussian noise along the normal every 3 mm; and the contours the simulated
    camera segments (noisy depth, default perception). Ranges are min-max
    over 5 draws. At the default 0.008:

    =======  =====  ===========  ==========  ==========  ==========
    contour  clean  camera px    1 mm noise  2 mm noise  sim camera
    =======  =====  ===========  ==========  ==========  ==========
    bottle   10     10           10          10          10
    can      7      7            7-9         9-10        7-9
    case     7      5-7          7-8         7-10        6-7
    ellipse  3      3            5-6         10-11       -
    peanut   5      4-5          5-6         7-9         -
    stone1   4      4            4-6         8-9         4-5
    stone2   8      8            8           9-12        8
    =======  =====  ===========  ==========  ==========  ==========

    and over tolerances (clean / camera px):

    =======  =====  ======  =====  ======  =====  =====
    contour  0.006  0.007   0.008  0.009   0.010  0.012
    =======  =====  ======  =====  ======  =====  =====
    bottle   10/10  10/10   10/10  9/9-10  9/9    9/9
    can      9/9    9/7-9   7/7    7/7     7/7    7/7
    case     7/7    7/7     7/5-7  5/5     5/5    5/5
    ellipse  5/3-5  3/3     3/3    3/3     3/3    3/3
    peanut   5/5    5/5     5/4-5  3/3-4   3/3    3/3
    stone1   5/5    4/4-5   4/4    4/4     4/4    4/4
    stone2   8/8    8/8     8/8    8/8     8/6-8  6/6
    =======  =====  ======  =====  ======  =====  =====

    0.008 is where the stones come out as the thesis wants them for clean,
    camera and simulated contours alike: stone 1 at 4 (its hollow flank
    concave), stone 2 at 8 (all five concavities; the 4-harmonic model keeps
    one). Stone 2's e(7) is 1.0 % of its size and its e(8) at most 0.45 %
    (0.75 % with 1 mm of noise), so 0.008 has margin on both sides; at 0.010
    camera contours of stone 2 fall back to 6 harmonics and lose a concavity.
    The case (e(5) = 0.8 %) and the peanut (e(3) = 0.8 %) sit on the edge and
    may take 5 or 7, 3 or 5: both keep their concave sides. The 2 mm column
    is a stress case (white noise twice a pixel, rougher than any camera
    outline here): the rule cannot tell it from detail and adds harmonics.
    The ``"power"`` rule at 2e-4 chooses the same for the stones, the can
    and the ellipse, and one step fewer for the bottle (9), case (5) and
    peanut (3).

    Examples
    --------
    >>> from contourgrasp import example_contour
    >>> choose_harmonics(example_contour("ellipse")), choose_harmonics(example_contour("stone2"))
    (3, 8)
    """
    rule, tolerance, (lower, upper) = _harmonics_options(rule, tolerance, bounds)
    pts = clean_polygon(points, check_units=False) if validate else np.asarray(points, dtype=float)
    power = harmonic_power(fit(pts, upper, validate=False))
    left_out = np.append(np.cumsum(power[::-1])[::-1], 0.0)  # left_out[N] = P_{N+1} + ... + P_R
    if rule == "rms":
        allowed = tolerance**2 * abs(signed_area(pts))
    else:
        allowed = tolerance * float(np.sum(power))
    for n in range(lower, upper + 1):
        if left_out[n] <= allowed:
            return n
    return upper  # not reached: left_out[upper] == 0


def fit_adaptive(
    points,
    *,
    rule: HarmonicsRule = "rms",
    tolerance: float | None = None,
    bounds: tuple[int, int] = tol.HARMONICS_BOUNDS,
    validate: bool = True,
) -> EFD:
    """:func:`fit` with the number of harmonics of :func:`choose_harmonics` (same options).

    Returns
    -------
    EFD
        Its ``harmonics`` is the chosen count.

    Examples
    --------
    >>> from contourgrasp import example_contour
    >>> fit_adaptive(example_contour("stone1")).harmonics
    4
    """
    pts = clean_polygon(points, check_units=False) if validate else np.asarray(points, dtype=float)
    harmonics = choose_harmonics(pts, rule=rule, tolerance=tolerance, bounds=bounds, validate=False)
    return fit(pts, harmonics, validate=False)


def _harmonics_options(rule, tolerance, bounds) -> tuple[str, float, tuple[int, int]]:
    """Check the options of :func:`choose_harmonics`; fill in the default tolerance."""
    if not isinstance(rule, str) or rule not in HARMONICS_RULES:
        raise InputError(f"rule must be one of {HARMONICS_RULES}, got {rule!r}")
    if tolerance is None:
        tolerance = tol.HARMONICS_RMS_TOLERANCE if rule == "rms" else tol.HARMONICS_POWER_TOLERANCE
    if (isinstance(tolerance, bool) or not isinstance(tolerance, (int, float, np.integer, np.floating))
            or not np.isfinite(tolerance) or tolerance <= 0):
        raise InputError(f"tolerance must be a positive number, got {tolerance!r}")
    if rule == "power" and tolerance >= 1:
        raise InputError(f"tolerance of the 'power' rule is a fraction of the power, below 1; got {tolerance!r}")
    try:
        lower, upper = bounds
    except (TypeError, ValueError):
        raise InputError(f"bounds must be a pair (lower, upper) of harmonic counts, got {bounds!r}") from None
    for value in (lower, upper):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
            raise InputError(f"bounds must be a pair (lower, upper) of integers, got {bounds!r}")
    if not 1 <= lower <= upper:
        raise InputError(f"bounds must satisfy 1 <= lower <= upper, got {bounds!r}")
    return rule, float(tolerance), (int(lower), int(upper))

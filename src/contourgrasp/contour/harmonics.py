"""Adaptive number of harmonics (thesis 6.1 item 3): :func:`choose_harmonics` picks the count per object
from the power of the harmonics it would leave out; :func:`fit_adaptive` fits with it."""

from __future__ import annotations

from typing import Literal

import numpy as np

from .. import tolerances as tol
from .. import validation
from ..errors import InputError
from .efd import EFD, fit
from .polygon import clean_polygon, signed_area

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
        Fewest and most harmonics, 1 <= lower <= upper <= ``tolerances.MAX_HARMONICS`` (default
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

    The default tolerance comes from ``python tools/harmonics_figure.py --sweep --sim`` (docs/studies.md).

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
    validation.choice("rule", rule, HARMONICS_RULES)
    if tolerance is None:
        tolerance = tol.HARMONICS_RMS_TOLERANCE if rule == "rms" else tol.HARMONICS_POWER_TOLERANCE
    tolerance = validation.positive("tolerance", tolerance)
    if rule == "power" and tolerance >= 1:
        raise InputError(f"tolerance of the 'power' rule is a fraction of the power, below 1; got {tolerance!r}")
    try:
        lower, upper = bounds
    except (TypeError, ValueError):
        raise InputError(f"bounds must be a pair (lower, upper) of harmonic counts, got {bounds!r}") from None
    lower, upper = (validation.integer(f"bounds[{k}]", value, 1, maximum=tol.MAX_HARMONICS)
                    for k, value in enumerate((lower, upper)))
    if lower > upper:
        raise InputError(f"bounds must satisfy lower <= upper, got {bounds!r}")
    return rule, tolerance, (lower, upper)
